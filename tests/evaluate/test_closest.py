"""Closest points on the limit surface (ccproof.evaluate.closest) against brute force.

The reference is independent of the Newton descent under test: the limit surface sampled on a
64 x 64 grid per face (level 6), the nearest samples in up to 4 different faces, each refined by a
grid search (9 x 9 points over +-h, h divided by 3 per step, down to 1e-15), all with the exact
evaluator's positions only (no derivatives, no Newton).
"""

import numpy as np
import pytest
from scipy.spatial import cKDTree

from ccproof.errors import CCProofError
from ccproof.evaluate import limit_surface
from ccproof.evaluate.closest import ClosestPointFinder, closest_points

MESHES = ["cube", "sector_k3", "sector_k5", "sector_k6", "torus_8x6"]


@pytest.fixture(scope="module")
def surfaces(refdir):
    return {name: limit_surface(refdir / "meshes" / f"{name}.obj") for name in MESHES}


def brute_force(S, X, level=6, faces_per_point=4, faces=None):
    """Nearest limit point (on ``faces``, default all) by dense sampling plus grid-search refinement
    (positions only)."""
    faces = np.arange(S.mesh.n_faces) if faces is None else np.asarray(faces)
    nf = faces.size
    L = 2**level
    t = np.arange(L + 1) / L
    U, V = np.meshgrid(t, t, indexing="ij")
    fu = np.repeat(faces, (L + 1) ** 2)
    uu, vv = np.tile(U.ravel(), nf), np.tile(V.ravel(), nf)
    T = cKDTree(S.evaluate(fu, uu, vv, 0)["P"])
    _, J = T.query(X, k=min(256, fu.size))
    pairs = []  # (point, sample) for the nearest samples in distinct faces
    for p in range(X.shape[0]):
        seen = []
        for j in J[p]:
            if fu[j] not in seen:
                seen.append(fu[j])
                pairs.append((p, j))
            if len(seen) == faces_per_point:
                break
    pp = np.array([a for a, _ in pairs])
    jj = np.array([b for _, b in pairs])
    f, cu, cv = fu[jj], uu[jj].copy(), vv[jj].copy()
    h = 1.0 / L
    g = np.linspace(-1.0, 1.0, 9)
    while h > 1e-15:
        A = np.clip(cu[:, None, None] + h * g[None, :, None], 0, 1)
        B = np.clip(cv[:, None, None] + h * g[None, None, :], 0, 1)
        A, B = np.broadcast_to(A, (f.size, 9, 9)), np.broadcast_to(B, (f.size, 9, 9))
        Q = S.evaluate(np.repeat(f, 81), A.ravel(), B.ravel(), 0)["P"].reshape(f.size, 81, 3)
        d = np.linalg.norm(Q - X[pp][:, None], axis=2)
        k = np.argmin(d, axis=1)
        cu, cv = A.reshape(f.size, 81)[np.arange(f.size), k], B.reshape(f.size, 81)[np.arange(f.size), k]
        h /= 3.0
    P = S.evaluate(f, cu, cv, 0)["P"]
    d = np.linalg.norm(P - X[pp], axis=1)
    best = np.full(X.shape[0], np.inf)
    bP = np.zeros_like(X)
    for i in range(pp.size):
        if d[i] < best[pp[i]]:
            best[pp[i]], bP[pp[i]] = d[i], P[i]
    return best, bP


