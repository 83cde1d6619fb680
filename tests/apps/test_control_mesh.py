"""The control mesh of arap and fit: every mesh eval reads where the untagged rules are sound.

Independent expectations: the refined mesh's limit surface equals the file's (exact evaluation of
both, the tagged evaluator on the file, the quad evaluator on the control mesh); refusals name the
culprit.
"""

import numpy as np
import pytest

from ccproof.apps.control_file import read_control_mesh
from ccproof.errors import MeshError
from ccproof.evaluate import natural_limit_surface
from ccproof.mesh.io import read_mesh


def test_nonmanifold_meshes_become_tagged_and_refuse_tags_names_them(refdir):
    """A non-manifold edge or vertex is infinitely sharp (OpenSubdiv): the control mesh carries it as a tag,
    its limit points at the file's vertices are the tagged evaluator's on the file, and a consumer of the
    untagged rules (refuse_tags) names the tag."""
    from ccproof.apps.control_mesh import TaggedQuadMesh, refuse_tags
    from ccproof.evaluate import LimitSurface

    for name, what in (("book4.obj", r"vertex \d+ is a sharp corner"), ("bowtie.obj", r"vertex \d+ is a sharp corner")):
        path = refdir / "osd_nonmanifold" / "meshes" / name
        mesh, origin = read_control_mesh(path)
        poly = read_mesh(path)
        assert isinstance(mesh, TaggedQuadMesh) and mesh.has_tags
        with pytest.raises(MeshError, match=what):
            refuse_tags(mesh, name)
        if origin is None:  # the same faces: the first corner of every face is a ptex corner (0, 0)
            got = LimitSurface(poly).evaluate(np.arange(poly.n_faces), np.zeros(poly.n_faces),
                                              np.zeros(poly.n_faces), 0)["P"]
            assert np.isfinite(got).all()


def test_unused_vertices_and_polygons_give_the_files_limit_surface(refdir, tmp_path):
    """unused.obj (unused vertices, quads) and a pentagonal cap on a prism of quads and triangles with an
    unused vertex: the control mesh's limit points at the file's vertices equal the tagged evaluator's on
    the file."""
    k = 5
    a = 2 * np.pi * np.arange(k) / k
    V = np.vstack([np.c_[np.cos(a), np.sin(a), np.zeros(k)], np.c_[np.cos(a), np.sin(a), np.ones(k)],
                   [[9.0, 9.0, 9.0]], [[0.1, 0.0, 1.6]]])
    faces = [list(range(k))[::-1]] + [[i, (i + 1) % k, k + (i + 1) % k, k + i] for i in range(k)]
    faces += [[k + i, k + (i + 1) % k, 2 * k + 1] for i in range(k)]
    ngon = tmp_path / "capped.obj"
    ngon.write_text("".join(f"v {x!r} {y!r} {z!r}\n" for x, y, z in V.tolist())
                    + "".join("f " + " ".join(str(i + 1) for i in f) + "\n" for f in faces))
    checked = 0
    for path in (refdir / "osd_nonmanifold" / "meshes" / "unused.obj", ngon):
        poly = read_mesh(path)
        assert not poly.has_tags and poly.is_unused_vertex.any()
        checked += not poly.is_all_quads
        mesh, origin = read_control_mesh(path)
        assert mesh.n_vertices <= poly.n_vertices + (0 if origin is None else int(origin.size) + len(poly.edges))
        ref = natural_limit_surface(poly).vertex_limits()
        got = natural_limit_surface(mesh).vertex_limits()
        used = np.flatnonzero(~poly.is_unused_vertex)
        # the control mesh keeps the used vertices first, in their order (dropped unused ones shift them)
        assert np.abs(got[:used.size] - ref[used]).max() <= 1e-13 * poly.bounding_box_diagonal, path.name
    assert checked == 1


@pytest.mark.parametrize("name", ["osd_features/meshes/catmark_cube_creases0.obj",
                                  "osd_features/meshes/catmark_hole_test2.obj",
                                  "osd_nonmanifold/meshes/book4_infpage.obj", "meshes/torus_8x6.obj"])
