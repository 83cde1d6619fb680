"""Dense clouds off the bunny's limit surface (scripts/fit_dense.py): the sampler draws exact limit points uniformly
by area, and the fit is judged against the TRUE surface, both ways.

The sampler is checked independently: its points lie on the limit surface (global closest points of
:mod:`ccproof.evaluate.closest`, distance 0) and the share of the points per group of faces matches the share of
the area of those faces, measured on the exact limit points of the mesh subdivided three times (two triangles
per quad), not on the sampler's own densities.
"""

import importlib.util
import re
from pathlib import Path

import numpy as np
import pytest

SCRIPT = Path(__file__).resolve().parents[3] / "scripts" / "fit_dense.py"


@pytest.fixture(scope="module")
def fit_dense():
    spec = importlib.util.spec_from_file_location("fit_dense", SCRIPT)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.fixture(scope="module")
def bunny(fit_dense):
    return fit_dense.true_surface()  # (control mesh, limit surface, closest-point search on it)


def _face_areas_level3(mesh):
    from ccproof.apps.dynamics.cloud import limit_surface_mesh

    S = limit_surface_mesh(mesh, 3)  # child 4 f + i of face f: the 64 quads of face f are 64 f .. 64 f + 63
    V, F = np.asarray(S.vertices), S.faces
    a = 0.5 * (np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1)
               + np.linalg.norm(np.cross(V[F[:, 2]] - V[F[:, 0]], V[F[:, 3]] - V[F[:, 0]]), axis=1))
    return a.reshape(mesh.n_faces, 64).sum(axis=1)


def test_dense_samples_are_limit_points_spread_by_area(fit_dense, bunny):
    mesh, S, finder = bunny
    n = 20_000
    X = fit_dense.sample_by_area(S, mesh.n_faces, n, seed=3)
    r = finder.query(X)
    assert X.shape == (n, 3) and float(r.distance.max()) < 1e-9  # on the true surface
    area = _face_areas_level3(mesh)
    groups = np.arange(mesh.n_faces) * 20 // mesh.n_faces  # 20 groups of about 100 faces
    share = np.bincount(groups, weights=area) / area.sum()
    got = np.bincount(groups[r.face], minlength=20) / n
    # binomial standard deviation of a 5 % share over 20,000 points: 0.15 %; allow 4 of them
    assert np.abs(got - share).max() < 0.006, (got - share).round(4).tolist()
    # a sampler by parameter instead of area (every face the same share) is far off: the check can fail
    assert np.abs(np.bincount(groups) / mesh.n_faces - share).max() > 0.006


def test_fit_dense_smoke_run_prints_the_true_surface_figures(fit_dense, capsys):
    """The script's tiny run (1,000 points, 5 steps: a fit far from equilibrium, which the figures must show)."""
    fit_dense.main(["--smoke"])
    out = capsys.readouterr().out
    m = re.search(r"n=\s*1000 .*>1%\s+([\d.]+) % of area, >2%\s+([\d.]+) %, max\s+([\d.]+) %", out)
    assert m, out
    over1, over2, worst = (float(t) for t in m.groups())
    assert 100 >= over1 >= over2 > 1.0 and worst > 2.0  # 5 steps from the small cube: far off the bunny
    assert "stopped at the step cap" in out


def _fit_and_judge(fit_dense, bunny, n, **kw):
    from ccproof.apps.dynamics.fit import fit_points

    mesh, S, finder = bunny
    X = fit_dense.sample_by_area(S, mesh.n_faces, n, seed=0)
    res = fit_points(X, levels=1, **kw)
    return res, fit_dense.judge(res, finder)  # the fitted limit surface against the true one (closest points)


# 64 s on a quiet machine, about 7 minutes under load (400 + 80 steps); also: python scripts/fit_dense.py --n 10000
@pytest.mark.slow
def test_dense_bunny_fit_stays_on_the_true_surface_both_ways(fit_dense, bunny):
    """10^4 exact points off the bunny: the default (two-way) fit spans no concavity: measured 0.05 % of its area
    more than 2 % of the diameter off the true surface, max 2.58 %, data -> surface 1.35 %, no warning."""
    res, q = _fit_and_judge(fit_dense, bunny, 10_000)
    assert q["over2"] < 0.005 and q["max"] < 4.0 and q["rms"] < 0.3  # fitted surface -> true surface
    assert res.max_error_percent < 2.0  # data (on the true surface) -> fitted surface
    assert res.warnings == []


