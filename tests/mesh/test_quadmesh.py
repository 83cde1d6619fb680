"""Topology checks of QuadMesh: each kind of bad input gives a MeshError naming the element."""

import numpy as np
import pytest

from ccproof.errors import MeshError
from ccproof.mesh import QuadMesh
from ccproof.mesh.examples import cube, grid, k_regular_disk, torus


def test_grid_topology():
    m = grid(3, 2)
    assert m.n_vertices == 12 and m.n_faces == 6 and m.n_edges == 17
    assert m.is_boundary_vertex.sum() == 10
    assert m.is_boundary_edge.sum() == 10
    assert m.valence.tolist() == [2, 3, 3, 2, 3, 4, 4, 3, 2, 3, 3, 2]
    assert m.extraordinary_vertices.size == 0
    # boundary edges directed with the face on the left: a closed loop
    be = m.boundary_edges
    assert sorted(be[:, 0].tolist()) == sorted(be[:, 1].tolist())


def test_one_ring_cyclic_ccw():
    m = k_regular_disk(5, rings=2)
    e, d, f = m.one_ring(0)
    assert len(e) == len(d) == len(f) == 5
    ang = np.arctan2(m.vertices[e, 1], m.vertices[e, 0])
    steps = np.mod(np.diff(np.r_[ang, ang[0]]), 2 * np.pi)
    assert np.allclose(steps, 2 * np.pi / 5)  # counter-clockwise
    for j in range(5):  # d_j lies in the face between e_j and e_{j+1}
        assert {e[j], e[(j + 1) % 5], d[j], 0} == set(m.faces[f[j]].tolist())


def test_boundary_one_ring_starts_and_ends_on_boundary():
    m = grid(2, 2)
    e, d, f = m.one_ring(1)  # bottom middle vertex
    assert e.tolist() == [2, 4, 0] and d.tolist() == [5, 3] and f.tolist() == [1, 0]


def test_closed_meshes():
    assert cube().valence.tolist() == [3] * 8
    t = torus()
    assert not t.is_boundary_vertex.any() and (t.valence == 4).all()


def test_non_finite_coordinate():
    V = np.array(cube().vertices)
    V[5, 1] = np.nan
    with pytest.raises(MeshError, match="vertex 5 has a non-finite coordinate"):
        QuadMesh(V, cube().faces)
    V[5, 1] = np.inf
    with pytest.raises(MeshError, match="vertex 5"):
        cube().with_vertices(V)


def test_non_manifold_edge():
    V = np.zeros((8, 3))
    F = [[0, 1, 2, 3], [1, 0, 4, 5], [0, 1, 6, 7]]
    with pytest.raises(MeshError, match=r"non-manifold edge \(0, 1\): shared by 3 faces \[0, 1, 2\]"):
        QuadMesh(V, F)


def test_inconsistent_orientation():
    V = np.zeros((6, 3))
    F = [[0, 1, 2, 3], [1, 2, 5, 4]]  # the second face traverses edge (1, 2) from 1 to 2 as well
    msg = r"inconsistent orientation: faces 0 and 1 both traverse edge \(1, 2\)"
    with pytest.raises(MeshError, match=msg):
        QuadMesh(V, F)


def test_duplicate_face_has_its_own_message():
    V = np.random.default_rng(1).random((9, 3))
    F = [[0, 1, 4, 3], [1, 2, 5, 4], [3, 4, 7, 6], [4, 5, 8, 7], [4, 7, 6, 3]]  # face 4 is face 2 rotated
    with pytest.raises(MeshError, match=r"duplicate face: faces 2 and 4 have the same vertices \[3, 4, 7, 6\]"):
        QuadMesh(V, F)
    F[4] = [3, 6, 7, 4]  # face 2 reversed: also a duplicate (both orientations)
    with pytest.raises(MeshError, match=r"duplicate face: faces 2 and 4"):
        QuadMesh(V, F)


def test_unused_vertices_are_allowed_and_keep_their_indices():
    c = cube()
    V = np.vstack([[np.nan] * 3, c.vertices, [[5.0, 5.0, 5.0]]])
    m = QuadMesh(V, c.faces + 1)
    assert m.is_unused_vertex.tolist() == [True] + [False] * 8 + [True]
    assert m.extraordinary_vertices.tolist() == list(range(1, 9)) and m.valence[0] == 0
    assert m.bounding_box_diagonal == c.bounding_box_diagonal
    assert m.one_ring(0)[0].size == 0


def test_non_manifold_vertex():
    V = np.zeros((7, 3))
    F = [[0, 1, 2, 3], [0, 4, 5, 6]]  # bow tie: two faces meet at vertex 0 only
    with pytest.raises(MeshError, match="non-manifold vertex 0: its faces form 2 separate fans"):
        QuadMesh(V, F)


def test_valence_two_interior_vertex():
    V = np.random.default_rng(0).normal(size=(4, 3))
    with pytest.raises(MeshError, match=r"interior vertex \d has valence 2"):
        QuadMesh(V, [[0, 1, 2, 3], [3, 2, 1, 0]])  # a pillow: every vertex interior of valence 2


