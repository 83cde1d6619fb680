"""The reference Catmull-Clark step and the vertex masks.

Expected values come from the rules written out by hand here (R1), from invariance under the step
(the masks are left eigenvectors) and from OpenSubdiv 3.6 (``vertex_limit``, ``vertex_limit_normal``).
"""

import json

import numpy as np
import pytest

from ccproof.mesh import (
    limit_normals,
    limit_positions,
    read_obj,
    subdivide,
    subdivision_matrix,
)
from ccproof.mesh.examples import cube, grid, k_regular_disk

MESHES = ["cube", "sector_k3", "sector_k5", "sector_k6", "torus_8x6"]


def _wavy(m, seed=0):
    rng = np.random.default_rng(seed)
    return m.with_vertices(m.vertices + 0.1 * rng.normal(size=m.vertices.shape))


def _exact_operator_in_quad_layout(m):
    """The exact stencils of ccproof.mesh.rules.refine_complex for the QuadMesh ``m``, as a dense
    float matrix (each entry rounded once) with the rows in the layout of ccproof.mesh.subdivision."""
    from ccproof.mesh.polymesh import PolyMesh
    from ccproof.mesh.rules import to_float

    p = PolyMesh(m.vertices, m.faces)
    exact = p.subdivision_operator(exact=True)
    cx = p.complex()
    n, E = m.n_vertices, m.n_edges
    eid = {(int(a), int(b)): i for i, (a, b) in enumerate(m.edges)}
    rows = list(range(n)) + [None] * E + list(range(n + E, n + E + m.n_faces))
    for e, h in enumerate(cx.edges):
        a, b = cx.org[h], cx.dst(h)
        rows[n + eid[(min(a, b), max(a, b))]] = n + e
    out = np.zeros((len(exact), n))
    for i, r in enumerate(rows):
        for j, w in exact[r].items():
            out[i, j] = to_float(w)
    return out, exact


@pytest.mark.parametrize("make", [cube, lambda: grid(3, 2), lambda: k_regular_disk(7, 2)])
def test_vectorized_step_equals_exact_stencils(make):
    """The vectorized float operator and the exact stencils of the same rules agree to rounding."""
    m = _wavy(make())
    S = subdivision_matrix(m).toarray()
    assert np.allclose(S.sum(axis=1), 1, atol=1e-15, rtol=0)
    E, exact = _exact_operator_in_quad_layout(m)
    assert all(sum(r.values()) == 1 for r in exact)  # affine invariance, exactly
    # the vectorized entries are float sums of up to k + 1 rounded weights (the vertex's own
    # weight collects (k - 2)/k and its share of the k face points); a wrong weight is off by >= 1e-3
    assert np.abs(S - E).max() <= 8 * 2.0**-52
    assert np.array_equal(S != 0, E != 0)
    m1 = subdivide(m)
    assert np.array_equal(m1.vertices, subdivision_matrix(m) @ m.vertices)
    # twice
    S2 = subdivision_matrix(m1) @ subdivision_matrix(m)
    assert np.abs(S2 @ m.vertices - subdivide(m1).vertices).max() <= 1e-14


def test_bunny_vectorized_step_equals_exact_stencils(refdir):
    m = read_obj(refdir / "meshes" / "bunny_quads.obj")
    assert m.n_faces == 2036 and m.extraordinary_vertices.size == 103 and not m.is_boundary_vertex.any()
    S = subdivision_matrix(m)
    E, _ = _exact_operator_in_quad_layout(m)
    assert np.abs(S.toarray() - E).max() <= 8 * 2.0**-52
    assert np.array_equal(S.toarray() != 0, E != 0)


@pytest.mark.parametrize("k", [3, 5, 6, 9])
def test_rules_by_hand(k):
    m = _wavy(k_regular_disk(k, rings=2), seed=k)
    V = m.vertices
    m1 = subdivide(m)
    n, E = m.n_vertices, m.n_edges
    # centre: weights 1 - 7/(4k), 3/(2k^2) on edge neighbours, 1/(4k^2) on diagonals
    e, d, f = m.one_ring(0)
    want = (1 - 7 / (4 * k)) * V[0] + 3 / (2 * k * k) * V[e].sum(0) + 1 / (4 * k * k) * V[d].sum(0)
    assert np.allclose(m1.vertices[0], want, atol=1e-15, rtol=0)
    # face point of face 0 and edge point of the interior edge (0, e_0)
    assert np.allclose(m1.vertices[n + E + f[0]], V[m.faces[f[0]]].mean(0), atol=1e-15, rtol=0)
    eid = int(np.flatnonzero((m.edges == sorted([0, e[0]])).all(1))[0])
    fa, fb = m.edge_faces[eid]
    want = (V[0] + V[e[0]] + V[m.faces[fa]].mean(0) + V[m.faces[fb]].mean(0)) / 4
    assert np.allclose(m1.vertices[n + eid], want, atol=1e-15, rtol=0)
    # boundary: cubic B-spline curve rule and midpoints
    for v in np.flatnonzero(m.is_boundary_vertex)[:5]:
        e, _, _ = m.one_ring(v)
        assert np.allclose(m1.vertices[v], (V[e[0]] + 6 * V[v] + V[e[-1]]) / 8, atol=1e-15, rtol=0)
    for eid in np.flatnonzero(m.is_boundary_edge)[:5]:
        a, b = m.edges[eid]
        assert np.allclose(m1.vertices[n + eid], (V[a] + V[b]) / 2, atol=1e-15, rtol=0)


