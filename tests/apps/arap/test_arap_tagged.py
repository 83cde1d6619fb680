"""ARAP on tagged and non-manifold meshes: the surface it parameterizes is the surface ``ccproof eval`` evaluates.

Independent path: the limit points the application writes (its own stationary masks on its own chart levels,
:mod:`ccproof.apps.control_mesh`) are compared with the evaluator's table (:class:`~ccproof.evaluate.LimitSurface`
on the file's :class:`~ccproof.mesh.polymesh.PolyMesh`, which refines semi-sharp features, darts and n-gons
its own way: local exact subdivision and eigen-analysis of corner configurations) at the ptex coordinates of
every corner of every level-k chart face, derived here from the face numbering alone.
"""

import numpy as np
import pytest

from ccproof.apps.arap.charts import segment_by_normals
from ccproof.apps.arap.export import sample_chart
from ccproof.apps.arap.meshes import LevelPlan, compare
from ccproof.apps.control_file import read_control_mesh
from ccproof.apps.control_mesh import TaggedQuadMesh, subdivide_control, tagged_step
from ccproof.evaluate import LimitSurface
from ccproof.mesh.io import read_mesh

CORNERS = np.array([(0, 0), (1, 0), (1, 1), (0, 1)], dtype=float)


def _child(frame, i):
    """Frame (origin o, matrix A: (s, t) -> o + A (s, t)) of child i (corner i of the quad, child's corner 0)."""
    o, A = frame
    c = CORNERS[i]
    cols = np.c_[(CORNERS[(i + 1) % 4] - c) / 2, (CORNERS[(i + 3) % 4] - c) / 2]
    return o + A @ c, A @ cols


def _control_frames(poly, n_control, origin):
    """Ptex face and frame of every control face of read_control_mesh (global steps: 0 if origin is None)."""
    ident = (np.zeros(2), np.eye(2))
    if origin is None:
        return [(int(poly.ptex_of(f)), ident) for f in range(n_control)]
    first = int(np.asarray(poly.sizes).sum())
    steps = 1 + int(round(np.log(n_control / first) / np.log(4)))
    assert first * 4 ** (steps - 1) == n_control
    offsets = np.asarray(poly.offsets)
    out = []
    for c in range(n_control):
        digits = []
        for _ in range(steps - 1):
            digits.append(c % 4)
            c //= 4
        f = int(np.searchsorted(offsets, c, side="right") - 1)
        k = c - int(offsets[f])
        if poly.sizes[f] == 4:
            ptex, fr = int(poly.ptex_start[f]), _child(ident, k)
        else:
            ptex, fr = int(poly.ptex_start[f]) + k, ident
        for d in reversed(digits):
            fr = _child(fr, d)
        out.append((ptex, fr))
    return out


def _check_samples(path, level=2, methods=("c", "b"), text=None, tmp_path=None):
    if text is not None:  # a variant of the file, written next to the test
        p = tmp_path / path.name
        p.write_text(text)
        path = p
    poly = read_mesh(path)
    mesh, origin = read_control_mesh(path)
    assert isinstance(mesh, TaggedQuadMesh)
    labels = segment_by_normals(mesh)
    res, hs = compare(mesh, labels, methods, LevelPlan(levels=1, eval_level=level, sample_level=level))
    frames = _control_frames(poly, mesh.n_faces, origin)
    S = LimitSurface(poly)
    worst = 0.0
    for m in methods:
        assert all(np.isfinite(x) for x in res[m].metrics.as_tuple()), (path.name, m)
        for tex in res[m].textures:
            h = tex.hierarchy
            P, UV, Q = sample_chart(tex, level)
            assert np.isfinite(UV).all()
            faces, us, vs, idx = [], [], [], []
            for t in range(Q.shape[0]):
                c, digits = t, []
                for _ in range(level):
                    digits.append(c % 4)
                    c //= 4
                ptex, fr = frames[int(h.chart_faces[c])]
                for d in reversed(digits):
                    fr = _child(fr, d)
                for j in range(4):
                    uv = fr[0] + fr[1] @ CORNERS[j]
                    faces.append(ptex)
                    us.append(uv[0])
                    vs.append(uv[1])
                    idx.append(Q[t, j])
            ref = S.evaluate(faces, us, vs, 0)["P"]
            worst = max(worst, float(np.abs(P[idx] - ref).max()))
    assert worst <= 1e-12 * poly.bounding_box_diagonal, (path.name, worst)
    return mesh, res