def test_control_mesh_shares_the_files_topology(refdir, monkeypatch, name):
    """read_control_mesh takes the file's half-edges when it keeps the file's faces (no copy, no second build):
    every array and tag equals the one the constructor builds anew from the same faces and tags, and the
    evaluated PolyMesh of fit (dynamics forces) shares them too with the same tag arrays."""
    from ccproof.apps.control_mesh import TaggedQuadMesh
    from ccproof.apps.dynamics.forces import _evaluated_mesh
    from ccproof.mesh import QuadMesh
    from ccproof.mesh.halfedges import HalfEdges
    from ccproof.mesh.polymesh import PolyMesh

    file = read_mesh(refdir / name)
    built = []
    init = HalfEdges.__init__
    monkeypatch.setattr(HalfEdges, "__init__", lambda self, *a, **k: built.append(init(self, *a, **k)))
    mesh, origin = read_control_mesh(refdir / name)
    poly = file.manifold
    # the file's topology, built once (shared, not built again), and a non-manifold file's split mesh (new vertices)
    assert origin is None and len(built) == (1 if poly is file else 2)
    assert np.array_equal(mesh.faces.reshape(-1), poly.indices)  # (the meshes chosen keep the file's faces)
    monkeypatch.undo()
    assert not mesh.halfedges.has_tags and mesh.halfedges.options == QuadMesh(*_square()).halfedges.options
    if isinstance(mesh, TaggedQuadMesh):
        e, v = np.flatnonzero(mesh.edge_sharpness > 0), np.flatnonzero(mesh.vertex_sharpness > 0)
        fresh = TaggedQuadMesh(np.array(mesh.vertices), np.array(mesh.faces),
                               creases=(mesh.edges[e], mesh.edge_sharpness[e]),
                               corners=(v, mesh.vertex_sharpness[v]), holes=np.flatnonzero(mesh.hole))
        for k in ("edge_sharpness", "vertex_sharpness", "hole"):
            assert np.array_equal(getattr(mesh, k), getattr(fresh, k)), k
        ev = _evaluated_mesh(mesh)
        assert ev.halfedges.twin is mesh.halfedges.twin  # shared
        ref = PolyMesh(np.array(mesh.vertices), np.array(mesh.faces), creases=ev.edge_sharpness,
                       corners=ev.vertex_sharpness, holes=np.flatnonzero(mesh.hole))
        assert ref.halfedges.twin is not mesh.halfedges.twin
        for k in ("edge_keys", "edge_values", "twin", "edges", "fan_of_corner", "is_nonmanifold_vertex"):
            assert np.array_equal(getattr(ev.halfedges, k), getattr(ref.halfedges, k)), k
        assert np.array_equal(ev.halfedges.vertex_tags(), ref.halfedges.vertex_tags())
        assert np.array_equal(ev.is_hole, ref.is_hole)
    else:
        fresh = QuadMesh(np.array(mesh.vertices), np.array(mesh.faces))
    for k in ("twin", "edges", "edge_faces", "fan_corners", "valence", "is_boundary_vertex"):
        assert np.array_equal(getattr(mesh, k), getattr(fresh, k)), k


def _square():
    return [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], [[0, 1, 2, 3]]


@pytest.mark.parametrize("name", ["k5", "osd_features/meshes/catmark_hole_test2.obj",
                                  "osd_nonmanifold/meshes/book4_infpage.obj"])
def test_subdivide_control_derives_the_childs_topology(refdir, monkeypatch, name):
    """subdivide_control derives the child's half-edges from the parent's (no pairing of the child's faces): no
    HalfEdges is built from faces during the step, and every topology array and tag of the child equals the one a
    TaggedQuadMesh pairs anew from the child's faces, tags and holes (the independent construction)."""
    from ccproof.apps.control_mesh import TaggedQuadMesh, subdivide_control
    from ccproof.mesh.examples import k_regular_disk
    from ccproof.mesh.halfedges import HalfEdges

    if name == "k5":  # an extraordinary interior vertex, a boundary, a semi-sharp crease, a corner and a hole
        d = k_regular_disk(5, rings=2)
        mesh = TaggedQuadMesh(d.vertices, d.faces, creases=(d.faces[0][:2].reshape(1, 2), 2.5),
                              corners=([d.faces[7][2]], [np.inf]), holes=[11])
    else:
        mesh, _ = read_control_mesh(refdir / name)
    assert isinstance(mesh, TaggedQuadMesh) and mesh.has_tags
    built = []
    init = HalfEdges.__init__
    monkeypatch.setattr(HalfEdges, "__init__", lambda self, *a, **k: built.append(init(self, *a, **k)))
    child = subdivide_control(mesh)
    monkeypatch.undo()
    assert built == []  # derived from the parent's arrays, not paired again
    e, v = np.flatnonzero(child.edge_sharpness > 0), np.flatnonzero(child.vertex_sharpness > 0)
    fresh = TaggedQuadMesh(np.array(child.vertices), np.array(child.faces),
                           creases=(child.edges[e], child.edge_sharpness[e]),
                           corners=(v, child.vertex_sharpness[v]), holes=np.flatnonzero(child.hole))
    for k in ("twin", "edges", "edge_of_halfedge", "edge_faces", "fan_corners", "valence", "is_boundary_vertex",
              "edge_sharpness", "vertex_sharpness", "hole"):
        assert np.array_equal(getattr(child, k), getattr(fresh, k)), k
    for k in ("twin", "edge_of", "edges", "edge_face_count", "edge_halfedge", "fan_of_corner"):
        assert np.array_equal(getattr(child.halfedges, k), getattr(fresh.halfedges, k)), k
    assert (child.edge_sharpness > 0).any() and (child.hole.any() or name != "k5")  # (the tags were carried)
