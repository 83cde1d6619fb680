"""Exact evaluation of tagged polygon meshes against OpenSubdiv 3.6 (tests/data/osd_features).

OpenSubdiv's own regression shapes with creases, semi-sharp creases (uniform and Chaikin), corners,
holes, the three boundary modes, triangles (Catmark and smooth-triangle rules) and n-gons, read
from OBJ with OpenSubdiv's tag lines. Reference values are inputs (OpenSubdiv Far, isolation 10,
and the 15-level ``deep`` values), never our output. Tolerances relative to the bounding-box
diagonal of the control mesh: positions 1e-12, first derivatives 1e-10 on every sample marked
``exact`` and on the ``deep`` values where those are outside an end cap; vertex limits 1e-13.
"""

import functools
import json

import numpy as np
import pytest

from ccproof.errors import CCProofError
from ccproof.evaluate import limit_surface
from ccproof.evaluate.backend import available_backends
from ccproof.evaluate.surface import LimitSurface
from ccproof.mesh.io import read_obj_tagged
from ccproof.mesh.polymesh import PolyMesh

FAST = ["cube_creases0", "cube_corner2", "cube_corner4", "dart_edgeonly", "edgecorner", "edgenone",
        "hole_test2", "nonquads", "pyramid_creases1", "chaikin1", "cubes_infsharp"]
SLOW = ["inf_crease1", "smoothtris1", "xord_boundary", "helmet"]
SHAPES = FAST + [pytest.param(s, marks=pytest.mark.slow) for s in SLOW]


def _ref(refdir, name):
    return json.loads((refdir / "osd_features" / f"osd_limit_catmark_{name}.json").read_text())


@functools.cache
def _surface(refdir, name):
    mesh = read_obj_tagged(refdir / "osd_features" / "meshes" / f"catmark_{name}.obj")
    return mesh, limit_surface(mesh)


def _rows(d):
    rows = []
    for s in d["samples"]:
        if s["exact"]:
            rows.append((s["ptex"], s["s"], s["t"], s["P"], s["Ps"], s["Pt"]))
        elif s.get("deep") and not s["deep"]["endcap"]:
            q = s["deep"]
            rows.append((s["ptex"], s["s"], s["t"], q["P"], q["Ps"], q["Pt"]))
    return rows


@pytest.mark.parametrize("name", SHAPES)
def test_shape_matches_opensubdiv(refdir, name):
    d = _ref(refdir, name)
    mesh, S = _surface(refdir, name)
    assert isinstance(S.mesh, PolyMesh) or not mesh.has_tags
    assert mesh.n_ptex == d["num_ptex_faces"]
    assert [f["ptex"] for f in d["faces"]] == mesh.ptex_start[:-1].tolist()
    rows = _rows(d)
    assert len(rows) >= 400
    f, u, v = (np.array([r[i] for r in rows]) for i in range(3))
    out = S.evaluate(f, u, v, derivatives=1)
    diag = mesh.bounding_box_diagonal
    for key, i, tol in (("P", 3, 1e-12), ("Pu", 4, 1e-10), ("Pv", 5, 1e-10)):
        err = np.abs(out[key] - np.array([r[i] for r in rows])).max() / diag
        assert err <= tol, (name, key, err)
    VL = np.array(d["vertex_limit"], dtype=float)
    ok = np.isfinite(VL).all(axis=1)
    err = np.abs(S.vertex_limits()[ok] - VL[ok]).max() / diag
    assert err <= 1e-13, (name, "vertex limits", err)


def test_ngon_centres_match_opensubdiv(refdir):
    for name in ("nonquads", "pyramid_creases1"):
        d = _ref(refdir, name)
        mesh, S = _surface(refdir, name)
        for f, P in d["ngon_centre_limit"].items():
            f = int(f)
            k = int(mesh.sizes[f])
            r = S.evaluate(np.arange(k) + mesh.ptex_start[f], np.ones(k), np.ones(k), 0)["P"]
            assert np.abs(r - np.array(P)).max() <= 1e-13 * mesh.bounding_box_diagonal


