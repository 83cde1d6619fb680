"""Meshes OpenSubdiv accepts that a manifold reader would refuse, against OpenSubdiv 3.5's own values.

tests/data/osd_nonmanifold: non-manifold edges (four faces on an edge, a non-manifold crease vertex),
non-manifold vertices (two closed cubes touching at a vertex, two open sheets touching at a corner),
a face given twice, a face oriented against its neighbours, unused vertices (one with NaN
coordinates), a quad/n-gon OFF file. The reference values come from OpenSubdiv (driver.cpp in that
folder: adaptive level 10, regular B-spline patches marked ``exact``); they are inputs, never our
output. Tolerances relative to the bounding-box diagonal, as in test_osd_features.py: positions
1e-12, first derivatives 1e-10, on every sample OpenSubdiv evaluates on a regular patch.
"""

import functools
import json
import math

import numpy as np
import pytest

from ccproof.cli import main
from ccproof.errors import MeshError
from ccproof.evaluate import limit_surface
from ccproof.evaluate.surface import LimitSurface
from ccproof.mesh import PolyMesh, QuadMesh
from ccproof.mesh.io import read_mesh

#: every mesh of tests/data/osd_nonmanifold (README there)
MESHES = ["book4.obj", "two_cubes.obj", "bowtie.obj", "dupface.obj", "flipped.obj", "unused.obj", "prism.off",
          "book4_tags.obj", "book4_infpage.obj", "book4_semipage.obj", "bowtie_none.obj", "two_cubes_creases.obj",
          "two_cubes_chaikin.obj", "collapsed.obj"]


def _path(refdir, name):
    return refdir / "osd_nonmanifold" / "meshes" / name


@functools.cache
def _ref(refdir, name):
    stem = name.rsplit(".", 1)[0]
    return json.loads((refdir / "osd_nonmanifold" / f"osd_limit_{stem}.json").read_text())


#: where OpenSubdiv's patch is not the limit of its own rules: at a non-manifold vertex that is a corner by
#: three infinitely sharp edges (vertex sharpness 0), Far::PatchBuilder takes a fan of two faces between
#: the non-manifold edges for a regular crease patch; the vertex rule keeps the vertex fixed (corner).
#: mesh -> (vertex, half-width of the excluded square at its ptex corners; the level-10 patch is 2^-10)
OSD_CORNER_AS_CREASE = {"book4_infpage.obj": (1, 2.0**-10)}
_CORNER_ST = ((0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0))


def _near_vertex(mesh, rows, v, r):
    """Samples of quad ptex faces within max-norm distance r of a ptex corner at vertex v."""
    out = []
    for s in rows:
        f, _ = mesh.face_of_ptex(s["ptex"])
        p = mesh.polygons[f]
        out.append(len(p) == 4 and v in p and max(abs(s["s"] - _CORNER_ST[p.index(v)][0]),
                                                  abs(s["t"] - _CORNER_ST[p.index(v)][1])) < r)
    return np.array(out, dtype=bool)


def _exact(d, mesh=None, name=None):
    rows = [s for s in d["samples"] if s["exact"]]
    if name in OSD_CORNER_AS_CREASE:
        rows = [s for s, near in zip(rows, _near_vertex(mesh, rows, *OSD_CORNER_AS_CREASE[name])) if not near]
    f, s, t = (np.array([r[k] for r in rows]) for k in ("ptex", "s", "t"))
    return f, s, t, {k: np.array([r[k] for r in rows]) for k in ("P", "Ps", "Pt")}


def _compare(S, d, diag, name=None):
    f, s, t, ref = _exact(d, S.mesh, name)
    assert f.size >= 0.8 * len(d["samples"])  # most samples are on regular patches
    out = S.evaluate(f, s, t, 1)
    for key, rk, tol in (("P", "P", 1e-12), ("Pu", "Ps", 1e-10), ("Pv", "Pt", 1e-10)):
        err = np.abs(out[key] - ref[rk]).max() / diag
        assert err <= tol, (key, err)


