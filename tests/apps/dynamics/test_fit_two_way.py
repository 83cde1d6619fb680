"""Fits judged in both directions: a cloud with a deep pit, fitted with data springs only (the surface webs across
the pit while the data -> surface error stays small) and with the surface -> data springs (it follows the pit).

The true surface is known in closed form here (a unit sphere whose top is pushed down into a pit, a surface of
revolution); the fitted limit surface is compared with a dense sampling of it, independently of the fit's own
reports.
"""

import re

import numpy as np
import pytest
from scipy.spatial import cKDTree

from ccproof.apps.dynamics.cloud import limit_surface_mesh
from ccproof.apps.dynamics.fit import FitSprings, fit_points
from ccproof.apps.dynamics.forces import Springs, SurfaceToDataSprings
from ccproof.apps.dynamics.meshes import paper_initial_model
from ccproof.apps.dynamics.model import DynamicSurface
from ccproof.errors import CCProofError

#: pit depth (the pole goes from z = 1 down to z = 1 - DEPTH) and its polar half-angle
DEPTH, HALF_ANGLE = 1.2, 0.35
#: the unit sphere encloses the pitted sphere and the equator lies on it: the enclosing-sphere diameter is 2
DIAMETER = 2.0


def _profile(t):
    s = np.clip(t / HALF_ANGLE, 0.0, 1.0)
    return np.sin(t), np.cos(t) - DEPTH * (1 - s * s) ** 2


def _pitted_sphere(m, seed):
    """``m`` area-uniform points of the pitted sphere (inverse transform of the area along the profile)."""
    rng = np.random.default_rng(seed)
    th = np.linspace(0.0, np.pi, 20001)
    rho, z = _profile(th)
    w = rho * np.hypot(np.gradient(rho, th), np.gradient(z, th))
    cdf = np.concatenate([[0.0], np.cumsum(0.5 * (w[1:] + w[:-1]) * np.diff(th))])
    t = np.interp(rng.random(m) * cdf[-1], cdf, th)
    r, zz = _profile(t)
    ph = rng.random(m) * 2 * np.pi
    return np.stack([r * np.cos(ph), r * np.sin(ph), zz], axis=1)


X_DATA = _pitted_sphere(1500, seed=0)


@pytest.fixture(scope="module")
def truth():
    """A dense sampling of the true surface (spacing about 0.4 % of the diameter) in a k-d tree."""
    return cKDTree(_pitted_sphere(200_000, seed=1))


def _off_true_surface(res, truth):
    """Area fraction of the fitted limit surface farther than 2 % of the diameter from the true surface, and the
    largest distance (% of the diameter): the limit surface sampled at level 3, quad areas by two triangles."""
    S = limit_surface_mesh(res.mesh, 3)
    V, F = np.asarray(S.vertices), S.faces
    quad = 0.5 * (np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1)
                  + np.linalg.norm(np.cross(V[F[:, 2]] - V[F[:, 0]], V[F[:, 3]] - V[F[:, 0]]), axis=1))
    d, _ = truth.query(V[F].mean(axis=1))  # the quads' centroids
    return float(quad[d > 0.02 * DIAMETER].sum() / quad.sum()), 100 * float(d.max()) / DIAMETER


def _data_to_surface_percent(res):
    """Independent upper bound of the data -> surface distance: to the nearest of the level-4 limit points."""
    d, _ = cKDTree(limit_surface_mesh(res.mesh, 4).vertices).query(X_DATA)
    return 100 * float(d.max()) / DIAMETER


