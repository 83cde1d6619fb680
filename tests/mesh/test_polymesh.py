"""PolyMesh input (OBJ with OpenSubdiv tags, meshio, numpy), validation errors, ptex indexing, the rules."""

import json
import math
from fractions import Fraction

import numpy as np
import pytest

from ccproof.errors import CCProofError, MeshError
from ccproof.mesh import QuadMesh, subdivide
from ccproof.mesh.io import read_mesh, read_obj_tagged
from ccproof.mesh.polymesh import PolyMesh

OSD_BOUNDARY = {"VTX_BOUNDARY_EDGE_ONLY": "edge_only", "VTX_BOUNDARY_EDGE_AND_CORNER": "edge_and_corner",
                "VTX_BOUNDARY_NONE": "none"}
SHAPES = ["chaikin1", "cube_corner2", "cubes_infsharp", "edgenone", "hole_test2", "nonquads",
          "pyramid_creases1", "smoothtris1", "helmet"]


@pytest.mark.parametrize("name", SHAPES)
def test_obj_tags_match_opensubdiv_topology(refdir, name):
    d = json.loads((refdir / "osd_features" / f"osd_limit_catmark_{name}.json").read_text())
    m = read_obj_tagged(refdir / "osd_features" / d["mesh"])
    assert (m.n_vertices, m.n_faces, m.n_ptex) == (d["num_vertices"], d["num_faces"], d["num_ptex_faces"])
    assert m.options.boundary == OSD_BOUNDARY[d["boundary_interpolation"]]
    assert m.options.crease_method == {"CREASE_UNIFORM": "uniform", "CREASE_CHAIKIN": "chaikin"}[d["creasing_method"]]
    assert m.options.triangle_subdivision == d["triangle_subdivision"].split("_")[-1].lower()
    for c in d["creases"]:
        a, b = c["edge"]
        s = m.edge_sharpness.get((min(a, b), max(a, b)), 0.0)
        assert s == (math.inf if c["infinite"] else c["sharpness"]), c
    for c in d["corners"]:
        assert m.vertex_sharpness.get(c["vertex"], 0.0) == (math.inf if c["sharpness"] >= 10 else c["sharpness"])
    assert [f["verts"] for f in d["faces"]] == [list(p) for p in m.polygons]
    assert [f["ptex"] for f in d["faces"]] == m.ptex_start[:-1].tolist()
    assert sorted(np.flatnonzero(m.is_hole_tagged).tolist()) == sorted(d["holes"])
    assert sorted(np.flatnonzero(m.is_hole & ~m.is_hole_tagged).tolist()) == sorted(d["implicit_holes"])
    for f, p in enumerate(m.polygons):
        for k in range(len(p)):
            q = m.ptex_of(f, k)
            assert m.face_of_ptex(q) == (f, k if len(p) != 4 else 0)


def _mixed():
    V = [[0, 0, 0], [1, 0, 0], [2, 0, 0], [0, 1, 0], [1, 1, 0], [2, 1, 0.5], [1, 2, 0]]
    F = [[0, 1, 4, 3], [1, 2, 5, 4], [3, 4, 6], [4, 5, 6]]
    return V, F


def test_numpy_inputs_agree():
    V, F = _mixed()
    a = PolyMesh(V, F, creases=([[1, 4], [4, 6]], [2.5, 12.0]), corners=([0], [1.0]), holes=[3])
    idx = np.concatenate([np.array(f) for f in F])
    off = np.r_[0, np.cumsum([len(f) for f in F])]
    b = PolyMesh(V, (idx, off), creases={(4, 1): 2.5, (6, 4): 12}, corners={0: 1.0}, holes=[3])
    c = PolyMesh(V, idx, sizes=[4, 4, 3, 3], creases=(np.array([[1, 4], [4, 6]]), np.array([2.5, 12.0])),
                 corners={0: 1}, holes=[3])
    for m in (b, c):
        assert m.polygons == a.polygons and m.edge_sharpness == a.edge_sharpness
        assert m.vertex_sharpness == a.vertex_sharpness and (m.is_hole == a.is_hole).all()
    assert a.edge_sharpness[(4, 6)] == math.inf and a.n_ptex == 2 + 3 + 3
    assert a.face_of_ptex(5) == (3, 0) and a.ptex_of(2, 2) == 4