@pytest.mark.parametrize("name", MESHES)
def test_mesh_matches_opensubdiv(refdir, name):
    d = _ref(refdir, name)
    mesh = read_mesh(_path(refdir, name))
    assert mesh.n_vertices == d["num_vertices"] and mesh.n_faces == d["num_faces"]
    assert mesh.n_ptex == d["num_ptex_faces"]
    assert [f["ptex"] for f in d["faces"]] == mesh.ptex_start[:-1].tolist()
    # OpenSubdiv's classification (it also tags unused vertices non-manifold: they have no fan)
    osd_nm = sorted(set(d["nonmanifold_vertices"]) - set(np.flatnonzero(mesh.is_unused_vertex).tolist()))
    assert np.flatnonzero(mesh.is_nonmanifold_vertex).tolist() == osd_nm
    # (OpenSubdiv lists every occurrence of an edge a face repeats as an edge of its own)
    osd_edges = sorted({tuple(sorted(e)) for e in d["nonmanifold_edges"]})
    assert osd_edges == list(map(tuple, mesh.nonmanifold_edges.tolist()))
    # its sharpening: infinitely sharp vertices are corners on every split copy, crease vertices keep
    # their own sharpness
    M, vmap = mesh.manifold, mesh.manifold_vertex_map
    for v in osd_nm:
        copies = np.flatnonzero(vmap == v).tolist()
        sharp = [M.vertex_sharpness.get(c, 0.0) for c in copies]
        if d["vertex_sharpness"][v] >= 10:
            assert sharp == [math.inf] * len(copies) and d["vertex_rule"][v] == "corner"
        elif d["vertex_rule"][v] == "crease":
            assert sharp == [d["vertex_sharpness"][v]] * len(copies) == [0.0] * len(copies)
        else:  # a corner by its own sharpness or by three sharp edges, for ever or until they decay
            at_v = [s for a, b, s in d["edges"] if v in (a, b) and s < 10]
            others = [s for a, b, s in d["edges"] if v in (a, b) and s >= 10 and sorted((a, b)) not in
                      sorted(map(sorted, d["nonmanifold_edges"]))]
            want = math.inf if others else max([d["vertex_sharpness"][v]] + at_v)
            assert sharp == [want] * len(copies)
    # holes (tagged, or OpenSubdiv's implicit ones under boundary mode none): no samples there
    ptex_hole = np.repeat(mesh.is_hole, np.diff(mesh.ptex_start))
    assert sorted({s["ptex"] for s in d["samples"]}) == np.flatnonzero(~ptex_hole).tolist()
    S = limit_surface(mesh)
    assert isinstance(S.mesh, PolyMesh)
    _compare(S, d, mesh.bounding_box_diagonal, name)


def test_opensubdiv_patch_at_a_corner_by_three_sharp_edges_is_not_its_limit(refdir):
    """book4_infpage: vertex 1 ends two non-manifold edges and an infinitely sharp page edge, so its
    rule is the corner rule (Sdc: three sharp edges; OpenSubdiv's own tags say 'corner'): every
    subdivision step keeps it where it is, its limit is its position (closed form). OpenSubdiv's
    level-10 "regular" patches of the three other pages put it 2e-5 away; ours put it there exactly."""
    name = "book4_infpage.obj"
    d = _ref(refdir, name)
    mesh = read_mesh(_path(refdir, name))
    assert d["vertex_rule"][1] == "corner" and d["vertex_sharpness"][1] == 0
    S = limit_surface(mesh)
    rows = [s for s in d["samples"] if s["exact"] and s["s"] in (0.0, 1.0) and s["t"] in (0.0, 1.0)]
    at1 = [s for s, near in zip(rows, _near_vertex(mesh, rows, 1, 1e-300)) if near]
    assert len(at1) == 6  # a corner sample on each face at vertex 1 of the three pages without the edge
    ours = S.evaluate([s["ptex"] for s in at1], [s["s"] for s in at1], [s["t"] for s in at1], 0)["P"]
    assert np.abs(ours - mesh.vertices[1]).max() <= 1e-15 * mesh.bounding_box_diagonal
    osd = np.array([s["P"] for s in at1])
    assert np.abs(osd - mesh.vertices[1]).max() > 1e-6 * mesh.bounding_box_diagonal
    # the page with the sharp edge gets a corner patch there: OpenSubdiv and we agree
    on_page0 = [s for s in d["samples"] if s["ptex"] in (0, 1) and s["exact"]]
    f = [s["ptex"] for s in on_page0]
    P = S.evaluate(f, [s["s"] for s in on_page0], [s["t"] for s in on_page0], 0)["P"]
    assert np.abs(P - [s["P"] for s in on_page0]).max() <= 1e-12 * mesh.bounding_box_diagonal


