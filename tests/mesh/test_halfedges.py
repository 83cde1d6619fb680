"""The one topology type (:class:`ccproof.mesh.halfedges.HalfEdges`) against a pairing written out with
Python dicts, on every mesh of the OpenSubdiv feature and non-manifold test data (duplicated, flipped and
collapsed faces, bow ties, books), and its tag arrays against the mesh's tag dicts."""

import math
from collections import defaultdict
from pathlib import Path

import numpy as np
import pytest

from ccproof.mesh.halfedges import HalfEdges
from ccproof.mesh.io import read_mesh, read_obj_tagged
from ccproof.mesh.polymesh import PolyMesh

DATA = Path(__file__).resolve().parents[1] / "data"
FEATURES = sorted((DATA / "osd_features" / "meshes").glob("*.obj"))
NONMANIFOLD = sorted(p for p in (DATA / "osd_nonmanifold" / "meshes").iterdir() if p.suffix in (".obj", ".off"))


def _read(p):
    return read_obj_tagged(p) if "osd_features" in str(p) else read_mesh(p)


def _brute(polys):
    """Per half-edge (face corner, in order): origin, destination, face; twins by dicts: the other corner of
    an edge with exactly two corners, in opposite directions, in different faces (else -1)."""
    hes = [(p[i], p[(i + 1) % len(p)], f) for f, p in enumerate(polys) for i in range(len(p))]
    by_edge = defaultdict(list)
    for h, (a, b, _) in enumerate(hes):
        by_edge[(min(a, b), max(a, b))].append(h)
    twin = [-1] * len(hes)
    for hs in by_edge.values():
        if len(hs) == 2:
            h1, h2 = hs
            if hes[h1][0] != hes[h2][0] and hes[h1][2] != hes[h2][2]:
                twin[h1], twin[h2] = h2, h1
    return hes, by_edge, twin


@pytest.mark.parametrize("path", FEATURES + NONMANIFOLD, ids=lambda p: p.name)
def test_halfedges_against_dict_pairing(path):
    m = _read(path)
    polys = [list(p) for p in (m.polygons if isinstance(m, PolyMesh) else m.faces.tolist())]
    he = m.halfedges
    hes, by_edge, twin = _brute(polys)
    assert he.org.tolist() == [a for a, _, _ in hes]
    assert he.org[he.nxt].tolist() == [b for _, b, _ in hes]
    assert he.face_of.tolist() == [f for _, _, f in hes]
    assert he.twin.tolist() == twin
    keys = sorted(by_edge)
    assert [tuple(e) for e in he.edges.tolist()] == keys
    assert he.edge_face_count.tolist() == [len(by_edge[k]) for k in keys]
    assert [keys[e] for e in he.edge_of.tolist()] == [(min(a, b), max(a, b)) for a, b, _ in hes]
    # the same arrays, recomputed on demand when not kept
    lazy = HalfEdges(he.org, he.offsets, he.n_vertices, edges=False)
    assert np.array_equal(lazy.twin, he.twin) and np.array_equal(lazy.edges, he.edges)
    assert np.array_equal(lazy.prv[lazy.nxt], np.arange(he.org.size))


@pytest.mark.parametrize("path", FEATURES + NONMANIFOLD, ids=lambda p: p.name)
def test_tag_arrays_hold_the_interior_tags(path):
    """``edge_keys`` / ``edge_values``: the tagged edges with two faces (boundary and non-manifold ones are
    sharp by the topology), ``inf`` from 10 on; ``vertex_values``: the vertex sharpness."""
    m = _read(path).manifold
    he = m.halfedges
    n = m.n_vertices
    _, by_edge, twin = _brute([list(p) for p in m.polygons])
    want = sorted((a * n + b, math.inf if s >= 10 else s) for (a, b), s in m.edge_sharpness.items()
                  if twin[by_edge[(a, b)][0]] >= 0)
    assert list(zip(he.edge_keys.tolist(), he.edge_values.tolist())) == want
    vv = he.vertex_tags()
    assert {int(v): float(vv[v]) for v in np.flatnonzero(vv)} == {
        v: (math.inf if s >= 10 else s) for v, s in m.vertex_sharpness.items()}


def test_nonmanifold_flags_of_a_bow_tie():
    he = HalfEdges([0, 1, 2, 0, 3, 4], [0, 3, 6], 5)
    assert he.is_nonmanifold_vertex.tolist() == [True, False, False, False, False]
    assert he.n_fans.tolist() == [2, 1, 1, 1, 1]
    assert not he.is_nonmanifold_edge.any() and he.edge_manifold


def test_with_tags_takes_an_edge_once_in_either_order():
    """An edge given as (a, b) and as (b, a): one tag, the later one (as a dict of ``(min, max)`` keys
    built in that order would hold it); a pair that is no edge, a zero and a boundary edge are left out."""
    he = HalfEdges([0, 1, 4, 3, 1, 2, 5, 4], [0, 4, 8], 6)
    t = he.with_tags({(1, 4): 2.0, (4, 1): 3.5, (0, 5): 1.0, (0, 1): 4.0})
    assert t.edge_keys.tolist() == [1 * 6 + 4] and t.edge_values.tolist() == [3.5]
    assert t.edge_sharpness_at([4, 1, 0], [1, 4, 1]).tolist() == [3.5, 3.5, 0.0]
    assert t.edge_sharpness_at([0, 2], [10, -2]).tolist() == [0.0, 0.0]  # no vertex 10 or -2 (keys 10 = 1 * 6 + 4)
    t = he.with_tags({(4, 1): 12.0, (1, 4): 0.0})
    assert t.edge_keys.size == 0 and not t.has_tags


@pytest.mark.parametrize("path", FEATURES + NONMANIFOLD, ids=lambda p: p.name)
def test_a_face_subset_keeps_the_twins_within_it(path):
    """A random half of the faces, shuffled: against the dict pairing of the whole mesh restricted to them."""
    m = _read(path)
    polys = [list(p) for p in (m.polygons if isinstance(m, PolyMesh) else m.faces.tolist())]
    hes, _, twin = _brute(polys)
    rng = np.random.default_rng(len(polys))
    faces = rng.permutation(len(polys))[: max(1, len(polys) // 2)]
    sub = m.halfedges.subset(faces)
    corners = [h for f in faces.tolist() for h, (_, _, g) in enumerate(hes) if g == f]  # in the subset's order
    where = {h: i for i, h in enumerate(corners)}
    assert sub.parent_halfedge.tolist() == corners and sub.parent_face.tolist() == faces.tolist()
    assert sub.org.tolist() == [hes[h][0] for h in corners]
    assert sub.org[sub.nxt].tolist() == [hes[h][1] for h in corners]
    assert sub.twin.tolist() == [where.get(twin[h], -1) if twin[h] >= 0 else -1 for h in corners]
    assert sub.n_vertices == m.halfedges.n_vertices and sub.n_faces == faces.size


def test_subset_refuses_repeated_or_foreign_faces():
    he = HalfEdges([0, 1, 4, 3, 1, 2, 5, 4], [0, 4, 8], 6)
    for bad in ([0, 0], [2], [-1]):
        with pytest.raises(ValueError, match="distinct faces"):
            he.subset(bad)
    assert he.subset([]).org.size == 0