def test_holes_are_refused_by_name(refdir):
    mesh, S = _surface(refdir, "hole_test2")
    hole = int(np.flatnonzero(mesh.is_hole)[0])
    with pytest.raises(CCProofError, match=rf"point 1: ptex face {hole} \(face {hole}\) is a hole"):
        S.evaluate([0, hole], [0.5, 0.5], [0.5, 0.5])


@pytest.mark.parametrize("backend", ["c", "numba"])
def test_backends_and_threads_agree_on_tagged_meshes(refdir, backend):
    if backend not in available_backends():
        pytest.skip(f"backend {backend!r} not available in this install")
    mesh, S = _surface(refdir, "pyramid_creases1")
    rng = np.random.default_rng(3)
    n = 5000
    f = rng.integers(0, mesh.n_ptex, n)
    s, t = rng.random(n), rng.random(n)
    s[:500] = 0.5 ** rng.integers(0, 80, 500)  # deep layers at corners
    t[:500] = s[:500] * rng.random(500)
    a = S.evaluate(f, s, t, 2, backend="numpy")
    b = S.evaluate(f, s, t, 2, backend=backend, threads=1)
    c = S.evaluate(f, s, t, 2, backend=backend, threads=3)
    for k in a:
        assert np.array_equal(a[k], b[k]), k
        assert np.array_equal(b[k], c[k]), k


@pytest.mark.parametrize("name", ["cube", "sector_k3", "sector_k5", "torus_8x6"])
def test_tagged_evaluator_on_the_quad_references(refdir, name):
    """The tagged evaluator on untagged all-quad meshes (tests/data/osd_limit_*.json)."""
    from ccproof.mesh.io import read_mesh

    d = json.loads((refdir / f"osd_limit_{name}.json").read_text())
    mesh = read_mesh(refdir / "meshes" / f"{name}.obj")
    S = LimitSurface(mesh)
    rows = []
    for s in d["samples"]:
        q = s if not s["endcap"] else (s["deep"] if not s["deep"]["endcap"] else None)
        if q is not None:
            rows.append((s["face"], s["s"], s["t"], q["P"], q["Ps"], q["Pt"]))
    f, u, v = (np.array([r[i] for r in rows]) for i in range(3))
    out = S.evaluate(f, u, v, 1)
    diag = mesh.bounding_box_diagonal
    for key, i, tol in (("P", 3, 1e-12), ("Pu", 4, 1e-10), ("Pv", 5, 1e-10)):
        assert np.abs(out[key] - np.array([r[i] for r in rows])).max() / diag <= tol, key
    VL = np.array(d["vertex_limit"], dtype=float)
    assert np.abs(S.vertex_limits() - VL).max() / diag <= 1e-13


def test_disk_cache_gives_the_computed_scheme(tmp_path, monkeypatch):
    """A corner scheme read back from the disk cache is the computed one, bit for bit."""
    from ccproof.evaluate import _diskcache, local

    monkeypatch.setenv("CCPROOF_CACHE", str(tmp_path))
    V = [[np.cos(a), np.sin(a), 0.1 * np.cos(3 * a)] for a in np.linspace(0, 2 * np.pi, 5, endpoint=False)]
    m = PolyMesh([[0, 0, 0.3]] + V, [[0, 1 + i, 1 + (i + 1) % 5] for i in range(5)], creases={(0, 1): 12})
    local.corner_scheme.cache_clear()
    a = LimitSurface(m)
    files = sorted(tmp_path.glob("*"))
    assert files
    local.corner_scheme.cache_clear()
    b = LimitSurface(m)  # now read from the cache
    assert sorted(tmp_path.glob("*")) == files
    for x, y in zip(a._table, b._table):
        assert np.array_equal(x, y)
    key = b._schemes[0]
    computed = a._schemes[0]
    assert key is not computed and key.A == computed.A  # the exact matrix, read on first use
    assert np.array_equal(key.tangent_masks, computed.tangent_masks)
    monkeypatch.setenv("CCPROOF_CACHE", "off")
    assert _diskcache.cache_dir() is None and key.A.nrows() == key.size
