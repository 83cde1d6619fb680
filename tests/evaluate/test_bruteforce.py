"""Exact evaluation against brute force: repeated reference subdivision + limit masks, finite differences.

Expected values are computed by :func:`ccproof.mesh.subdivide` iterated and the vertex limit masks
(independent of the patch tables of ccproof.evaluate), or by central differences of positions.
"""

from fractions import Fraction

import numpy as np
import pytest

from ccproof.evaluate import limit_surface
from ccproof.evaluate.local import corner_scheme, quad_ring
from ccproof.mesh import QuadMesh, limit_positions, subdivide, subdivision_matrix
from ccproof.mesh.examples import cube, grid, k_regular_disk, l_shape, torus

CORNERS = [(0, 0), (1, 0), (1, 1), (0, 1)]


def dyadic_vertex(meshes, f, u, v):
    """Vertex of the level-L mesh at the dyadic point (f, u, v) (u, v Fractions with denominator 2^L).

    Child 4f+i of a face covers its quarter at corner i; its own corner 0 is the vertex point of
    corner i and its axes are the parent's edges from corner i (to corner i+1 and to corner i-1).
    """
    for m in meshes:
        for i, c in enumerate(CORNERS):
            if (u, v) == c:
                return int(m.faces[f, i])
        i = {(0, 0): 0, (1, 0): 1, (1, 1): 2, (0, 1): 3}[(int(u >= Fraction(1, 2)), int(v >= Fraction(1, 2)))]
        c, c1, c3 = (np.array(CORNERS[j]) for j in (i, (i + 1) % 4, (i + 3) % 4))
        d = (2 * (u - c[0]), 2 * (v - c[1]))
        s = d[0] * int(c1[0] - c[0]) + d[1] * int(c1[1] - c[1])
        t = d[0] * int(c3[0] - c[0]) + d[1] * int(c3[1] - c[1])
        f, u, v = 4 * f + i, s, t
    raise AssertionError("point is not dyadic at this level")


def _perturbed(m, seed, scale=0.1):
    rng = np.random.default_rng(seed)
    return m.with_vertices(m.vertices + scale * rng.normal(size=m.vertices.shape))


def single_quad():
    return QuadMesh([[0, 0, 0], [1, 0, 0.3], [1.2, 1, 0], [0, 0.9, -0.2]], [[0, 1, 2, 3]])


CASES = {
    "cube": (lambda: _perturbed(cube(), 1), 6),  # every face has four valence-3 corners: split
    "k5_disk": (lambda: _perturbed(k_regular_disk(5, 2), 2), 5),  # interior EV, one-face corners
    "k3_disk_1ring": (lambda: _perturbed(k_regular_disk(3, 1), 3), 6),  # EV touching the boundary
    "l_shape": (lambda: l_shape(4), 5),  # concave boundary vertex with three faces
    "single_quad": (single_quad, 7),  # four one-face corners
    "k6_grid_mix": (lambda: _perturbed(k_regular_disk(6, 3), 5, 0.05), 4),
    "torus_3x3": (lambda: _perturbed(torus(3, 3), 6, 0.05), 4),  # 4 x 4 nets that wrap around
}