def test_one_way_fit_webs_across_the_pit_with_a_small_data_error(truth):
    """The paper's data springs alone: the headline error is small, the surface is not (what the report exposes)."""
    res = fit_points(X_DATA, levels=1, springs=FitSprings(surface_total=0.0))
    far, worst = _off_true_surface(res, truth)
    assert res.max_error_percent < 3.0 and _data_to_surface_percent(res) < 3.5  # data -> surface looks fine
    assert far > 0.045 and worst > 14.0  # measured 6.37 % of the area, up to 17.9 %: a web across the pit
    assert res.surface_max_percent > 14.0 and res.surface_report["stray_fraction"] > 0.02  # and the report sees it
    assert any("strays from the data" in w for w in res.warnings)
    # the warning says where: the control faces it names are among those whose limit surface lies more than 2 %
    # of the diameter off the true surface (level-3 quads, child 4 f + i: quad q lies in control face q // 64)
    warn = next(w for w in res.warnings if "strays from the data" in w)
    where = re.search(r"on (\d+) of the (\d+) fitted control faces \(most: ([\d, .]+)\) around \(([^)]*)\)", warn)
    assert where and "spans a concavity" in warn, warn
    named = {int(t) for t in where.group(3).replace("...", "").split(",") if t.strip()}
    S = limit_surface_mesh(res.mesh, 3)
    d, _ = truth.query(np.asarray(S.vertices)[S.faces].mean(axis=1))
    off = set((np.flatnonzero(d > 0.02 * DIAMETER) // 64).tolist())
    assert len(named & off) >= 0.75 * len(named), (sorted(named), sorted(off))
    assert 0 < int(where.group(1)) < int(where.group(2)) == res.mesh.n_faces


@pytest.mark.slow  # about 20 s (288 + 32 steps)
def test_two_way_fit_follows_the_pit_in_both_directions(truth):
    res = fit_points(X_DATA, levels=1)  # the surface -> data springs are on by default
    far, worst = _off_true_surface(res, truth)
    assert far < 0.01 and worst < 6.0  # measured 0.10 % of the area, up to 3.77 % (one-way: 6.37 %, 17.9 %)
    assert res.max_error_percent < 1.6 and _data_to_surface_percent(res) < 1.6  # measured 1.02 % (one-way 2.29)
    assert res.surface_max_percent < 9.0 and res.surface_report["stray_fraction"] < 0.005  # 7.83 %, 0.15 %
    # RMS: measured 0.090 % and 2.68 % (one-way: 0.211 %, 3.37 %; surface -> data is measured to the nearest
    # of the discrete data points, 2.2 % of the diameter apart)
    assert res.data_rms_percent < 0.15 and res.surface_rms_percent < 3.0
    assert res.warnings == [] and res.parameters["surface_spring_total"] == 5.0
    assert "data springs alone for the first 85" in res.levels[0].reason


def test_surface_to_data_springs_pull_every_sample_to_its_nearest_data_point_by_area():
    m = DynamicSurface(paper_initial_model())
    X = np.random.default_rng(3).normal(size=(50, 3))
    slack = 0.3
    rev = SurfaceToDataSprings(m, X, 2.5, per_side=3, slack=slack)
    P = m.vertices + np.random.default_rng(4).normal(scale=0.01, size=m.vertices.shape)
    s, dist = rev.springs(P)
    ev = m.evaluate(rev.faces, rev.u, rev.v, derivatives=1, P=P)  # the model's evaluator, not the rows
    brute = np.linalg.norm(ev["P"][:, None, :] - X[None, :, :], axis=2)
    near = X[brute.argmin(axis=1)]
    assert np.allclose(dist, brute.min(axis=1)) and s.count == 96 * 9
    far = dist > slack
    assert 0 < far.sum() < far.size  # both kinds of samples
    # a far sample: anchored on the segment to its nearest data point, slack short of it; a near one: no force
    expect = near + slack * (ev["P"] - near) / dist[:, None]
    assert np.allclose(s.anchors[far], expect[far]) and np.allclose(s.lengths(P)[far], dist[far] - slack)
    area = np.linalg.norm(np.cross(ev["Pu"], ev["Pv"]), axis=1)
    assert np.allclose(s.stiffness, np.where(far, 2.5 * area / area.sum(), 0.0))
    # the generalized force is J^T k (d - s) at the samples: moving P along it lowers the spring energy
    F = s.force(P)
    assert s.energy(P + 1e-4 * F) < s.energy(P)
    with pytest.raises(CCProofError, match="finite and >= 0"):
        SurfaceToDataSprings(m, X, float("nan"))
    a = Springs(m, [0], [0.5], [0.5], [[0, 0, 1.0]], 1.0)
    with pytest.raises(CCProofError, match="two different models"):
        Springs.stacked(a, Springs(DynamicSurface(paper_initial_model()), [0], [0.5], [0.5], [[0, 0, 1.0]], 1.0))


def test_cli_fit_reports_both_directions_and_checks_surface_spring(tmp_path, capsys):
    from ccproof.cli import main

    pts = tmp_path / "pit.xyz"
    np.savetxt(pts, X_DATA[:300])
    out = tmp_path / "fit.obj"
    for bad in ("-1", "nan", "inf"):
        assert main(["fit", str(pts), "--out", str(out), "--surface-spring", bad, "--no-progress"]) == 2
        assert f"--surface-spring must be a finite number >= 0, got {float(bad)}" in capsys.readouterr().err
    assert not out.exists()
    rc = main(["fit", str(pts), "--out", str(out), "--levels", "0", "--max-steps", "6", "--no-progress",
               "--surface-spring", "0.5"])
    cap = capsys.readouterr()
    assert rc == 0 and "data -> surface (300 points): max" in cap.out and ", RMS " in cap.out
    assert "area-weighted mean" in cap.out and "RMS" in cap.out.split("surface -> data (")[1]