def test_meshio_input(tmp_path):
    meshio = pytest.importorskip("meshio")
    V, F = _mixed()
    p = tmp_path / "mixed.vtk"
    meshio.write_points_cells(str(p), np.array(V, float), [("quad", np.array(F[:2])), ("triangle", np.array(F[2:]))])
    m = read_mesh(p)
    assert [list(q) for q in m.polygons] == F and np.array_equal(m.vertices, np.array(V, float))
    q = tmp_path / "lines.vtk"
    meshio.write_points_cells(str(q), np.array(V, float), [("line", np.array([[0, 1]]))])
    with pytest.raises(MeshError, match="cell block 0 has type 'line'"):
        read_mesh(q)


@pytest.mark.parametrize("kwargs,msg", [
    ({"creases": {(0, 5): 1.0}}, r"crease on edge \(0, 5\): no such edge in the mesh"),
    ({"creases": {(0, 2 ** 64): 1.0}}, r"crease on edge \(0, 18446744073709551616\): no such edge in the mesh"),
    ({"creases": {(0, 1): 1.0, (-2 ** 63, 2): 1.0}}, r"crease on edge \(-9223372036854775808, 2\): no such edge"),
    ({"creases": {(0, 1): -0.5}}, r"crease on edge \(0, 1\): negative sharpness -0.5"),
    ({"creases": {(0, 1): float("nan")}}, r"crease on edge \(0, 1\): sharpness is NaN"),
    ({"corners": {2: -1}}, r"corner on vertex 2: negative sharpness"),
    ({"corners": {9: 1}}, r"corner on vertex 9: out of range"),
    ({"holes": [7]}, r"hole face 7 out of range"),
    ({"faces": [[0, 1]]}, r"face 0 has 2 vertices"),
    ({"faces": [[0, 1, 9]]}, r"face 0 has a vertex index out of range"),
    ({"nan": True}, r"vertex 2 has a non-finite coordinate"),
])
def test_bad_input_names_the_element(kwargs, msg):
    V, F = _mixed()
    V = np.array(V, float)
    n = kwargs.pop("n", None)
    if n is not None:
        V = np.random.default_rng(0).random((n, 3))
    if kwargs.pop("nan", False):
        V[2, 1] = np.nan
    F = kwargs.pop("faces", F)
    with pytest.raises(MeshError, match=msg):
        PolyMesh(V, F, **kwargs)


@pytest.mark.parametrize("faces,n,nm_edges,nm_vertices", [
    ([[0, 1, 4, 3], [1, 4, 2, 5], [4, 1, 6]], 7, [[1, 4]], [1, 4]),  # an edge of three faces
    ([[0, 1, 3], [1, 2, 4], [4, 5, 1]], 6, [], [1]),  # two fans at vertex 1
    ([[0, 1, 4, 3], [1, 4, 5, 2]], 6, [[1, 4]], [1, 4]),  # two faces traverse (1, 4) the same way
    ([[0, 1, 2], [0, 1, 2]], 3, [[0, 1], [0, 2], [1, 2]], [0, 1, 2]),  # a face given twice
    ([[0, 1, 1], [0, 2, 1]], 3, [[0, 1], [1, 1]], [0, 1]),  # a face repeating a vertex (degenerate edge)
])
def test_nonmanifold_meshes_are_classified_as_opensubdiv_does(faces, n, nm_edges, nm_vertices):
    """OpenSubdiv's Vtr::Level: an edge with more than two faces or two faces in the same direction is
    non-manifold, so are its end vertices and every vertex whose faces form more than one fan."""
    V = np.random.default_rng(0).random((n, 3))
    m = PolyMesh(V, faces)
    assert not m.is_manifold
    assert m.nonmanifold_edges.tolist() == nm_edges
    assert np.flatnonzero(m.is_nonmanifold_vertex).tolist() == nm_vertices
    M = m.manifold  # every fan of a non-manifold vertex on its own, same faces
    assert M.is_manifold and M.n_faces == m.n_faces and M.n_ptex == m.n_ptex
    assert np.array_equal(M.vertices, V[m.manifold_vertex_map])
    for p, q in zip(m.polygons, M.polygons):
        assert m.manifold_vertex_map[list(q)].tolist() == list(p)
    # one step: the split's step, as a matrix on this mesh's vertices, and its exact rows
    m1, S = m.refine()
    assert S.shape == (M.n_vertices + len(M.edges) + M.n_faces, n)
    assert np.abs(m1.vertices - S @ V).max() <= 1e-15
    exact = m.subdivision_operator(exact=True)
    dense = np.zeros(S.shape)
    for r, row in enumerate(exact):
        for c, w in row.items():
            dense[r, c] = int(w.p) / int(w.q)
    assert np.abs(dense - S.toarray()).max() <= 1e-16


