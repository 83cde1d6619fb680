"""PolyMesh.with_vertices: the topology objects shared, everything equal to a PolyMesh built anew.

The reference is the constructor on the moved vertices with the mesh's polygons and tags (its own
topology, tags and split of the non-manifold vertices); the moved mesh must agree with it in every
array and in what is computed from them (one subdivision step and its operator, bit for bit).
"""

import numpy as np
import pytest

from ccproof.errors import MeshError
from ccproof.mesh.io import read_mesh
from ccproof.mesh.polymesh import PolyMesh

CASES = [("osd_features", "catmark_pyramid_creases1.obj"), ("osd_features", "catmark_hole_test2.obj"),
         ("osd_features", "catmark_chaikin1.obj"), ("osd_nonmanifold", "bowtie.obj"),
         ("osd_nonmanifold", "unused.obj"), ("osd_nonmanifold", "book4_tags.obj")]
TOPOLOGY = ("indices", "offsets", "sizes", "halfedges", "edges", "twin", "next", "prev", "edge_sharpness",
            "vertex_sharpness", "is_hole", "options", "manifold_vertex_map", "ptex_start")


def _fresh(mesh, X):
    """The PolyMesh of ``mesh`` with vertices ``X``, through the constructor (nothing shared)."""
    es = mesh.edge_sharpness
    return PolyMesh(X, [list(p) for p in mesh.polygons],
                    creases=(list(es.keys()), list(es.values())) if es else None,
                    corners=dict(mesh.vertex_sharpness) or None, holes=np.flatnonzero(mesh.is_hole_tagged),
                    options=mesh.options)


def _same(a, b):
    return np.array_equal(a, b, equal_nan=True)


@pytest.mark.parametrize("folder,name", CASES)
def test_with_vertices_shares_the_topology_and_equals_a_fresh_mesh(refdir, folder, name):
    mesh = read_mesh(refdir / folder / "meshes" / name)
    V = np.array(mesh.vertices)
    rng = np.random.default_rng(3)
    X = V + rng.standard_normal(V.shape)
    X[mesh.is_unused_vertex] = np.nan  # may hold anything
    new = mesh.with_vertices(X)
    ref = _fresh(mesh, X)
    assert isinstance(new, PolyMesh) and new is not mesh
    for k in TOPOLOGY:  # the same objects, not copies
        assert getattr(new, k) is getattr(mesh, k), k
    assert new.manifold.halfedges is mesh.manifold.halfedges
    assert (new.manifold is new) == (mesh.manifold is mesh) == mesh.is_manifold
    assert new.manifold.manifold is new.manifold
    # equal to the mesh built anew: vertices, split vertices, topology arrays, tags
    assert _same(new.vertices, X) and not new.vertices.flags.writeable
    assert _same(new.manifold.vertices, ref.manifold.vertices)
    assert _same(new.manifold_vertex_map, ref.manifold_vertex_map)
    for he, hr in ((new.halfedges, ref.halfedges), (new.manifold.halfedges, ref.manifold.halfedges)):
        for k in ("org", "twin", "nxt", "prv", "edges", "face_of", "edge_of"):
            assert np.array_equal(getattr(he, k), getattr(hr, k)), k
    assert new.edge_sharpness == ref.edge_sharpness and new.vertex_sharpness == ref.vertex_sharpness
    assert np.array_equal(new.is_hole, ref.is_hole) and new.n_ptex == ref.n_ptex
    assert new.manifold.vertex_sharpness == ref.manifold.vertex_sharpness
    # what is computed from them: one step (vertices and tags) and its operator, bit for bit
    (a, Sa), (b, Sb) = new.refine(), ref.refine()
    assert _same(a.vertices, b.vertices) and np.array_equal(a.indices, b.indices)
    assert a.edge_sharpness == b.edge_sharpness and a.vertex_sharpness == b.vertex_sharpness
    assert _same(Sa.toarray(), Sb.toarray())
    assert new.bounding_box_diagonal == ref.bounding_box_diagonal
    # the original is untouched
    assert _same(mesh.vertices, V) and _same(mesh.manifold.vertices, V[mesh.manifold_vertex_map])


def test_with_vertices_bad_input(refdir):
    mesh = read_mesh(refdir / "osd_nonmanifold" / "meshes" / "bowtie.obj")  # vertex 0 split in two
    V = np.array(mesh.vertices)
    n = V.shape[0]
    with pytest.raises(MeshError, match=rf"shape \({n}, 3\), got \({n + 1}, 3\)"):
        mesh.with_vertices(np.zeros((n + 1, 3)))
    with pytest.raises(MeshError, match="shape"):
        mesh.with_vertices(V[:, :2])
    for v in (0, n - 1):  # the split vertex named by its own index, not its copy's
        X = V.copy()
        X[v, 1] = np.inf
        with pytest.raises(MeshError, match=f"^vertex {v} has a non-finite coordinate"):
            mesh.with_vertices(X)
    um = read_mesh(refdir / "osd_nonmanifold" / "meshes" / "unused.obj")
    unused = np.flatnonzero(um.is_unused_vertex)
    used = np.flatnonzero(~um.is_unused_vertex)
    X = np.array(um.vertices)
    X[unused] = np.nan
    assert _same(um.with_vertices(X).vertices, X)  # unused: anything
    X[used[-1], 2] = np.nan
    with pytest.raises(MeshError, match=f"vertex {int(used[-1])} "):
        um.with_vertices(X)