@pytest.mark.parametrize("name", sorted(CASES))
def test_dyadic_points_equal_subdivision_limit(name):
    make, L = CASES[name]
    m0 = make()
    meshes = [m0]
    for _ in range(L):
        meshes.append(subdivide(meshes[-1]))
    Lpos = limit_positions(meshes[-1])
    rng = np.random.default_rng(7)
    den = 2**L
    f_ids, us, vs, want = [], [], [], []
    for f in range(m0.n_faces):
        pts = {(0, 0), (1, 1), (den, 0), (0, den), (den // 2, den // 2), (1, 0), (0, 1), (den - 1, den - 1)}
        pts |= {tuple(rng.integers(0, den + 1, size=2)) for _ in range(12)}
        for a, b in sorted(pts):
            u, v = Fraction(int(a), den), Fraction(int(b), den)
            f_ids.append(f)
            us.append(float(u))
            vs.append(float(v))
            want.append(Lpos[dyadic_vertex(meshes, f, u, v)])
    S = limit_surface(m0)
    got = S.evaluate(f_ids, us, vs, 0)["P"]
    err = np.abs(got - np.array(want)).max() / m0.bounding_box_diagonal
    assert err <= 1e-13, err


def _fd_check(S, f, u, v, h=1e-5):
    r = S.evaluate(f, u, v, 2)
    P = lambda du, dv: S.evaluate(f, u + du, v + dv, 1)
    pu, mu, pv, mv = P(h, 0), P(-h, 0), P(0, h), P(0, -h)
    scale = np.abs(r["Pu"]).max() + np.abs(r["Pv"]).max()
    errs = {
        "Pu": np.abs((pu["P"] - mu["P"]) / (2 * h) - r["Pu"]).max() / scale,
        "Pv": np.abs((pv["P"] - mv["P"]) / (2 * h) - r["Pv"]).max() / scale,
    }
    scale2 = max(np.abs(r[k]).max() for k in ("Puu", "Puv", "Pvv"))
    errs["Puu"] = np.abs((pu["Pu"] - mu["Pu"]) / (2 * h) - r["Puu"]).max() / scale2
    errs["Pvv"] = np.abs((pv["Pv"] - mv["Pv"]) / (2 * h) - r["Pvv"]).max() / scale2
    errs["Puv"] = np.abs((pv["Pu"] - mv["Pu"]) / (2 * h) - r["Puv"]).max() / scale2
    return errs


@pytest.mark.parametrize("name", ["cube", "k5_disk", "l_shape", "single_quad", "k3_disk_1ring"])
def test_derivatives_agree_with_central_differences(name):
    m0 = CASES[name][0]()
    S = limit_surface(m0)
    rng = np.random.default_rng(11)
    n = 400
    f = rng.integers(0, m0.n_faces, n)
    u = rng.uniform(1e-3, 1 - 1e-3, n)
    v = rng.uniform(1e-3, 1 - 1e-3, n)
    # include points straddling the dyadic layer boundaries near the corners
    u[:40] = 0.5 ** rng.integers(1, 8, 40) * rng.uniform(0.9, 1.1, 40)
    v[:40] = rng.uniform(0.01, 0.02, 40)
    u, v = np.clip(u, 2e-5, 1 - 2e-5), np.clip(v, 2e-5, 1 - 2e-5)
    errs = _fd_check(S, f, u, v)
    assert max(errs["Pu"], errs["Pv"]) < 1e-7, errs
    assert max(errs["Puu"], errs["Puv"], errs["Pvv"]) < 1e-5, errs


@pytest.mark.parametrize("k", [3, 5, 6, 8])
def test_corner_matrix_equals_global_step(k):
    """Stam's exact (2k+8) x (2k+8) matrix A = rows of the global sparse step on the two rings."""
    m0 = _perturbed(k_regular_disk(k, 4), k)
    m1 = subdivide(m0)
    S = subdivision_matrix(m0)
    ring0, key0 = quad_ring(m0.faces, 0, 0)
    ring1, key1 = quad_ring(m1.faces, 0, 0)  # child 0 of face 0: at the EV
    assert key0 == key1 and len(ring0) == 2 * k + 8
    A = np.array([[float(x) for x in row] for row in corner_scheme(key0).A.tolist()])
    assert np.abs(S[ring1][:, ring0].toarray() - A).max() < 1e-15
    assert abs(S[ring1][:, np.setdiff1d(np.arange(m0.n_vertices), ring0)]).max() == 0
    # A^n C equals n global steps on the ring of the level-n child at the EV
    C = m0.vertices[ring0]
    mn = m0
    An = np.eye(len(ring0))
    for _ in range(4):
        mn = subdivide(mn)
        An = A @ An
        ringn, keyn = quad_ring(mn.faces, 0, 0)
        assert keyn == key0
        assert np.abs(mn.vertices[ringn] - An @ C).max() < 1e-14
    # eigenvalues: 1, then lam (double), docs/readings.md R2
    c = np.cos(2 * np.pi / k)
    lam = (5 + c + np.sqrt((1 + c) * (9 + c))) / 16
    ev = np.sort(np.abs(np.linalg.eigvals(A)))[::-1]
    assert abs(ev[0] - 1) < 1e-12 and np.allclose(ev[1:3], lam, atol=1e-8)


@pytest.mark.parametrize("k", [5, 6, 8])
def test_derivative_growth_near_extraordinary_vertex(k):
    """bmz04 eq. (3): |dP/du| at (2^-m, 2^-m) grows like (2 lam)^m."""
    m0 = _perturbed(k_regular_disk(k, 3, height=lambda x, y: 0.3 * x * x - 0.2 * x * y), k, 0.02)
    S = limit_surface(m0)
    ms = np.arange(12, 45)
    h = 0.5**ms
    r = S.evaluate(np.zeros(ms.size, int), h, h, 1)
    g = np.log2(np.linalg.norm(r["Pu"], axis=1))
    slope = np.polyfit(ms, g, 1)[0]
    c = np.cos(2 * np.pi / k)
    lam = (5 + c + np.sqrt((1 + c) * (9 + c))) / 16
    assert abs(slope - np.log2(2 * lam)) <= 0.01 * abs(np.log2(2 * lam)), (slope, np.log2(2 * lam))


def test_regular_grid_is_bicubic():
    """On a regular open grid with the boundary rules, the limit of a polynomial of degree <= 1 is
    itself (linear precision, also at boundary faces through the ghost points; not at the four
    faces at the grid's corners, whose one-face corner vertices follow the boundary curve rule)."""
    m = grid(4, 3)
    A = np.array([[1.0, 0.2, 0.1], [0.3, -1, 0.5], [0.2, 0.4, 2]])
    m = m.with_vertices(m.vertices @ A.T + [1, 2, 3])
    S = limit_surface(m)
    rng = np.random.default_rng(0)
    f = rng.choice([1, 2, 4, 5, 6, 7, 9, 10], 200)
    u, v = rng.random(200), rng.random(200)
    r = S.evaluate(f, u, v, 2)
    corner = grid(4, 3).vertices[grid(4, 3).faces[f, 0]]
    want = (corner + np.stack([u, v, 0 * u], 1)) @ A.T + [1, 2, 3]
    assert np.abs(r["P"] - want).max() < 1e-14
    assert np.abs(r["Pu"] - A[:, 0]).max() < 1e-14 and np.abs(r["Pv"] - A[:, 1]).max() < 1e-14
    assert np.abs(r["Puu"]).max() < 1e-13