def test_unused_vertices_keep_their_indices():
    V = np.array([[np.nan] * 3, [0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [np.inf, 0, 0]], float)
    m = PolyMesh(V, [[1, 2, 3, 4]])
    assert m.is_unused_vertex.tolist() == [True, False, False, False, False, True] and m.is_manifold
    assert m.bounding_box_diagonal == pytest.approx(np.sqrt(2))
    V[2, 0] = np.nan
    with pytest.raises(MeshError, match=r"vertex 2 has a non-finite coordinate"):
        PolyMesh(V, [[1, 2, 3, 4]])


def test_obj_tag_errors(tmp_path):
    base = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n"
    for tag, msg in [("t vertexedit 1/0/0 0", "tag 'vertexedit': not supported"),
                     ("t crease 2/1/0 0 2 1.0", r"crease on edge \(0, 2\): no such edge"),
                     ("t crease 2/1/0 0 1 nan", r"sharpness is NaN on edge \(0, 1\)"),
                     ("t interpolateboundary 1/0/0 5", "expected one of 0, 1, 2"),
                     ("t crease 2/1/0 0 1", "announces 3 values, has 2")]:
        p = tmp_path / "t.obj"
        p.write_text(base + tag + "\n")
        with pytest.raises(MeshError, match=msg):
            read_obj_tagged(p)
    p.write_text(base + "t crease 2/1/0 0 1 -3\nt corner 1/1/0 2 0.5\n")
    m = read_obj_tagged(p)  # negative sharpness is clamped to 0, as OpenSubdiv's shape_utils does
    assert m.edge_sharpness == {} and m.vertex_sharpness == {2: 0.5}


def test_ptex_and_parameter_errors(refdir):
    from ccproof.evaluate import limit_surface

    m = read_obj_tagged(refdir / "osd_features" / "meshes" / "catmark_pyramid_creases1.obj")
    S = limit_surface(m)
    with pytest.raises(CCProofError, match=r"point 1: face id 13 out of range \[0, 13\)"):
        S.evaluate([0, 13], [0.5, 0.5], [0.5, 0.5])
    with pytest.raises(CCProofError, match=r"point 0: v = 1.5 is outside \[0, 1\]"):
        S.evaluate([0], [0.5], [1.5])
    with pytest.raises(CCProofError, match=r"point 0: u = nan is outside"):
        S.evaluate([0], [np.nan], [0.5])
    with pytest.raises(MeshError, match=r"ptex face 13 out of range"):
        m.face_of_ptex(13)


@pytest.mark.parametrize("name", ["pyramid_creases1", "chaikin1", "smoothtris1", "edgecorner"])
def test_exact_and_float_operator_agree(refdir, name):
    m = read_obj_tagged(refdir / "osd_features" / "meshes" / f"catmark_{name}.obj")
    for _ in range(2):  # level 0 (n-gons, level-0 rules) and level 1 (decayed tags)
        exact = m.subdivision_operator(exact=True)
        S = m.subdivision_operator().toarray()
        E = np.array([[float(r.get(j, Fraction(0))) for j in range(m.n_vertices)] for r in exact])
        assert np.array_equal(S, E)
        assert all(sum(r.values()) == 1 for r in exact)  # affine invariance, exactly
        m1, S1 = m.refine()
        assert np.array_equal(m1.vertices, S1 @ m.vertices)
        m = m1


def test_untagged_step_matches_reference(refdir):
    # untagged all-quad meshes: the same step as the independent ccproof.mesh.subdivide
    from ccproof.mesh.examples import cube

    q = cube()
    p = PolyMesh(q.vertices, q.faces)
    p1, _ = p.refine()
    r = subdivide(q)
    n, E_, F_ = q.n_vertices, q.n_edges, q.n_faces
    def close(x, y):  # the two implementations sum the same exact weights in different orders
        return np.abs(x - y).max() <= 4e-16

    assert close(p1.vertices[:n], r.vertices[:n])
    assert close(p1.vertices[n + E_ :], r.vertices[n + E_ :])
    cx = p.complex()
    for e, h in enumerate(cx.edges):
        a, b = cx.org[h], cx.dst(h)
        ref = int(np.flatnonzero((q.edges[:, 0] == min(a, b)) & (q.edges[:, 1] == max(a, b)))[0])
        assert close(p1.vertices[n + e], r.vertices[n + ref])
    assert isinstance(q, QuadMesh) and F_ == 6


def test_quad_reader_refuses_tags(refdir):
    from ccproof.mesh import read_obj

    with pytest.raises(MeshError, match=r"catmark_cube_creases0.obj:\d+: OpenSubdiv tag 'crease'"):
        read_obj(refdir / "osd_features" / "meshes" / "catmark_cube_creases0.obj")


def test_refine_without_the_operator_gives_the_same_vertices():
    """refine(operator=False) (the evaluator's setup: no scipy) sums each stencil as the sparse product does."""
    V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0.3], [2, 0.5, 0.1], [np.nan, 0, 0]])
    m = PolyMesh(V, [[0, 1, 2, 3], [1, 4, 2]], creases={(1, 2): 1.5}, options={"triangle_subdivision": "smooth"})
    m1, S = m.refine()
    m2, none = m.refine(operator=False)
    assert none is None
    assert np.array_equal(m1.vertices, m2.vertices, equal_nan=True)
    used = ~m2.is_unused_vertex  # the unused NaN vertex stays unused; it enters no used vertex's stencil
    assert used.sum() == 13 and np.isfinite(m2.vertices[used]).all()
    assert np.array_equal(m1.vertices[used], (S @ np.where(np.isnan(V), 0.0, V))[used])