@pytest.mark.slow  # 40 s on a quiet machine, about 3 minutes under load
def test_dense_bunny_one_way_fit_webs_across_the_ear_concavity(fit_dense, bunny):
    """The paper's data springs alone (the fit before the surface -> data springs, 229 + 73 steps): a web across a
    concavity that the data -> surface error does not show; the fit's own stray report sees it (8.0 % of the area)."""
    from ccproof.apps.dynamics.fit import FitSprings

    res, q = _fit_and_judge(fit_dense, bunny, 10_000, springs=FitSprings(surface_total=0.0))
    assert q["over2"] > 0.04 and q["max"] > 6.0  # measured 6.89 % of the area, max 9.87 %: the judge above fails
    assert res.max_error_percent < 2.0  # measured 1.34 %: the headline error does not show it
    assert any("spans a concavity" in w for w in res.warnings)


def test_spring_points_cap_which_points_pull_not_which_are_judged(capsys, tmp_path):
    """A cloud larger than ``spring_points``: a fixed random subset carries the data springs (the same on every
    run), while the errors and the stray report cover every point. With all points the fit differs."""
    from ccproof.apps.dynamics.fit import Evolution, FitSprings, fit_points
    from ccproof.apps.dynamics.shapes import synthetic_range_data
    from ccproof.cli import main
    from ccproof.errors import CCProofError

    X = synthetic_range_data("ellipsoid", 600)
    m = X.shape[0]
    seen, four = [], Evolution(max_steps=4)
    res = fit_points(X, levels=0, springs=FitSprings(points=100), evolution=four,
                     callback=lambda *a: seen.append(a[3].copy()))
    again = fit_points(X, levels=0, springs=FitSprings(points=100), evolution=four)
    full = fit_points(X, levels=0, springs=FitSprings(points=None), evolution=four)
    assert res.parameters["spring_points"] == 100 and full.parameters["spring_points"] == m
    assert res.data_distances.shape == (m,) and full.data_distances.shape == (m,)  # all points judged
    assert np.array_equal(res.normalized_state, again.normalized_state)  # a fixed subset
    assert np.array_equal(seen[-1], res.normalized_state)
    assert not np.allclose(res.normalized_state, full.normalized_state)  # the subset is what pulls
    for bad in (3, 2.5, -1):
        with pytest.raises(CCProofError, match="spring_points must be an integer >= 4 or None"):
            fit_points(X, levels=0, springs=FitSprings(points=bad), evolution=Evolution(max_steps=1))
    pts = tmp_path / "e.xyz"
    np.savetxt(pts, X)
    assert main(["fit", str(pts), "--out", str(tmp_path / "o.obj"), "--spring-points", "2", "--no-progress"]) == 2
    assert "--spring-points must be 0 (all) or at least 4, got 2" in capsys.readouterr().err


# 78 s on a quiet machine, about 6 minutes under load (423 + 109 steps); also: python scripts/fit_dense.py --n 100000
@pytest.mark.slow
def test_dense_bunny_fit_of_100k_points_on_a_spring_subset(fit_dense, bunny):
    """10^5 exact points: the data springs on the default 10^4 of them (every point re-projected at every step
    took 6.6 s per step, an hour per fit), judged on all of them and against the true surface: measured 0.03 % of
    the area beyond 2 %, max 2.12 %, data -> surface 1.68 %. The fit's own stray report (distances to the data,
    stray distance 3 spacings = 0.53 %) sees 3.8 % of the area beyond it, up to 2.3 %, and says where."""
    res, q = _fit_and_judge(fit_dense, bunny, 100_000)
    assert res.parameters["spring_points"] == 10_000 and res.data_distances.shape == (100_000,)
    assert q["over2"] < 0.005 and q["max"] < 4.0 and q["rms"] < 0.3
    assert res.max_error_percent < 2.5
    assert all("fitted control faces (most:" in w for w in res.warnings if "strays" in w)