def test_other_bad_faces():
    with pytest.raises(MeshError, match=r"face 0 has a vertex index out of range \[0, 4\)"):
        QuadMesh(np.zeros((4, 3)), [[0, 1, 2, 4]])
    with pytest.raises(MeshError, match="face 1 repeats vertex 1"):
        QuadMesh(np.zeros((6, 3)), [[0, 1, 2, 3], [1, 4, 1, 5]])
    with pytest.raises(MeshError, match="all quads"):
        QuadMesh(np.zeros((4, 3)), [[0, 1, 2]])
    assert QuadMesh(np.zeros((5, 3)), [[0, 1, 2, 3]]).is_unused_vertex.tolist() == [False] * 4 + [True]


def test_connected_components_agree_with_scipy():
    """The numpy components of the fans against scipy's graph search (labels in the same order)."""
    import scipy.sparse as sp
    from scipy.sparse.csgraph import connected_components as scipy_components

    from ccproof.mesh.quadmesh import connected_components

    rng = np.random.default_rng(7)
    for n, m in ((1, 0), (10, 0), (50, 30), (200, 150), (1000, 990), (3000, 6000)):
        a, b = rng.integers(0, n, m), rng.integers(0, n, m)
        ref = scipy_components(sp.coo_matrix((np.ones(m), (a, b)), shape=(n, n)), directed=False)
        got = connected_components(n, a, b)
        assert got[0] == ref[0] and np.array_equal(got[1], ref[1]), (n, m)


_TOPOLOGY = ("twin", "edge_of_halfedge", "edges", "edge_faces", "is_boundary_edge", "rot", "fan_ptr", "fan_corners",
             "face_count", "valence", "is_boundary_vertex", "is_unused_vertex", "faces", "vertices")


def _same_quadmesh(a, b):
    for name in _TOPOLOGY:
        x, y = getattr(a, name), getattr(b, name)
        assert x.dtype == y.dtype and np.array_equal(x, y), name


@pytest.mark.parametrize("name", ["cube", "torus_8x6", "sector_k5", "bunny_quads"])
def test_from_polymesh_shares_the_topology_and_equals_the_constructor(refdir, name):
    """``QuadMesh.from_polymesh`` (and ``to_quad_mesh``) take the PolyMesh's half-edges, not built again, and give
    every array the constructor builds from the same faces, bit for bit, and the same evaluated surface."""
    from ccproof.evaluate import LimitSurface
    from ccproof.mesh.io import read_mesh

    p = read_mesh(refdir / "meshes" / f"{name}.obj")
    q = p.to_quad_mesh()
    assert q.halfedges is p.halfedges and q.twin is p.twin
    fresh = QuadMesh(p.vertices, p.indices.reshape(-1, 4))
    assert fresh.halfedges is not p.halfedges
    _same_quadmesh(q, fresh)
    rng = np.random.default_rng(1)
    f, u, v = rng.integers(0, q.n_faces, 50), rng.random(50), rng.random(50)
    a, b = LimitSurface(q).evaluate(f, u, v, 1), LimitSurface(fresh).evaluate(f, u, v, 1)
    assert all(np.array_equal(a[k], b[k]) for k in b)


def test_from_polymesh_makes_the_constructors_checks():
    """A pillow (two quads on the same four vertices) is a manifold PolyMesh, but no QuadMesh: the shared path
    refuses it as the constructor does (every interior vertex of valence 2)."""
    from ccproof.mesh.polymesh import PolyMesh

    V = np.random.default_rng(0).normal(size=(4, 3))
    p = PolyMesh(V, [[0, 1, 2, 3], [3, 2, 1, 0]])
    assert p.is_plain_quads
    with pytest.raises(MeshError, match=r"interior vertex \d has valence 2"):
        p.to_quad_mesh()
    with pytest.raises(MeshError, match="faces that are not quads"):
        QuadMesh.from_polymesh(PolyMesh(V, [[0, 1, 2], [0, 2, 3]]))


def test_shared_halfedges_only_for_the_same_faces():
    from ccproof.mesh.quadmesh import shared_halfedges

    g = grid(2, 2)
    assert shared_halfedges(g, np.array(g.faces), g.n_vertices) is g.halfedges
    assert shared_halfedges(g, np.array(g.faces), g.n_vertices + 1) is None  # one more vertex
    assert shared_halfedges(g, np.roll(g.faces, 1, axis=1), g.n_vertices) is None  # other corners first
    assert shared_halfedges(g, g.faces[:3], g.n_vertices) is None
    s = QuadMesh(g.vertices + 1.0, g.faces, _halfedges=shared_halfedges(g, g.faces, g.n_vertices))
    assert s.halfedges is g.halfedges
    _same_quadmesh(s.with_vertices(g.vertices), g)


def test_halfedges_of_other_faces_are_not_taken():
    """``_halfedges=`` of a mesh with the same counts but other faces (each face started one corner later,
    or the faces in another order): the QuadMesh builds its own topology, every array as the constructor
    without it builds it (not the other faces' twins and fans)."""
    g = grid(3, 3)
    F = np.asarray(g.faces)
    for F2 in (np.roll(F, 1, axis=1), F[::-1].copy()):
        q = QuadMesh(g.vertices, F2, _halfedges=g.halfedges)
        assert q.halfedges is not g.halfedges
        _same_quadmesh(q, QuadMesh(g.vertices, F2))