def test_children_orientation_and_parameter():
    m = grid(1, 1)
    m1 = subdivide(m)
    # child 4f+i covers the quarter at corner i of face f, its corner 0 being the vertex point of corner i
    assert m1.faces[:4, 0].tolist() == m.faces[0].tolist()
    assert not m1.is_boundary_vertex[8] and m1.valence[8] == 4


@pytest.mark.parametrize("make", [cube, lambda: grid(3, 3), lambda: k_regular_disk(5, 3)])
def test_masks_are_invariant_under_the_step(make):
    m = _wavy(make(), seed=3)
    m1 = subdivide(m)
    n = m.n_vertices
    assert np.abs(limit_positions(m1)[:n] - limit_positions(m)).max() < 1e-14
    N0, N1 = limit_normals(m), limit_normals(m1)[:n]
    ok = ~np.isnan(N0).any(1)
    assert ok.sum() >= n - 5
    assert np.abs(N1[ok] - N0[ok]).max() < 1e-13


@pytest.mark.parametrize("name", MESHES)
def test_vertex_limits_against_opensubdiv(refdir, name):
    d = json.loads((refdir / f"osd_limit_{name}.json").read_text())
    m = read_obj(refdir / "meshes" / f"{name}.obj")
    assert np.abs(limit_positions(m) - np.array(d["vertex_limit"])).max() <= 1e-13
    N = limit_normals(m)
    ok = ~np.isnan(N).any(1)
    # NaN only at boundary vertices with one face (no closed-form mask in the mesh layer)
    assert (m.is_boundary_vertex & (m.face_count != 2))[~ok].all()
    assert np.abs(N[ok] - np.array(d["vertex_limit_normal"])[ok]).max() <= 1e-13


def test_reference_step_agrees_with_pygel3d(refdir):
    """An established implementation (pygel3d's cc_subdivide) gives the same points, as a set."""
    hmesh = pytest.importorskip("pygel3d.hmesh", reason="pygel3d not installed (optional extra ccproof[bench])")
    from scipy.spatial import cKDTree

    path = refdir / "meshes" / "bunny_quads.obj"
    m = read_obj(path)
    g = hmesh.obj_load(str(path))
    for _ in range(2):
        hmesh.cc_subdivide(g)
        m = subdivide(m)
    pos = g.positions()
    assert pos.shape == m.vertices.shape
    d1 = cKDTree(m.vertices).query(pos)[0].max()
    d2 = cKDTree(pos).query(m.vertices)[0].max()
    assert max(d1, d2) < 1e-14


def test_rule_functions_exact_and_float_from_the_same_code():
    """Each rule's weights, evaluated with exact_one() and with 1.0 (scalar and vectorized), agree:
    the float weights are the correctly rounded exact ones, and the exact ones are the textbook
    fractions (bmz04 Fig. 1)."""
    from fractions import Fraction

    from ccproof.mesh.rules import (
        crease_vertex_weights,
        exact_one,
        face_point_weight,
        sharp_edge_weight,
        smooth_edge_weights,
        smooth_vertex_weights,
        to_float,
    )

    one = exact_one()
    ks = np.arange(3, 30)
    vec = smooth_vertex_weights(ks, 1.0)
    for i, k in enumerate(ks.tolist()):
        ex = smooth_vertex_weights(k, one)
        want = [Fraction(k - 2, k), Fraction(1, k * k), Fraction(1, k * k)]
        assert [Fraction(int(w.p), int(w.q)) for w in ex] == want
        assert [to_float(w) for w in ex] == [float(Fraction(k - 2, k)), 1 / (k * k), 1 / (k * k)]
        assert [to_float(w) for w in ex] == [float(v[i]) for v in vec]
        # in a quad mesh: 1 - 7/(4k) on V (with its share of the k face points), 3/(2k^2), 1/(4k^2)
        wv, we, wf = ex
        assert wv + k * wf / 4 == one - one * 7 / (4 * k) and we + 2 * wf / 4 == one * 3 / (2 * k * k)
    for n in (3, 4, 5, 7):
        assert to_float(face_point_weight(n, one)) == face_point_weight(n, 1.0) == 1 / n
    assert [to_float(w) for w in smooth_edge_weights(one)] == list(smooth_edge_weights(1.0)) == [0.25, 0.25]
    assert to_float(sharp_edge_weight(one)) == sharp_edge_weight(1.0) == 0.5
    assert [to_float(w) for w in crease_vertex_weights(one)] == list(crease_vertex_weights(1.0)) == [0.75, 0.125]