def _points(S, n, seed):
    """Uniform in the bounding box of the limit surface enlarged by 5 %, plus points near the vertices."""
    rng = np.random.default_rng(seed)
    P = S.evaluate(np.repeat(np.arange(S.mesh.n_faces), 9), np.tile(np.repeat([0, 0.5, 1], 3), S.mesh.n_faces),
                   np.tile([0, 0.5, 1.0], 3 * S.mesh.n_faces), 0)["P"]
    lo, hi = P.min(0), P.max(0)
    ext = hi - lo
    X = lo - 0.05 * ext + rng.random((n, 3)) * 1.1 * ext
    Vl = S.vertex_limits()
    Vn = S.vertex_normals()
    ev = np.flatnonzero(~S.mesh.is_regular_vertex)
    ev = ev if ev.size else np.arange(S.mesh.n_vertices)
    v = rng.choice(ev, size=n // 3)
    off = 0.02 * np.linalg.norm(ext) * (rng.random((n // 3, 1)) * Vn[v] + 0.3 * rng.standard_normal((n // 3, 3)))
    Y = Vl[v] + np.nan_to_num(off)
    return np.concatenate([X, Y])


@pytest.mark.parametrize("name", MESHES)
def test_against_brute_force(surfaces, name):
    S = surfaces[name]
    X = _points(S, 45, seed=MESHES.index(name))
    res = closest_points(S, X)
    ref, refP = brute_force(S, X)
    rel = (res.distance - ref) / ref
    assert rel.max() <= 1e-12, f"{name}: distance above brute force by {rel.max():.3g} (relative)"
    # both are distances to true surface points; ours below the reference would mean the reference
    # missed the minimum (then this comparison is not a check): on these small meshes it never does
    assert rel.min() >= -1e-12, f"{name}: the brute-force reference missed the minimum by {-rel.min():.3g}"
    # the same nearest point (a region, not necessarily the same face: points on shared edges)
    diag = S.mesh.bounding_box_diagonal
    assert np.linalg.norm(res.P - refP, axis=1).max() <= 1e-5 * diag
    # the returned point is on the surface at the returned parameter, distance consistent
    P = S.evaluate(res.face, res.u, res.v, 0)["P"]
    np.testing.assert_array_equal(P, res.P)
    np.testing.assert_allclose(np.linalg.norm(X - P, axis=1), res.distance, rtol=0, atol=0)


def _on_boundary(S, face, u, v):
    """(point on a boundary edge, unit direction of that edge in (u, v)) for quad meshes."""
    twin = S.mesh.twin.reshape(-1, 4)
    side = np.stack([v == 0.0, u == 1.0, v == 1.0, u == 0.0], axis=1)  # half-edge i of the face
    return (side & (twin[face] < 0)).any(axis=1)


@pytest.mark.parametrize("name", MESHES)
def test_residual_is_normal(surfaces, name):
    S = surfaces[name]
    X = _points(S, 150, seed=7)
    res = closest_points(S, X)
    r = S.evaluate(res.face, res.u, res.v, 1)
    R = X - res.P
    nr = np.linalg.norm(R, axis=1)
    tu = r["Pu"] / np.linalg.norm(r["Pu"], axis=1)[:, None]
    tv = r["Pv"] / np.linalg.norm(r["Pv"], axis=1)[:, None]
    gu = np.abs(np.einsum("ij,ij->i", R, tu)) / nr
    gv = np.abs(np.einsum("ij,ij->i", R, tv)) / nr
    bnd = _on_boundary(S, res.face, res.u, res.v)
    interior = ~bnd & (nr > 1e-6 * S.mesh.bounding_box_diagonal)
    # at a face corner that is an extraordinary vertex the parameterization is singular: the tangent
    # plane is the limit normal's, checked separately below
    corner = ((res.u == 0) | (res.u == 1)) & ((res.v == 0) | (res.v == 1))
    ok = interior & ~corner
    assert ok.sum() > 50
    # relative 1e-12 of |X - P|; for points closer than 1e-3 of the diagonal the round-off of P
    # (~1e-16 of the diagonal) dominates, so there the bound is 1e-15 of the diagonal, absolute
    diag = S.mesh.bounding_box_diagonal
    tol = np.maximum(1e-12, 1e-15 * diag / nr)
    far = ok & (nr >= 1e-3 * diag)
    assert far.sum() > 30
    assert (gu[ok] <= tol[ok]).all() and (gv[ok] <= tol[ok]).all()
    assert max(gu[far].max(), gv[far].max()) <= 1e-12
    # on a boundary edge (not at a corner): the derivative along the edge is normal to the residual
    on_u = bnd & ~corner & ((res.v == 0) | (res.v == 1))
    on_v = bnd & ~corner & ((res.u == 0) | (res.u == 1))
    assert (gu[on_u] <= tol[on_u]).all() and (gv[on_v] <= tol[on_v]).all()
    # at an interior extraordinary corner the residual is along the limit normal
    if corner.any():
        F = S.mesh.faces
        cidx = np.where(res.u[corner] == 0, np.where(res.v[corner] == 0, 0, 3), np.where(res.v[corner] == 0, 1, 2))
        vert = F[res.face[corner], cidx]
        n = S.vertex_normals()[vert]
        inner = ~S.mesh.is_boundary_vertex[vert] & (nr[corner] > 1e-6)
        cross = np.linalg.norm(np.cross(R[corner], n), axis=1) / nr[corner]
        assert (cross[inner] <= 1e-10).all()


@pytest.mark.parametrize("name", MESHES)
def test_points_on_the_surface(surfaces, name):
    S = surfaces[name]
    rng = np.random.default_rng(3)
    n = 200
    f = rng.integers(0, S.mesh.n_faces, n)
    u, v = rng.random(n), rng.random(n)
    u[:20], v[:20] = 0.0, rng.random(20)  # on face edges
    u[20:30], v[20:30] = 1e-9, 1e-9  # next to corners (extraordinary vertices on some faces)
    X = S.evaluate(f, u, v, 0)["P"]
    res = closest_points(S, X)
    diag = S.mesh.bounding_box_diagonal
    assert res.distance.max() <= 1e-13 * diag
    assert np.linalg.norm(res.P - X, axis=1).max() <= 1e-13 * diag
    # the same parameter where it is unique: interior of the face (not on a shared edge)
    inside = (u > 1e-6) & (u < 1 - 1e-6) & (v > 1e-6) & (v < 1 - 1e-6)
    np.testing.assert_array_equal(res.face[inside], f[inside])
    np.testing.assert_allclose(res.u[inside], u[inside], atol=1e-7)
    np.testing.assert_allclose(res.v[inside], v[inside], atol=1e-7)


def test_equidistant_centre_of_the_cube(surfaces):
    S = surfaces["cube"]
    X = np.zeros((1, 3))
    res = closest_points(S, X)
    # by symmetry the 6 face centres (and their images) are the minimizers; brute force agrees
    ref, _ = brute_force(S, X, faces_per_point=24)
    assert abs(res.distance[0] - ref[0]) <= 1e-12 * ref[0]
    # the minimizers are the face centres of the cube's limit surface: distance 68/81 (ccproof doctest)
    assert abs(res.distance[0] - 68 / 81) <= 1e-13
    assert res.descents[0] >= 2  # other faces were not pruned: they are as close


def test_finder_reuse_and_options(surfaces):
    S = surfaces["sector_k5"]
    X = _points(S, 30, seed=11)
    a = closest_points(S, X)
    for kw in ({"cells": 2}, {"cells": 6, "cover": 1}):
        b = closest_points(S, X, **kw)
        np.testing.assert_allclose(b.distance, a.distance, rtol=1e-13)
    F = ClosestPointFinder(S)
    c = F(X[:5])
    np.testing.assert_array_equal(c.distance, F.query(X[:5]).distance)


def test_restricted_to_faces(surfaces):
    """``faces=``: the nearest point among the given faces only (brute force over the same faces)."""
    S = surfaces["sector_k5"]
    X = _points(S, 40, seed=12)
    sel = np.arange(0, S.mesh.n_faces, 3)
    res = closest_points(S, X, faces=sel)
    assert np.isin(res.face, sel).all()
    ref, refP = brute_force(S, X, level=5, faces=sel)
    assert (res.distance <= ref + 1e-12 * (1 + ref)).all()
    assert (ref <= res.distance + 1e-9).all()
    full = closest_points(S, X)
    assert (full.distance <= res.distance + 1e-12).all() and (full.distance < res.distance - 1e-3).any()
    with pytest.raises(CCProofError, match="faces"):
        ClosestPointFinder(S, faces=[S.mesh.n_faces])
    with pytest.raises(CCProofError, match="faces"):
        ClosestPointFinder(S, faces=[])


def test_bad_input(surfaces):
    S = surfaces["torus_8x6"]
    with pytest.raises(CCProofError, match="shape"):
        closest_points(S, np.zeros((3, 2)))
    with pytest.raises(CCProofError, match="point 1"):
        closest_points(S, [[0, 0, 0], [np.nan, 0, 0]])
    with pytest.raises(CCProofError, match="cells"):
        ClosestPointFinder(S, cells=0)


def test_only_the_public_evaluator_is_used(surfaces):
    """A stand-in surface with its own face numbering and orientation (like ptex faces of another
    evaluator): only ``evaluate`` and ``n_ptex_faces`` are available, and the answers map back."""
    S = surfaces["sector_k6"]
    perm = np.random.default_rng(0).permutation(S.mesh.n_faces)

    class Ptex:
        n_ptex_faces = S.mesh.n_faces

        def evaluate(self, faces, u, v, derivatives=1):
            r = S.evaluate(perm[np.asarray(faces)], 1.0 - np.asarray(u), v, derivatives)
            for k in ("Pu", "Puv"):
                if k in r:
                    r[k] = -r[k]
            return r

    X = _points(S, 30, seed=5)
    a = closest_points(S, X)
    b = closest_points(Ptex(), X)
    np.testing.assert_allclose(b.distance, a.distance, rtol=1e-12)
    P = S.evaluate(perm[b.face], 1.0 - b.u, b.v, 0)["P"]
    np.testing.assert_allclose(P, b.P, rtol=0, atol=0)


@pytest.mark.slow
def test_bunny_against_brute_force(bunny_path):
    """The bunny (103 extraordinary vertices): 1,333 random points against level-5 sampling + grid search."""
    S = limit_surface(bunny_path)
    X = _points(S, 1000, seed=1)
    res = closest_points(S, X)
    ref, refP = brute_force(S, X, level=5)
    rel = (res.distance - ref) / ref
    diag = S.mesh.bounding_box_diagonal
    # never farther than brute force: relative 1e-12, or the round-off of positions (1e-16 of the
    # diagonal) for points very close to the surface
    assert (res.distance - ref <= np.maximum(1e-12 * ref, 2e-16 * diag)).all(), rel.max()
    # the same nearest point where brute force found the minimum (with 4 faces per point it can
    # miss it: then ours is closer, by up to 4e-5 relative at 2 of these points)
    same = np.abs(rel) <= 1e-9
    assert same.mean() > 0.99
    assert np.linalg.norm(res.P - refP, axis=1)[same].max() <= 1e-5 * diag


@pytest.mark.parametrize("name", ["catmark_nonquads", "catmark_cube_creases0"])
def test_tagged_meshes_never_farther_than_dense_sampling(refdir, name):
    """Triangles, n-gons (ptex faces) and creases: on the tagged evaluator the search is never farther
    than a 41 x 41 sampling of every ptex face, and within that sampling's resolution of it."""
    from ccproof.evaluate import limit_surface
    from ccproof.mesh.io import read_mesh

    s = limit_surface(read_mesh(refdir / "osd_features" / "meshes" / f"{name}.obj"))
    g = np.linspace(0, 1, 41)
    U, V = np.meshgrid(g, g, indexing="ij")
    nf = s.n_faces
    P = s.evaluate(np.repeat(np.arange(nf), U.size), np.tile(U.ravel(), nf), np.tile(V.ravel(), nf),
                   derivatives=0)["P"]
    lo, hi = P.min(0), P.max(0)
    X = lo - 0.05 * (hi - lo) + 1.1 * (hi - lo) * np.random.default_rng(1).random((200, 3))
    r = s.closest_points(X)
    brute = np.sqrt(((X[:, None, :] - P[None]) ** 2).sum(-1)).min(1)
    diag = np.linalg.norm(hi - lo)
    assert r.face.max() < nf
    assert (r.distance - brute).max() <= 1e-12 * diag
    assert (brute - r.distance).max() < 1e-2 * diag


@pytest.mark.parametrize("name", ["cube", "sector_k3", "torus_8x6"])
def test_compiled_cell_bounds_equal_the_numpy_reference(surfaces, name):
    """The cylinders of the search structure, compiled, against the numpy reference (also on a
    surface collapsed to a point, where every centre normal needs the fallback and is zero)."""
    from ccproof.evaluate import _bvh

    S = surfaces[name]
    m, g = 4, 9
    nf = S.mesh.n_faces
    t = np.arange(g) / (2 * m)
    U, V = np.meshgrid(t, t, indexing="ij")
    r = S.evaluate(np.repeat(np.arange(nf), g * g), np.tile(U.ravel(), nf), np.tile(V.ravel(), nf), 1)
    grids = [r[k].reshape(nf, g, g, 3) for k in ("P", "Pu", "Pv")]
    for P, Pu, Pv in [grids, [np.full_like(grids[0], 0.25), 0 * grids[1], 0 * grids[2]]]:
        a = _bvh.cell_bounds(P, Pu, Pv, m, 2.0, 1e-13)
        b = _bvh.cell_bounds_numpy(P, Pu, Pv, m, 2.0, 1e-13)
        for x, y in zip(a, b):
            assert x.shape == y.shape
            np.testing.assert_allclose(x, y, rtol=1e-13, atol=1e-15)
    # the bounds hold the cell's samples: lateral radius and half-height cover every sample offset
    c, n, rr, hh = _bvh.cell_bounds(*grids, m, 2.0, 1e-13)
    P = grids[0]
    for k in np.random.default_rng(1).integers(0, nf * m * m, 20):
        f, ci, cj = k // (m * m), (k // m) % m, k % m
        W = P[f, 2 * ci : 2 * ci + 3, 2 * cj : 2 * cj + 3].reshape(-1, 3) - c[k]
        z = W @ n[k]
        assert np.abs(z).max() < hh[k] and np.sqrt(np.maximum((W * W).sum(1) - z * z, 0)).max() < rr[k]


def _face_grid(S, faces, g):
    """Samples P, Pu, Pv (k, g, g, 3) of ``faces`` on the g x g grid (index i along u)."""
    t = np.arange(g) / (g - 1)
    U, V = np.meshgrid(t, t, indexing="ij")
    k = faces.size
    r = S.evaluate(np.repeat(faces, g * g), np.tile(U.ravel(), k), np.tile(V.ravel(), k), 1)
    return [r[key].reshape(k, g, g, 3) for key in ("P", "Pu", "Pv")]


@pytest.mark.parametrize("name", ["sector_k5", "torus_8x6"])
def test_face_bounds_hold_the_surface_and_stay_below_their_cells(surfaces, name):
    """The structure keeps one cylinder per face: every limit point of the face (a 41 x 41 sampling, finer
    than the 17 x 17 the bounds come from) lies in it, and its lower bound never exceeds the bound of any of
    its cells (the cylinders of cell_bounds at 8 x 8 cells, computed here from the evaluator's samples), so
    the faces it prunes hold no cell the search by cells would have kept."""
    from ccproof.evaluate import _bvh

    S = surfaces[name]
    F = ClosestPointFinder(S)
    faces = np.arange(S.mesh.n_faces)
    P = _face_grid(S, faces, 41)[0]
    for f in faces:
        lb = F.lower_bounds(P[f].reshape(-1, 3), np.full(41 * 41, f))
        assert lb.max() == 0.0, (f, lb.max())
    c, n, r, h = _bvh.cell_bounds(*_face_grid(S, faces, 17), 8, 2.0, 0.0)
    rng = np.random.default_rng(4)
    lo, hi = P.reshape(-1, 3).min(0), P.reshape(-1, 3).max(0)
    X = lo - 0.5 * (hi - lo) + 2.0 * (hi - lo) * rng.random((200, 3))
    for f in rng.choice(faces, 12, replace=False):
        W = X[:, None, :] - c[None, 64 * f:64 * f + 64]
        z = np.abs((W * n[None, 64 * f:64 * f + 64]).sum(-1))
        rho = np.sqrt(np.maximum((W * W).sum(-1) - z * z, 0.0))
        cell_lb = np.hypot(np.maximum(rho - r[64 * f:64 * f + 64], 0), np.maximum(z - h[64 * f:64 * f + 64], 0))
        assert (F.lower_bounds(X, np.full(X.shape[0], f)) <= cell_lb.min(1) * (1 + 1e-12)).all()


def test_small_cell_cache_gives_the_same_answers(surfaces, monkeypatch):
    """Cells computed again after the cache is emptied (room for 2 faces) give the same answers, bit for bit."""
    import ccproof.evaluate.closest as closest

    S = surfaces["torus_8x6"]
    X = _points(S, 60, seed=21)
    a = closest_points(S, X)
    monkeypatch.setattr(closest, "CACHE_CELLS", 2 * 64)
    F = ClosestPointFinder(S)
    assert F._cache.capacity == 2
    b = F.query(X, chunk=7)
    for key in ("face", "u", "v", "distance"):
        np.testing.assert_array_equal(getattr(b, key), getattr(a, key))
    assert F._cache.size <= 2


def test_search_structure_memory_is_linear_in_faces(bunny_path):
    """On the bunny (2,036 faces) the structure keeps less than 400 bytes per face after its build besides
    its cell cache (the search by cells kept 37 kB per face: samples, cells, two k-d trees), the cache at
    most CACHE_CELLS cells of 64 bytes, and the peak of its build and of queries stays within the estimate
    `ccproof project` checks before any work (numpy arrays, traced)."""
    import tracemalloc

    from ccproof.evaluate.closest import CACHE_CELLS, search_memory

    S = limit_surface(bunny_path)
    ClosestPointFinder(S, cells=2).query(np.zeros((3, 3)))  # compiled kernels and the table's lazy parts
    tracemalloc.start()
    try:
        F = ClosestPointFinder(S)
        kept, peak = tracemalloc.get_traced_memory()
        F.query(_points(S, 300, seed=2))
        peak = max(peak, tracemalloc.get_traced_memory()[1])
    finally:
        tracemalloc.stop()
    nf = S.mesh.n_faces
    cache = sum(a.nbytes for a in (F._cache.c, F._cache.n, F._cache.r, F._cache.h))
    assert cache <= 64 * min(CACHE_CELLS, 64 * nf)
    assert kept - cache < 400 * nf, (kept - cache) / nf
    assert peak < search_memory(nf), (peak, search_memory(nf))


def test_the_normal_at_an_ngon_centre_is_the_exact_tangent_plane():
    """A drum (two 100-gons joined by a band of quads, symmetric about the z axis): the nearest point to a point on
    the axis is the centre of a 100-gon, where the normal is (0, 0, +-1) by symmetry. Pu x Pv at the innermost layer
    was tilted there by 0.03 rad; the surface's exact tangent plane is not."""
    from ccproof.evaluate import natural_limit_surface
    from ccproof.mesh.polymesh import PolyMesh

    n = 100
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    V = np.r_[np.c_[np.cos(t), np.sin(t), np.ones(n)], np.c_[np.cos(t), np.sin(t), -np.ones(n)]]
    F = [list(range(n))[::-1], list(range(n, 2 * n))] + [[i, (i + 1) % n, n + (i + 1) % n, n + i] for i in range(n)]
    S = natural_limit_surface(PolyMesh(V, F))
    res = closest_points(S, np.array([[0.0, 0.0, 3.0], [0.0, 0.0, -3.0]]))
    assert np.allclose(np.abs(res.P[:, 2]), np.abs(res.P[:, 2]).max()) and np.abs(res.P[:, :2]).max() < 1e-12
    assert np.abs(res.normal[:, :2]).max() < 1e-12 and np.allclose(np.abs(res.normal[:, 2]), 1.0, atol=1e-12)
