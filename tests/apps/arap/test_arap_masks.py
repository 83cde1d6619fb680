"""H1: the A3 tangent masks are exact limit tangents.

Expected values come from (i) the one-ring subdivision matrix of the mesh layer and the subdominant
eigenvalue written out here, (ii) the bicubic B-spline derivative at a knot computed here from the
1D weights, (iii) finite differences of limit points of a refined mesh (mesh layer subdivision and
limit-position masks).
"""

import numpy as np
import pytest

from ccproof.apps.arap.samples import mask_weights, tangent_mask_operators
from ccproof.mesh import limit_positions, subdivide, subdivision_matrix
from ccproof.mesh.examples import grid, k_regular_disk


def subdominant(n):
    c = np.cos(2 * np.pi / n)
    return (5 + c + np.cos(np.pi / n) * np.sqrt(18 + 2 * c)) / 16


def one_ring_matrix(n):
    """(2n+1) x (2n+1) one-ring subdivision matrix of the centre of k_regular_disk(n), with the
    one-ring (centre, e_0..e_{n-1}, d_0..d_{n-1}) in counter-clockwise order."""
    m = k_regular_disk(n, rings=2)
    e, d, f = m.one_ring(0)
    S = subdivision_matrix(m).toarray()
    nv, ne = m.n_vertices, m.n_edges
    edge_id = {tuple(sorted(map(int, m.edges[i]))): i for i in range(ne)}
    rows = [0] + [nv + edge_id[tuple(sorted((0, int(x))))] for x in e] + [nv + ne + int(x) for x in f]
    cols = [0] + list(e) + list(d)
    sub = S[np.ix_(rows, cols)]
    assert np.allclose(sub.sum(axis=1), 1.0)  # the one-ring is closed under subdivision
    return m, cols, sub


@pytest.mark.parametrize("n", list(range(3, 31)))
def test_masks_are_subdominant_left_eigenvectors(n):
    m, cols, S1 = one_ring_matrix(n)
    M1, M2 = tangent_mask_operators(m, np.array([0]))
    lam = subdominant(n)
    for M in (M1, M2):
        w = M.toarray()[0, cols]
        assert abs(w[0]) == 0.0
        assert np.abs(w @ S1 - lam * w).max() < 1e-12
    # the two masks are independent (they span the 2D eigenspace)
    W = np.stack([M1.toarray()[0, cols], M2.toarray()[0, cols]])
    assert np.linalg.matrix_rank(W, tol=1e-8) == 2


def test_valence4_is_bspline_derivative():
    # d/dx of the bicubic B-spline at a knot: (-1/2, 0, 1/2) x (1/6, 2/3, 1/6)
    dx = np.array([-0.5, 0.0, 0.5])
    px = np.array([1, 4, 1]) / 6
    Wx = np.outer(px, dx)  # rows: y = -1, 0, 1; columns x = -1, 0, 1
    Wy = np.outer(dx, px)
    g = grid(2, 2)  # centre vertex 4 at (1, 1), vertex i + 3 j at (i, j)
    M1, M2 = tangent_mask_operators(g, np.array([4]))
    e, _, _ = g.one_ring(4)
    m1 = M1.toarray()[0].reshape(3, 3)
    m2 = M2.toarray()[0].reshape(3, 3)
    # p1 is along e_0, p2 along e_1 (the next edge counter-clockwise)
    d0 = g.vertices[e[0], :2] - 1
    W0 = Wx if d0[0] == 1 else (-Wx if d0[0] == -1 else (Wy if d0[1] == 1 else -Wy))
    assert np.allclose(m1, W0, atol=1e-15)
    rot = np.array([[0, -1], [1, 0]])
    d1 = rot @ d0
    W1 = Wx if d1[0] == 1 else (-Wx if d1[0] == -1 else (Wy if d1[1] == 1 else -Wy))
    assert np.allclose(m2, W1, atol=1e-15)
    a, b = mask_weights(4)
    assert np.allclose(a, [1 / 3, 0, -1 / 3, 0]) and np.allclose(b, [1 / 12, -1 / 12, -1 / 12, 1 / 12])


def _edge_index(mesh, a, b):
    lo, hi = min(int(a), int(b)), max(int(a), int(b))
    return int(np.flatnonzero((mesh.edges[:, 0] == lo) & (mesh.edges[:, 1] == hi))[0])


def _edge_chains(mesh, v, ws, jmax):
    """Limit points of v and of its neighbours along the edges (v, w) after j = 1..jmax subdivisions."""
    nbs = list(ws)
    out = []
    for _ in range(jmax):
        nbs = [mesh.n_vertices + _edge_index(mesh, v, nb) for nb in nbs]
        mesh = subdivide(mesh)
        L = limit_positions(mesh)
        out.append((L[v], [L[nb] for nb in nbs]))
    return out


def _curved(rings):
    return k_regular_disk(5, rings=rings, height=lambda x, y: 0.3 * np.sin(x) * np.cos(0.7 * y) + 0.1 * x * y)


def test_mask_equals_central_difference_at_regular_vertex():
    m = subdivide(_curved(rings=3))  # level 1; pick a regular interior vertex
    v = int(np.flatnonzero(~m.is_boundary_vertex & (m.valence == 4))[5])
    e, _, _ = m.one_ring(v)
    M1, _ = tangent_mask_operators(m, np.array([v]))
    p1 = (M1 @ m.vertices)[0]
    chains = _edge_chains(m, v, [e[0], e[2]], 4)
    errs = []
    for j in (2, 3, 4):
        _, (plus, minus) = chains[j - 1]
        fd = (plus - minus) / (2 * 2.0**-j)
        errs.append(np.linalg.norm(fd - p1))
    assert errs[-1] < 1e-3 * np.linalg.norm(p1)
    assert errs[1] / errs[0] < 0.3 and errs[2] / errs[1] < 0.3  # O(h^2): ratio ~ 1/4


def test_mask_is_edge_curve_tangent_at_extraordinary_vertex():
    m = _curved(rings=2)  # the centre (vertex 0) has valence 5
    e, _, _ = m.one_ring(0)
    M1, M2 = tangent_mask_operators(m, np.array([0]))
    p = [(M1 @ m.vertices)[0], (M2 @ m.vertices)[0]]
    chains = _edge_chains(m, 0, [e[0], e[1]], 7)
    for a in (0, 1):
        angles = []
        for j in (3, 5, 7):
            L0, nbs = chains[j - 1]
            s = nbs[a] - L0
            cosang = s @ p[a] / (np.linalg.norm(s) * np.linalg.norm(p[a]))
            angles.append(np.arccos(min(1.0, cosang)))
        assert angles[-1] < 2e-3
        assert angles[2] < angles[1] < angles[0]
