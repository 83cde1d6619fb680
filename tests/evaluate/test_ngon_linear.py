"""n-gons at a cost linear in n: the corner schemes of the centre of an n-gon (valence n after one step).

The layers ``M A^t - 1 l^T`` are computed exactly on classes of equal columns and the limit mask on an
equitable quotient (ccproof/evaluate/_powers.py). Checked here against independent computations:

* the dense exact products (``Mi Ai^t`` as flint ``fmpz_mat`` products, the limit mask by a dense
  ``fmpq_mat`` solve: the method used before, written out below) for the n-gon discs n = 3..12 and 40 and
  k-regular disks, bit for bit;
* brute-force global subdivision (N steps of the tagged rules, closed-form limit masks of the level-N
  vertices) on drums (two n-gons joined by a band of quads) of a 50-gon and a 300-gon.

The 300-gon takes about a second or two here; before, the dense products took minutes (the test is not
timed: a slow run is still correct).
"""

import numpy as np
import pytest

from ccproof.evaluate import _powers, limit_surface
from ccproof.evaluate.local import (
    LAYER_TOLERANCE,
    MAX_LAYERS,
    _child_nets,
    canonical_ring,
    quad_ring,
    refine_key,
    ring_key,
)
from ccproof.mesh.examples import k_regular_disk
from ccproof.mesh.polymesh import PolyMesh
from ccproof.mesh.rules import Complex, Options

from .test_tagged_bruteforce import limit_point, refine_with_frames


def _disc(n, seed=0):
    """One n-gon (a perturbed circle) and a ring of quads around it."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) * 2 * np.pi / n
    inner = np.c_[np.cos(t), np.sin(t), 0.1 * rng.standard_normal(n)]
    outer = np.c_[2 * np.cos(t), 2 * np.sin(t), 0.3 + 0.1 * rng.standard_normal(n)]
    F = [list(range(n))] + [[i, n + i, n + (i + 1) % n, (i + 1) % n] for i in range(n)]
    return PolyMesh(np.vstack([inner, outer]), F)


def _drum(n, seed=0):
    """Two n-gons (perturbed circles at z = +-1) joined by a band of n quads: a closed surface."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) * 2 * np.pi / n
    r = 1 + 0.05 * rng.standard_normal((2, n))
    top = np.c_[r[0] * np.cos(t), r[0] * np.sin(t), 1 + 0.05 * rng.standard_normal(n)]
    bot = np.c_[r[1] * np.cos(t), r[1] * np.sin(t), -1 + 0.05 * rng.standard_normal(n)]
    F = [list(range(n)), list(range(2 * n - 1, n - 1, -1))]
    F += [[i, n + i, n + (i + 1) % n, (i + 1) % n] for i in range(n)]
    return PolyMesh(np.vstack([top, bot]), F)


def _centre(m1, n):
    """The vertex of the level-1 mesh ``m1`` with n faces (the centre of the n-gon, n > 4)."""
    counts = np.bincount(np.concatenate([np.asarray(p) for p in m1.polygons]))
    (v,) = np.flatnonzero(counts == n)[:1]
    return int(v)


def _centre_key(mesh, n):
    """The ring key of a level-1 child of the n-gon read from the n-gon's centre."""
    m1, _ = mesh.refine()
    cx = m1.complex()
    v = _centre(m1, n)
    g = next(g for g, poly in enumerate(m1.polygons) if v in poly)
    ring, faces, nr = canonical_ring(cx, g, m1.polygons[g].index(v))
    assert len(faces) > n
    return ring_key(cx, ring, faces, nr)


def _stationary(key):
    """``(rows, nets, N)`` of the corner scheme of ``key``, refined until its ring is stationary."""
    for _ in range(4):
        _, st, child = refine_key(key, 4)
        ring1, faces1, nr = canonical_ring(child, 0, 0, 1)
        key1 = ring_key(child, ring1, faces1, nr)
        if key1 == key:
            nets = _child_nets(child, st)
            if nets is not None:
                return [st[v] for v in ring1], nets, len(ring1)
        key = key1
    raise AssertionError("no stationary ring")


def _dense_reference(rows, nets, N):
    """The dense exact computation: limit mask by an fmpq solve, layers by fmpz_mat products."""
    import flint

    A = flint.fmpq_mat(N, N)
    for i, s in enumerate(rows):
        for j, w in s.items():
            A[i, j] = w
    M = flint.fmpq_mat(48, N)
    for i, s in enumerate(nets):
        for j, w in s.items():
            M[i, j] = w
    Bt = (A - flint.fmpq_mat(N, N, [int(i == j) for i in range(N) for j in range(N)])).transpose()
    for j in range(N):
        Bt[N - 1, j] = 1
    lvec = Bt.solve(flint.fmpq_mat(N, 1, [0] * (N - 1) + [1]))
    Ai, a = A.numer_denom()
    Mi, m = M.numer_denom()
    li, c = flint.fmpq_mat(1, N, [lvec[i, 0] for i in range(N)]).numer_denom()
    a, m, c = int(a), int(m), int(c)
    L1 = flint.fmpz_mat(48, 1, [1] * 48) * li
    R, den, layers = Mi, m, []
    for _ in range(MAX_LAYERS):
        D = np.array([int(p) / (c * den) for p in (R * c - L1 * den).entries()]).reshape(48, N)
        layers.append(D)
        if np.abs(D).max() < LAYER_TOLERANCE:
            return [lvec[i, 0] for i in range(N)], np.array(layers)
        R, den = R * Ai, den * a
    raise AssertionError("no convergence")