@pytest.mark.parametrize("name", ["catmark_cube_creases0", "catmark_cubes_infsharp", "catmark_dart_edgeonly",
                                  "catmark_edgecorner", "catmark_cube_corner4", "catmark_nonquads",
                                  "catmark_pyramid_creases1", "catmark_hole_test2",
                                  pytest.param("catmark_chaikin1", marks=pytest.mark.slow)])
def test_arap_limit_samples_are_the_evaluators(refdir, name):
    mesh, res = _check_samples(refdir / "osd_features" / "meshes" / f"{name}.obj")
    if name == "catmark_hole_test2":  # holes are in no chart; the 7.5 crease stays a tag (no global step)
        assert mesh.hole.any() and mesh.global_steps == 0 and mesh.edge_sharpness.max() == 7.5
        for tex in res["c"].textures:
            assert not mesh.hole[tex.hierarchy.chart_faces].any()


def test_arap_with_chaikin_creases(refdir, tmp_path):
    """CREASE_CHAIKIN semi-sharp tags: resolved by global steps (catmark_cube_creases0 with Chaikin's rule: two
    steps, 96 faces, no tag left)."""
    path = refdir / "osd_features" / "meshes" / "catmark_cube_creases0.obj"
    mesh, _ = _check_samples(path, text=path.read_text() + "t creasemethod 0/0/1 chaikin\n", tmp_path=tmp_path)
    assert mesh.global_steps == 2 and mesh.n_faces == 96 and not mesh.has_tags


@pytest.mark.parametrize("name", ["book4", "bowtie", "two_cubes_creases", "book4_semipage", "book4_tags"])
def test_arap_on_nonmanifold_meshes(refdir, name):
    _check_samples(refdir / "osd_nonmanifold" / "meshes" / f"{name}.obj")


@pytest.mark.parametrize("name", ["catmark_cubes_infsharp", "catmark_hole_test2", "catmark_pyramid_creases1"])
def test_tagged_step_is_the_rules_operator(refdir, name):
    """The tagged step (vectorized rows, local fans at semi-sharp tags) equals mesh/rules' stencils of the
    whole mesh (PolyMesh.subdivision_operator) on meshes with infinitely sharp and semi-sharp creases, corners
    and boundaries, at two levels."""
    from ccproof.mesh.polymesh import PolyMesh

    mesh, _ = read_control_mesh(refdir / "osd_features" / "meshes" / f"{name}.obj")
    for m in (mesh, subdivide_control(mesh)):
        se = m.edge_sharpness > 0
        sv = np.flatnonzero(m.vertex_sharpness > 0)
        poly = PolyMesh(m.vertices, m.faces, creases=(m.edges[se], np.minimum(m.edge_sharpness[se], 10.0)),
                        corners=(sv, np.minimum(m.vertex_sharpness[sv], 10.0)) if sv.size else None)
        poly.level = 1
        ref = poly.subdivision_operator().toarray()
        got = tagged_step(m)[0].toarray()
        assert got.shape == ref.shape
        n, E = m.n_vertices, m.n_edges
        eid = poly.complex().edge_index  # the rules number the edges by first appearance
        perm = [eid[(min(a, b), max(a, b))] for a, b in m.edges.tolist()]
        rows = np.r_[np.arange(n), n + np.asarray(perm), n + E + np.arange(m.n_faces)]
        # both are the correctly rounded exact weights (mesh.step sums every row exactly, then divides once)
        assert np.array_equal(got, ref[rows])
        assert se.any()


def test_chaikin_semi_sharp_beyond_the_cap_is_refused_by_name(refdir, tmp_path):
    """Chaikin's semi-sharp rule needs every edge at both ends: resolved by global steps, refused by name
    beyond the cap (catmark_hole_test2's 7.5 crease with CREASE_CHAIKIN: 8 steps)."""
    from ccproof.errors import MeshError

    p = tmp_path / "hole_chaikin.obj"
    p.write_text((refdir / "osd_features" / "meshes" / "catmark_hole_test2.obj").read_text()
                 + "t creasemethod 0/0/1 chaikin\n")
    with pytest.raises(MeshError, match=r"edge \(6, 7\) of sharpness 7.5 with CREASE_CHAIKIN decays in 8 "):
        read_control_mesh(p)


@pytest.mark.parametrize("name", ["osd_features/meshes/catmark_cube_creases0.obj",
                                  "osd_nonmanifold/meshes/book4_infpage.obj"])
