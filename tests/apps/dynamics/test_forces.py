"""Data springs attach to the globally nearest limit points (ccproof.evaluate.closest) in the model's parameters.

References independent of the code under test: the FEM model's own limit evaluation at the returned
parameters (its special elements, not ccproof.evaluate's layers), and a brute-force nearest point of
the FEM model's limit surface (dense samples of every face with a patch, refined by grid search;
positions only, no derivatives, no Newton, no bounding cells).
"""

import numpy as np
import pytest
from scipy.spatial import cKDTree

from ccproof.apps.dynamics.forces import ModelClosestPoints, Springs
from ccproof.apps.dynamics.meshes import open_surface_valence5, paper_initial_model
from ccproof.apps.dynamics.model import DynamicSurface
from ccproof.errors import CCProofError


def _perturbed(mesh, seed, amp):
    rng = np.random.default_rng(seed)
    return mesh.with_vertices(np.asarray(mesh.vertices) + amp * rng.standard_normal(mesh.vertices.shape))


def brute_force(model, P, X, level=5, per_point=6):
    """Nearest point of the model's limit surface: samples on a (2^level + 1)^2 grid per patch face, the
    nearest samples in up to ``per_point`` faces (more than the valences: near an extraordinary vertex
    the minimum can lie in any face of its fan), each refined by a shrinking 9 x 9 grid search."""
    ev = model.evaluator(P)
    faces = np.flatnonzero(model.layout.face_kind > 0)
    L = 2**level
    t = np.arange(L + 1) / L
    U, V = np.meshgrid(t, t, indexing="ij")
    fs = np.repeat(faces, (L + 1) ** 2)
    us, vs = np.tile(U.ravel(), faces.size), np.tile(V.ravel(), faces.size)
    _, J = cKDTree(ev.evaluate(fs, us, vs)["P"]).query(X, k=64)
    pp, jj = [], []
    for p in range(X.shape[0]):
        seen = []
        for j in J[p]:
            if fs[j] not in seen:
                seen.append(fs[j])
                pp.append(p)
                jj.append(j)
            if len(seen) == per_point:
                break
    pp, jj = np.array(pp), np.array(jj)
    f, cu, cv = fs[jj], us[jj].copy(), vs[jj].copy()
    g = np.linspace(-1.0, 1.0, 9)
    h = 1.0 / L
    while h > 1e-14:
        A = np.broadcast_to(np.clip(cu[:, None, None] + h * g[None, :, None], 0, 1), (f.size, 9, 9))
        B = np.broadcast_to(np.clip(cv[:, None, None] + h * g[None, None, :], 0, 1), (f.size, 9, 9))
        Q = ev.evaluate(np.repeat(f, 81), A.ravel(), B.ravel())["P"].reshape(f.size, 81, 3)
        k = np.argmin(np.linalg.norm(Q - X[pp][:, None], axis=2), axis=1)
        cu, cv = A.reshape(f.size, 81)[np.arange(f.size), k], B.reshape(f.size, 81)[np.arange(f.size), k]
        h /= 3.0
    d = np.linalg.norm(ev.evaluate(f, cu, cv)["P"] - X[pp], axis=1)
    best = np.full(X.shape[0], np.inf)
    np.minimum.at(best, pp, d)
    return best