def _keys():
    out = [(f"disc{n}", _centre_key(_disc(n), n)) for n in (5, 6, 7, 8, 9, 10, 11, 12, 40)]
    out += [(f"disk{k}", quad_ring(k_regular_disk(k, 3).faces, 0, 0)[1]) for k in (3, 5, 8)]
    cx = Complex(k_regular_disk(6, 3).faces, {(0, 1): 10.0}, {}, Options())  # a crease through the centre
    ring, faces, nr = canonical_ring(cx, 0, 0)
    out.append(("crease6", ring_key(cx, ring, faces, nr)))
    return out


@pytest.mark.parametrize("name,key", _keys(), ids=lambda x: x if isinstance(x, str) else "")
def test_class_layers_equal_the_dense_products_bit_for_bit(name, key):
    rows, nets, N = _stationary(key)
    lmask, want = _dense_reference(rows, nets, N)
    quotient = _powers.limit_mask(rows, N)
    if quotient is not None:  # the equitable quotient (3 x 3 at an n-gon centre) gives the same exact mask
        assert quotient == lmask
    got = _powers.class_layers(nets, rows, lmask, N, LAYER_TOLERANCE, MAX_LAYERS)
    assert got.shape == want.shape
    assert np.array_equal(got, want)


def test_quotient_of_an_ngon_centre_is_three_classes():
    rows, _, N = _stationary(_centre_key(_disc(40), 40))
    T = _powers.closure(rows, [0])
    classes = _powers._equitable_classes(rows, T, 12)
    assert len(T) == 2 * 40 + 1 and len(set(classes.values())) == 3


def _dyadic_limits(mesh, S, levels):
    """Evaluated and brute-force limit points at every level-N vertex of the faces around the n-gon centres."""
    m, frames = refine_with_frames(mesh, levels)
    cx = m.complex()
    E1 = len(mesh.complex().edges)
    centres = {mesh.n_vertices + E1 + f for f in np.flatnonzero(mesh.sizes != 4)}
    rng = np.random.default_rng(3)
    near = [g for g, poly in enumerate(m.polygons) if centres.intersection(poly)]
    faces = set(rng.choice(near, size=min(len(near), 80), replace=False).tolist())
    faces |= set(rng.choice(m.n_faces, size=min(m.n_faces, 40), replace=False).tolist())
    pts, want = [], []
    for g in sorted(faces):
        p, (o, a, b) = frames[g]
        for i, v in enumerate(m.polygons[g]):
            st = o + a * [(0, 0), (1, 0), (1, 1), (0, 1)][i][0] + b * [(0, 0), (1, 0), (1, 1), (0, 1)][i][1]
            pts.append((p, st[0], st[1]))
            want.append(limit_point(m, cx, v))
    f, s, t = (np.array([q[i] for q in pts]) for i in range(3))
    return S.evaluate(f.astype(int), s, t, 0)["P"], np.array(want)


@pytest.mark.parametrize("n,levels", [(50, 3), (300, 2)])
def test_drum_equals_global_subdivision(n, levels):
    mesh = _drum(n)
    S = limit_surface(mesh)
    got, want = _dyadic_limits(mesh, S, levels)
    assert len(got) >= 400
    err = np.abs(got - want).max() / mesh.bounding_box_diagonal
    assert err <= 1e-13, err


def test_ngon_centre_is_its_closed_form_limit():
    # the ptex corner (1, 1) of every sub-face of an n-gon is its centre: the smooth limit mask of the
    # level-1 face point (valence n: the centroid, the n edge points, the n vertices)
    n = 300
    mesh = _drum(n, seed=5)
    S = limit_surface(mesh)
    X = mesh.vertices
    m1, _ = mesh.refine()
    v = _centre(m1, n)  # both centres have n faces: the first is the first n-gon's
    assert np.allclose(m1.vertices[v], X[:n].mean(axis=0), atol=1e-15)
    want = limit_point(m1, m1.complex(), v)
    f = np.arange(n)  # the first n-gon's ptex faces
    got = S.evaluate(f, np.ones(n), np.ones(n), 0)["P"]
    assert np.abs(got - want).max() <= 1e-13 * mesh.bounding_box_diagonal


@pytest.mark.parametrize("n", [60, 130])
def test_sparse_tangent_masks_span_the_dense_tangent_plane(n):
    """The tangent masks at a large n-gon centre by Arnoldi iteration on the sparse matrix (linear cost) span
    the plane of the dense eigen-decomposition (numpy eig + SVD, cubic), and are left eigenvectors."""
    from ccproof.evaluate.local import _tangent_masks_float, _tangent_masks_sparse, _to_fmpq_mat

    rows, _, N = _stationary(_centre_key(_drum(n), n))
    A = _to_fmpq_mat(rows, N)
    Ts, Td = _tangent_masks_sparse(A), _tangent_masks_float(A)
    assert Ts is not None and Td is not None and Ts.shape == (2, N)
    Q, _ = np.linalg.qr(Td.T)
    assert np.linalg.norm(Ts.T - Q @ (Q.T @ Ts.T)) <= 1e-10 * np.linalg.norm(Ts)
    assert np.linalg.matrix_rank(Ts, tol=1e-6) == 2