def test_arap_command_on_tagged_meshes(refdir, tmp_path, capsys, name):
    """``ccproof arap MESH --segment normals --out``: finite metrics, a readable output whose points lie on the
    evaluator's surface (each written point is a limit point: its nearest ptex corner evaluation agrees)."""
    import json

    from ccproof.apps.arap.export import read_surface
    from ccproof.cli import main

    out = tmp_path / "uv.obj"
    assert main(["arap", str(refdir / name), "--segment", "normals", "--levels", "1", "--eval-level", "3",
                 "--refine", "0", "--out-level", "1", "--out", str(out), "--no-progress"]) == 0
    cap = capsys.readouterr()
    assert "E_angle" in cap.out or "angle" in cap.out
    points, uv, cells = read_surface(out)
    assert np.isfinite(points).all() and np.isfinite(uv).all() and cells.size
    assert uv.min() >= -1e-12 and uv.max() <= 1 + 1e-12
    info = json.loads((tmp_path / "uv.obj.json").read_text())
    flat = json.dumps(info)
    assert "NaN" not in flat and "Infinity" not in flat
    # quality is never silent: at this explicit --refine 0 the creased cube folds; each fold is on stderr
    flips, folds = info["table"]["c"]["flips_eval"], info["folds"]
    assert (f"{flips} flipped samples at level 3" in cap.err) == (flips > 0), cap.err
    assert (f"{folds} of {cells.shape[0]} triangles are folded in UV" in cap.err) == (folds > 0), cap.err
    # the written points are limit points of the file's surface: every corner limit of the file's faces is
    # among them (charts cover every face; level 1 keeps the level-0 corners)
    poly = read_mesh(refdir / name)
    S = LimitSurface(poly)
    from ccproof.evaluate.tagged import vertex_corners

    f, u, v, _ = vertex_corners(poly)
    ref = S.evaluate(f, u, v, 0)["P"]
    d = np.min(np.linalg.norm(ref[:, None, :] - points[None, :, :], axis=2), axis=1)
    assert d.max() <= 1e-6 * poly.bounding_box_diagonal  # the OBJ writes %.9g-ish decimals


@pytest.mark.parametrize("name", ["catmark_hole_test2", "catmark_cube_creases0", "catmark_cubes_infsharp",
                                  "catmark_dart_edgeonly", "catmark_cube_corner4", "catmark_inf_crease1",
                                  "catmark_edgecorner", "catmark_xord_boundary", "catmark_helmet",
                                  "catmark_edgenone"])
def test_limit_masks_are_opensubdivs_vertex_limits(refdir, name):
    """The limit masks of every control vertex (stationary: closed forms and the dart's eigenvector; semi-sharp:
    the fan subdivided until stationary) against OpenSubdiv's own vertex limits (Far::PrimvarRefiner::Limit
    after local refinement until the sharpness has decayed, stored in tests/data/osd_features with their
    provenance)."""
    import json

    from ccproof.apps.arap.hierarchy import Level
    from ccproof.apps.arap.samples import limit_operator

    d = json.loads((refdir / "osd_features" / f"osd_limit_{name}.json").read_text())
    mesh, origin = read_control_mesh(refdir / "osd_features" / "meshes" / f"{name}.obj")
    assert origin is None and mesh.n_vertices == d["num_vertices"]  # the file's vertices, in order
    P = limit_operator(Level(mesh, mesh.n_faces), "extended") @ mesh.vertices
    ref = np.array([x if x is not None else [np.nan] * 3 for x in d["vertex_limit"]], dtype=float)
    ok = ~np.isnan(ref).any(axis=1)
    ok[d["vertices_without_surface"]] = False
    assert ok.sum() >= 0.4 * ok.size  # (edgenone: the boundary vertices have no surface)
    assert np.abs(P[ok] - ref[ok]).max() <= 1e-13 * d["limit_bbox_diagonal"], name


def _written_frames(poly, origin, n_control, times, n_written):
    """Ptex face and frame of every face of a control mesh written after ``times`` more subdivisions of the
    control mesh of read_control_mesh (child 4 c + i of face c: its corner i, as read_control_mesh numbers)."""
    frames = _control_frames(poly, n_control, origin)
    out = []
    for c in range(n_written):
        digits = []
        for _ in range(times):
            digits.append(c % 4)
            c //= 4
        ptex, fr = frames[c]
        for d in reversed(digits):
            fr = _child(fr, d)
        out.append((ptex, fr))
    return out


@pytest.mark.parametrize("name", ["osd_features/meshes/catmark_cube_creases0.obj",  # semi-sharp creases
                                  "osd_features/meshes/catmark_pyramid_creases1.obj",  # triangles: a global step
                                  "osd_features/meshes/catmark_hole_test2.obj",  # holes, a 7.5 crease
                                  "osd_nonmanifold/meshes/book4.obj",  # non-manifold: split, sharp
                                  "osd_features/meshes/catmark_edgecorner.obj",  # EDGE_AND_CORNER boundary
                                  "osd_features/meshes/catmark_edgenone.obj"])  # boundary NONE