def test_the_book_has_a_crease_vertex_and_the_duplicate_face_is_accepted(refdir):
    """What the fixtures are meant to exercise, so that they cannot silently lose it."""
    book = _ref(refdir, "book4.obj")
    assert book["vertex_rule"][1] == "crease" and len(book["nonmanifold_edges"]) == 2
    m = read_mesh(_path(refdir, "book4.obj"))
    assert (m.edge_face_count[m.is_nonmanifold_edge] == 4).all()
    dup = read_mesh(_path(refdir, "dupface.obj"))
    assert dup.polygons[24] == dup.polygons[4] and not dup.is_manifold
    with pytest.raises(MeshError, match=r"duplicate face: faces 4 and 24 have the same vertices"):
        QuadMesh(dup.vertices, dup.polygons)


def test_unused_vertices_both_evaluators(refdir):
    """Unused vertices (one NaN) are ignored; vertex indices of the outputs are the file's."""
    d = _ref(refdir, "unused.obj")
    path = _path(refdir, "unused.obj")
    poly = read_mesh(path)
    assert poly.is_unused_vertex.tolist() == [True] + [False] * 4 + [True] + [False] * 22 + [True]
    assert np.isnan(poly.vertices[5]).all() and poly.is_plain_quads
    S = limit_surface(path)  # an untagged quad file: the QuadMesh evaluator
    assert isinstance(S, LimitSurface) and isinstance(S.mesh, QuadMesh)
    diag = poly.bounding_box_diagonal
    _compare(S, d, diag)
    _compare(LimitSurface(poly), d, diag)
    # vertex limits and normals by input index: NaN at the unused ones, OpenSubdiv's corner values elsewhere
    for T in (S, LimitSurface(poly)):
        L, N = T.vertex_limits(), T.vertex_normals()
        assert np.isnan(L[[0, 5, 28]]).all() and np.isnan(N[[0, 5, 28]]).all()
        corners = [s for s in d["samples"] if s["exact"] and s["s"] in (0.0, 1.0) and s["t"] in (0.0, 1.0)]
        for s in corners:
            i = {(0.0, 0.0): 0, (1.0, 0.0): 1, (1.0, 1.0): 2, (0.0, 1.0): 3}[(s["s"], s["t"])]
            v = poly.polygons[s["ptex"]][i]
            assert np.abs(L[v] - s["P"]).max() <= 1e-12 * diag
    # moved control points: the same surface as a fresh build, whatever the unused vertices hold
    X = np.array(poly.vertices)
    X[~poly.is_unused_vertex] *= 1.5
    X[0] = np.nan
    T = S.with_vertices(X)
    U = limit_surface(QuadMesh(X, np.array(poly.polygons)))
    f, s, t, _ = _exact(d)
    a, b = T.evaluate(f, s, t, 1), U.evaluate(f, s, t, 1)
    for k in a:
        assert np.abs(a[k] - b[k]).max() <= 1e-12 * diag
    assert np.abs(a["P"] - 1.5 * S.evaluate(f, s, t, 0)["P"]).max() <= 1e-12 * diag
    X[3] = np.inf
    with pytest.raises(MeshError, match=r"vertex 3 has a non-finite coordinate"):
        S.with_vertices(X)


def test_quad_and_ngon_off_file(refdir):
    meshio = pytest.importorskip("meshio")
    path = _path(refdir, "prism.off")
    with pytest.raises((meshio.ReadError, SystemExit)):  # the reason for our own OFF reader
        meshio.read(str(path))
    m = read_mesh(path)
    assert sorted({len(p) for p in m.polygons}) == [3, 4, 5] and m.is_manifold


