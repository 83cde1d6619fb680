"""The child's half-edges derived from the parent's (:meth:`HalfEdges.refined`, what ``PolyMesh.refine`` uses)
against the pairing of the child's faces (:class:`HalfEdges`' constructor), array by array, on every mesh of
the OpenSubdiv feature and non-manifold data (their manifold splits) and an icosphere, levels 0..2; and the
refined meshes against those the constructor builds from the child's faces alone."""

from pathlib import Path

import numpy as np
import pytest

import ccproof.mesh.polymesh as polymesh_module
from ccproof.mesh.halfedges import HalfEdges
from ccproof.mesh.io import read_mesh, read_obj_tagged
from ccproof.mesh.polymesh import PolyMesh

DATA = Path(__file__).resolve().parents[1] / "data"
MESHES = sorted((DATA / "osd_features" / "meshes").glob("*.obj")) + sorted(
    p for p in (DATA / "osd_nonmanifold" / "meshes").iterdir() if p.suffix in (".obj", ".off"))
ARRAYS = ("org", "nxt", "prv", "twin", "offsets", "sizes", "start", "face_of", "edge_of", "edges", "edge_face_count",
          "edge_halfedge", "_same", "repeat_edge", "is_nonmanifold_edge", "fan_of_corner", "n_fans",
          "is_nonmanifold_vertex", "is_boundary_vertex", "face_count", "edge_keys", "edge_values")


def _icosphere():
    """An icosahedron with every triangle split in four (midpoints pushed to the sphere): 80 triangles."""
    t = (1 + 5 ** 0.5) / 2
    V = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t), (0, 1, -t),
         (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    F = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2), (10, 7, 6),
         (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10),
         (8, 6, 7), (9, 8, 1)]
    V = [np.array(v, dtype=float) / np.linalg.norm(v) for v in V]
    mid = {}

    def m(a, b):
        k = (min(a, b), max(a, b))
        if k not in mid:
            p = V[a] + V[b]
            V.append(p / np.linalg.norm(p))
            mid[k] = len(V) - 1
        return mid[k]

    F2 = []
    for a, b, c in F:
        ab, bc, ca = m(a, b), m(b, c), m(c, a)
        F2 += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
    return PolyMesh(np.array(V), F2)


def _meshes():
    for p in MESHES:
        yield p.stem, lambda p=p: (read_obj_tagged(p) if "osd_features" in str(p) else read_mesh(p))
    yield "icosphere80", _icosphere


def _same_halfedges(c, q):
    for a in ARRAYS:
        x, y = getattr(c, a), getattr(q, a)
        assert x.dtype == y.dtype and np.array_equal(x, y), a
    for a in ("n_vertices", "uniform", "edge_manifold", "options"):
        assert getattr(c, a) == getattr(q, a), a
    assert (c.vertex_values is None) == (q.vertex_values is None)
    if c.vertex_values is not None:
        assert np.array_equal(c.vertex_values, q.vertex_values)


class _Paired(HalfEdges):
    """The former refine: the child's half-edges paired from its faces by the constructor."""

    @classmethod
    def refined(cls, parent, options=None):
        return None


@pytest.mark.parametrize("name,load", list(_meshes()), ids=[n for n, _ in _meshes()])
def test_refined_halfedges_equal_the_paired_ones(name, load, monkeypatch):
    m = load().manifold
    for level in range(3):
        c = HalfEdges.refined(m.halfedges)
        q = HalfEdges(c.org, c.offsets, c.n_vertices, m.options)  # the child's faces paired
        _same_halfedges(c, q)
        child, _ = m.refine(operator=False)
        assert np.array_equal(child.indices, c.org), level  # the faces the step writes
        with monkeypatch.context() as mp:
            mp.setattr(polymesh_module, "HalfEdges", _Paired)
            old, _ = m.refine(operator=False)
        assert isinstance(old.halfedges, _Paired) and not isinstance(child.halfedges, _Paired)
        assert old.__dict__.keys() == child.__dict__.keys()
        for k, x in old.__dict__.items():
            y = child.__dict__[k]
            if k == "halfedges":
                _same_halfedges(y, x)
            elif k == "manifold":
                assert x is old and y is child
            elif isinstance(x, np.ndarray):
                assert x.dtype == y.dtype and np.array_equal(x, y, equal_nan=x.dtype.kind == "f"), k
            else:
                assert x == y, k
        m = child


def test_refined_rejects_a_nonmanifold_parent():
    bow = PolyMesh([[0, 0, 0], [1, 0, 0], [1, 1, 0], [-1, 0, 0], [-1, -1, 0]], [[0, 1, 2], [0, 3, 4]])
    with pytest.raises(ValueError, match="not manifold"):
        HalfEdges.refined(bow.halfedges)
    assert HalfEdges.refined(bow.manifold.halfedges).n_vertices == 6 + 6 + 2


QUAD_MESHES = ["catmark_cube_corner2.obj", "catmark_xord_boundary.obj", "catmark_nonquads.obj",
               "catmark_smoothtris1.obj"]


@pytest.mark.parametrize("name", QUAD_MESHES)
def test_subdivide_derives_the_quad_childs_halfedges_in_its_sorted_numbering(name, monkeypatch):
    """``subdivide`` of a QuadMesh (edge points in the sorted numbering of ``mesh.edges``) takes the child's
    half-edges from HalfEdges.refined with that numbering: array by array those the constructor pairs from the
    child's faces, and the child QuadMesh the one built from its faces alone, at levels 1 and 2."""
    from ccproof.mesh import QuadMesh, subdivide

    pm = read_mesh(DATA / "osd_features" / "meshes" / name).manifold
    if not (pm.sizes == 4).all():
        pm, _ = pm.refine(operator=False)
    q = QuadMesh(pm.vertices, pm.indices.reshape(-1, 4))
    pairings = []
    real = HalfEdges._pair
    for _ in range(2):
        with monkeypatch.context() as mp:
            mp.setattr(HalfEdges, "_pair", lambda self: pairings.append(1) or real(self))
            child = subdivide(q)
        assert not pairings  # no half-edge paired: the child's derived
        alone = QuadMesh(child.vertices, child.faces)  # paired from the faces by the constructor
        _same_halfedges(child.halfedges, alone.halfedges)
        for k, x in alone.__dict__.items():
            y = child.__dict__[k]
            if isinstance(x, np.ndarray):
                assert x.dtype == y.dtype and np.array_equal(x, y), k
        q = child


def test_refined_in_the_sorted_numbering_differs_from_first_occurrence():
    """The numbering matters (the test above can fail): on a 2 x 2 grid the sorted and first-occurrence
    numberings of the edges differ, and so do the child's half-edges derived under each."""
    from ccproof.mesh.examples import grid

    g = grid(2, 2)
    first = HalfEdges.refined(g.halfedges)
    srt = HalfEdges.refined(g.halfedges, edge_of_halfedge=g.edge_of_halfedge)
    assert not np.array_equal(first.org, srt.org)
    q = HalfEdges.from_quads(srt.org.reshape(-1, 4), srt.n_vertices)
    assert np.array_equal(q.twin, srt.twin) and np.array_equal(q.edges, srt.edges)