def test_control_out_on_tagged_meshes_reads_back_with_its_tags_and_surface(refdir, tmp_path, capsys, name):
    """``--control-out`` on a tagged or non-manifold mesh: the written OBJ, read back, is the control mesh the
    UVs belong to (read_control_mesh of the input, subdivided with its tags as often as the sidecar says) with
    the same vertices bit for bit and the same creases, corners and holes; its limit surface (the evaluator on
    the written file) is the input file's at the ptex points derived from the face numbering alone."""
    import json

    from ccproof.cli import main
    from ccproof.mesh.io import read_obj_tagged

    src = refdir / name
    out = tmp_path / "ctl.obj"
    assert main(["arap", str(src), "--segment", "normals", "--levels", "1", "--eval-level", "3", "--refine", "0",
                 "--control-extra", "1", "--control-out", str(out), "--no-progress"]) == 0
    cap = capsys.readouterr()
    assert "tags as OpenSubdiv 't' lines" in cap.out
    side = json.loads((tmp_path / "ctl.obj.json").read_text())["table"]["control_out"]
    times = side["refine"] + side["extra_subdivisions"]
    start, origin = read_control_mesh(src)
    expect = start
    for _ in range(times):
        expect = subdivide_control(expect)
    assert any(line.startswith("t ") for line in out.read_text().splitlines())
    back, back_origin = read_control_mesh(out)
    assert back_origin is None and isinstance(back, TaggedQuadMesh)
    if expect.file_vertex is None:
        assert np.array_equal(back.faces, expect.faces) and np.array_equal(back.vertices, expect.vertices)
        for k in ("edge_sharpness", "vertex_sharpness", "hole"):
            assert np.array_equal(getattr(back, k), getattr(expect, k)), k
    else:  # non-manifold: written with the copies merged (one vertex each), read back split again
        lab, blab = expect.file_vertex, back.file_vertex
        from ccproof.mesh.io import read_obj_polygons

        W, polys, _ = read_obj_polygons(out)
        assert W.shape[0] == int(lab.max()) + 1 < expect.n_vertices
        assert np.array_equal(np.asarray(polys), lab[expect.faces]) and np.array_equal(W[lab], expect.vertices)
        assert np.array_equal(blab[back.faces], lab[expect.faces]) and np.array_equal(W[blab], back.vertices)

        def tags(m, la):
            e = np.flatnonzero(m.edge_sharpness > 0)
            v = np.flatnonzero(m.vertex_sharpness > 0)
            return ({(tuple(sorted(la[m.edges[i]].tolist())), float(m.edge_sharpness[i])) for i in e},
                    {(int(la[i]), float(m.vertex_sharpness[i])) for i in v}, m.hole.tolist())

        assert tags(back, blab) == tags(expect, lab)
    assert back.has_tags
    # the same limit surface: the written file against the input file, each through the evaluator
    poly_in, poly_out = read_mesh(src), read_obj_tagged(out)
    assert poly_out.is_all_quads and poly_out.n_faces == expect.n_faces
    S_in, S_out = LimitSurface(poly_in), LimitSurface(poly_out)
    frames = _written_frames(poly_in, origin, start.n_faces, times, poly_out.n_faces)
    rng = np.random.default_rng(3)
    faces = np.flatnonzero(~poly_out.is_hole)
    assert faces.size
    st = np.r_[CORNERS, rng.random((3, 2))]
    f_out = np.repeat(faces, st.shape[0])
    s_out, t_out = np.tile(st[:, 0], faces.size), np.tile(st[:, 1], faces.size)
    f_in, s_in, t_in = [], [], []
    for f, s, t in zip(f_out.tolist(), s_out.tolist(), t_out.tolist()):
        ptex, (o, A) = frames[f]
        p = o + A @ np.array([s, t])
        f_in.append(ptex)
        s_in.append(p[0])
        t_in.append(p[1])
    a = S_out.evaluate(poly_out.ptex_start[f_out], s_out, t_out, 0)["P"]
    b = S_in.evaluate(f_in, s_in, t_in, 0)["P"]
    assert np.abs(a - b).max() <= 1e-12 * poly_in.bounding_box_diagonal, np.abs(a - b).max()


def test_control_out_help_names_the_tags(capsys):
    from ccproof.cli import main

    with pytest.raises(SystemExit):
        main(["arap", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "tags as OpenSubdiv 't crease/corner/hole' lines" in text