def _queries(model, P, rng, n):
    """Points off the limit surface: near the extraordinary vertices (parameters down to 1e-6 of the EV
    corner of special faces) and anywhere on faces with a patch, moved along the normal by up to 0.05."""
    lay = model.layout
    ev = model.evaluator(P)
    spc = np.flatnonzero(lay.face_kind == 2)
    f1 = rng.choice(spc, n // 2)
    s, t = 10.0 ** rng.uniform(-6, -1, (2, n // 2))
    corner = lay.face_corner[f1]
    CORNER = np.array([(0, 0), (1, 0), (1, 1), (0, 1)], dtype=float)
    eu = CORNER[(corner + 1) % 4] - CORNER[corner]
    evv = CORNER[(corner + 3) % 4] - CORNER[corner]
    uv = CORNER[corner] + s[:, None] * eu + t[:, None] * evv
    f2 = rng.choice(np.flatnonzero(lay.face_kind > 0), n - n // 2)
    f = np.r_[f1, f2]
    u, v = np.r_[uv[:, 0], rng.random(f2.size)], np.r_[uv[:, 1], rng.random(f2.size)]
    r = ev.evaluate(f, u, v, 1)
    N = np.cross(r["Pu"], r["Pv"])
    N /= np.linalg.norm(N, axis=1)[:, None]
    return r["P"] + rng.uniform(-0.05, 0.05, (f.size, 1)) * N


@pytest.mark.parametrize("make", [paper_initial_model, open_surface_valence5])
def test_closest_points_are_the_models_own_nearest_limit_points(make):
    mesh = _perturbed(make(), seed=1, amp=0.03)
    model = DynamicSurface(mesh)
    P = np.asarray(mesh.vertices)
    rng = np.random.default_rng(2)
    X = _queries(model, P, rng, 120)
    f, u, v, pts, dist = ModelClosestPoints(model).query(P, X)
    # the parameters are the model's: attachment on faces with a patch, its own limit point there
    assert (model.layout.face_kind[f] > 0).all()
    own = model.evaluate(f, u, v, 1, P=P)
    assert np.abs(own["P"] - pts).max() < 1e-12
    springs = Springs(model, f, u, v, X, 1.0)
    assert np.abs(springs.jacobian @ P - pts).max() < 1e-12
    np.testing.assert_allclose(springs.lengths(P), dist, rtol=1e-12, atol=1e-15)
    # global: no point of the model's surface is nearer (brute force), and the answer is as near
    ref = brute_force(model, P, X)
    assert (dist <= ref + 1e-12).all()
    assert (ref <= dist + 1e-9).all()
    # first-order optimality in the model's derivatives, away from face edges
    R = X - own["P"]
    inner = (u > 1e-6) & (u < 1 - 1e-6) & (v > 1e-6) & (v < 1 - 1e-6) & (dist > 1e-6)
    for k in ("Pu", "Pv"):
        g = np.einsum("ij,ij->i", R, own[k]) / (dist * np.linalg.norm(own[k], axis=1))
        assert np.abs(g[inner]).max() < 1e-7, k


def test_faces_without_patch_are_not_attached():
    """On an open mesh the evaluator's surface continues over the boundary faces (boundary rules), the
    model has no patch there: points nearest to those faces attach to the nearest patch face."""
    from ccproof.evaluate import LimitSurface

    mesh = open_surface_valence5()
    model = DynamicSurface(mesh)
    P = np.asarray(mesh.vertices)
    kind = model.layout.face_kind
    S = LimitSurface(mesh)
    rng = np.random.default_rng(3)
    fb = rng.choice(np.flatnonzero(kind == 0), 40)
    X = S.evaluate(fb, rng.random(40), rng.random(40), 0)["P"] + 0.01
    assert (kind[S.closest_points(X).face] == 0).any()  # unrestricted, some land on boundary faces
    f, u, v, pts, dist = ModelClosestPoints(model).query(P, X)
    assert (kind[f] > 0).all()
    assert np.abs(model.evaluate(f, u, v, P=P)["P"] - pts).max() < 1e-12
    assert (dist <= brute_force(model, P, X) + 1e-12).all()


def test_to_nearest_and_bad_input():
    model = DynamicSurface(paper_initial_model())
    P = model.vertices
    X = np.random.default_rng(4).standard_normal((30, 3))
    sp = Springs.to_nearest(model, P, X, 0.5)
    f, u, v, pts, dist = ModelClosestPoints(model).query(P, X)
    assert np.array_equal(sp.faces, f) and np.abs(sp.jacobian @ P - pts).max() < 1e-12
    assert sp.energy(P) == pytest.approx(0.5 * 0.5 * float(np.sum(dist**2)), rel=1e-12)
    with pytest.raises(CCProofError, match="control points must have shape"):
        ModelClosestPoints(model).query(P[:5], X)
    with pytest.raises(CCProofError, match="non-finite coordinate at point 2"):
        ModelClosestPoints(model).query(P, np.r_[X[:2], [[np.nan, 0, 0]]])


def test_tagged_model_moves_its_evaluator_without_a_rebuild(refdir, monkeypatch):
    """On a tagged control mesh (creases, a dart, boundaries) the evaluator is built once and moved to every
    state (``LimitSurface.with_vertices``: no build per query); the answers are those of a finder on a surface
    built from scratch on the moved mesh, bit for bit, and the attachment points are the FEM model's own
    limit points (its tagged elements, not ccproof.evaluate)."""
    from ccproof.apps.control_file import read_control_mesh
    from ccproof.apps.dynamics.forces import _evaluated_mesh
    from ccproof.evaluate import LimitSurface
    from ccproof.evaluate.closest import ClosestPointFinder

    mesh, _ = read_control_mesh(refdir / "osd_features/meshes/catmark_dart_edgeonly.obj")
    model = DynamicSurface(mesh, levels=2)
    finder = ModelClosestPoints(model)
    builds = []
    init = LimitSurface.__init__
    monkeypatch.setattr(LimitSurface, "__init__", lambda self, *a, **k: (builds.append(1), init(self, *a, **k))[1])
    rng = np.random.default_rng(6)
    V = np.asarray(mesh.vertices)
    for _ in range(2):
        P = V + 0.05 * rng.standard_normal(V.shape)
        X = LimitSurface(_evaluated_mesh(mesh)).evaluate(rng.integers(0, mesh.n_faces, 60), rng.random(60),
                                                         rng.random(60))["P"] + 0.05 * rng.standard_normal((60, 3))
        builds.clear()
        f, u, v, pts, dist = finder.query(P, X)
        assert not builds  # moved, not rebuilt
        fresh = LimitSurface(_evaluated_mesh(mesh.with_vertices(P)))
        faces = np.flatnonzero(model.layout.face_kind > 0)
        r = ClosestPointFinder(fresh, cells=finder.cells,
                               faces=None if faces.size == mesh.n_faces else faces).query(X)
        for a, b in ((f, r.face), (u, r.u), (v, r.v), (pts, r.P), (dist, r.distance)):
            assert np.array_equal(a, b)
        own = model.evaluate(f, u, v, 0, P=P)["P"]
        assert np.abs(own - pts).max() < 1e-12 * (1 + np.abs(P).max())