def test_complex_topology_numpy_equals_the_loop(refdir, monkeypatch):
    """The numpy construction of a large Complex's half-edge lists gives the loop's lists exactly (twins,
    edge numbering by first occurrence, corners), on the OpenSubdiv shapes, their refinements and
    non-manifold meshes (a directed edge repeated: the last one is the twin, as the loop's dict keeps)."""
    from ccproof.mesh import complex as complex_module
    from ccproof.mesh.io import read_mesh

    names = ["osd_features/meshes/catmark_nonquads.obj", "osd_features/meshes/catmark_smoothtris1.obj",
             "meshes/bunny_quads.obj", "osd_nonmanifold/meshes/book4.obj", "osd_nonmanifold/meshes/dupface.obj",
             "osd_nonmanifold/meshes/flipped.obj", "osd_nonmanifold/meshes/collapsed.obj"]
    attrs = ("start", "org", "face_of", "nxt", "prv", "twin", "edges", "he_edge", "edge_index", "corners")
    n = 0
    for name in names:
        m = read_mesh(refdir / name)
        faces = [list(p) for p in m.polygons]
        cases = [faces, [list(f) for f in m.manifold.refine(operator=False)[0].polygons]]
        for F in cases:
            monkeypatch.setattr(complex_module, "_VECTORIZED_FACES", 1 << 30)
            a = complex_module.Complex(F, {}, {}, m.options, n_vertices=None)
            monkeypatch.setattr(complex_module, "_VECTORIZED_FACES", 1)
            b = complex_module.Complex(F, {}, {}, m.options, n_vertices=None)
            for k in attrs:
                assert getattr(a, k) == getattr(b, k), (name, k)
            n += 1
    assert n == 2 * len(names)


def test_shared_halfedges_taken_only_when_they_are_the_meshs():
    """``PolyMesh(..., _halfedges=he)`` takes ``he`` only when it is the untagged pairing of these faces under these
    options; half-edges of the faces rolled by one corner or in reverse order, tagged ones, or ones under other
    options are not taken: the mesh builds its own, every array as the constructor without ``he``."""
    from ccproof.mesh.examples import grid
    from ccproof.mesh.rules import Options

    g = grid(3, 3)
    F = np.asarray(g.faces)
    V = np.asarray(g.vertices)
    assert PolyMesh(V, F, _halfedges=g.halfedges).halfedges is g.halfedges  # the same faces: taken
    tagged = PolyMesh(V, F, creases={(5, 6): 2.0})
    assert tagged.halfedges.has_tags
    cases = [(np.roll(F, 1, axis=1), {}, g.halfedges), (F[::-1].copy(), {}, g.halfedges),
             (F, {}, tagged.halfedges), (F, {"options": Options(boundary="edge_and_corner")}, g.halfedges)]
    for F2, kw, he in cases:
        got, ref = PolyMesh(V, F2, _halfedges=he, **kw), PolyMesh(V, F2, **kw)
        assert got.halfedges is not he
        for k in ("org", "twin", "nxt", "prv", "edges", "edge_of", "edge_keys", "edge_values"):
            assert np.array_equal(getattr(got.halfedges, k), getattr(ref.halfedges, k)), k
        assert got.halfedges.options == ref.halfedges.options == (kw.get("options") or Options())