def test_eval_command_reads_every_case(refdir, tmp_path):
    for name in ("book4.obj", "prism.off", "unused.obj", "two_cubes.obj"):
        d = _ref(refdir, name)
        f, s, t, ref = _exact(d)
        pts = tmp_path / "p.csv"
        rows = zip(f.tolist(), s.tolist(), t.tolist())
        pts.write_text("face,u,v\n" + "".join(f"{a},{b!r},{c!r}\n" for a, b, c in rows))
        out = tmp_path / "o.npz"
        assert main(["eval", str(_path(refdir, name)), "--points", str(pts), "--out", str(out)]) == 0
        P = np.load(out)["P"]
        assert np.abs(P - ref["P"]).max() <= 1e-12 * read_mesh(_path(refdir, name)).bounding_box_diagonal, name


def test_project_command_reads_an_off_file(refdir, tmp_path):
    path = _path(refdir, "prism.off")
    S = limit_surface(path)
    on = S.evaluate([0, 7, 12], [0.3, 0.5, 0.2], [0.6, 0.5, 0.9], 1)
    nrm = np.cross(on["Pu"], on["Pv"])
    X = on["P"] + 1e-3 * nrm / np.linalg.norm(nrm, axis=1)[:, None]
    csv = tmp_path / "x.csv"
    csv.write_text("x,y,z\n" + "".join(f"{a!r},{b!r},{c!r}\n" for a, b, c in X.tolist()))
    out = tmp_path / "o.npz"
    assert main(["project", str(path), str(csv), "--out", str(out)]) == 0
    r = np.load(out)
    assert np.abs(r["distance"] - 1e-3).max() <= 1e-9


def test_unsupported_nonmanifold_configurations_are_refused_by_name(refdir):
    """The split of the fans is OpenSubdiv's surface only where every rule at a copy is the vertex's rule.

    Where it is not and no corner comes close, the mesh is refused with the vertex and the reason."""
    book = read_mesh(_path(refdir, "book4.obj"))  # vertex 1: a non-manifold crease vertex (spine 0-1-2)
    V, F = np.array(book.vertices), [list(p) for p in book.polygons]
    with pytest.raises(MeshError, match=r"non-manifold crease vertex 1: semi-sharp edges or vertex sharpness "
                                         r"\[1\.2.*, 1\.5\] ending at the same level with different values"):
        PolyMesh(V, F, creases={(1, 4): 1.5, (1, 10): 1.2})
    chaikin = {"crease_method": "chaikin"}
    msg = r"non-manifold vertex {}: Chaikin creases with semi-sharp edges at a non-manifold vertex are supported only"
    with pytest.raises(MeshError, match=msg.format(0)):  # two pages' edges at the corner vertex 0
        PolyMesh(V, F, creases={(0, 3): 2.0, (0, 9): 1.5}, options=chaikin)
    with pytest.raises(MeshError, match=msg.format(1)):  # at the crease vertex
        PolyMesh(V, F, creases={(1, 4): 2.0}, options=chaikin)
    assert not PolyMesh(V, F, creases={(0, 3): 2.0}, options=chaikin).is_manifold  # one fan: supported
    # a closed cone (a tetrahedron) at the corner vertex 0 (infinitely sharp: a corner on every fan); at
    # the crease vertex 1 see test_osd_nonmanifold_fins.py (its fan a corner, the pages creases)
    n = len(V)
    cone = [[1, n, n + 1], [1, n + 1, n + 2], [1, n + 2, n], [n, n + 2, n + 1]]
    cone0 = [[0 if v == 1 else v for v in f] for f in cone]
    m = PolyMesh(np.vstack([V, V[0] + [[0.3, 0.1, 0.1], [0.1, 0.3, 0.1], [0.2, 0.2, 0.4]]]), F + cone0)
    assert m.manifold.is_manifold and (m.manifold_vertex_map == 0).sum() == 5  # four pages and the cone
