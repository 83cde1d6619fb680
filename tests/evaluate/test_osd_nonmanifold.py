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
from ccproof.evaluate.tagged import TaggedLimitSurface
from ccproof.mesh import PolyMesh, QuadMesh
from ccproof.mesh.io import read_mesh

MESHES = ["book4.obj", "two_cubes.obj", "bowtie.obj", "dupface.obj", "flipped.obj", "unused.obj", "prism.off"]


def _path(refdir, name):
    return refdir / "osd_nonmanifold" / "meshes" / name


@functools.cache
def _ref(refdir, name):
    stem = name.rsplit(".", 1)[0]
    return json.loads((refdir / "osd_nonmanifold" / f"osd_limit_{stem}.json").read_text())


def _exact(d):
    rows = [s for s in d["samples"] if s["exact"]]
    f, s, t = (np.array([r[k] for r in rows]) for k in ("ptex", "s", "t"))
    return f, s, t, {k: np.array([r[k] for r in rows]) for k in ("P", "Ps", "Pt")}


def _compare(S, d, diag):
    f, s, t, ref = _exact(d)
    assert f.size >= 0.85 * len(d["samples"])  # most samples are on regular patches
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
    assert sorted(map(sorted, d["nonmanifold_edges"])) == mesh.nonmanifold_edges.tolist()
    # its sharpening: infinitely sharp vertices are corners on every split copy, crease vertices are not
    M, vmap = mesh.manifold, mesh.manifold_vertex_map
    for v in osd_nm:
        copies = np.flatnonzero(vmap == v).tolist()
        sharp = [M.vertex_sharpness.get(c, 0.0) for c in copies]
        if d["vertex_sharpness"][v] >= 10:
            assert sharp == [math.inf] * len(copies) and d["vertex_rule"][v] == "corner"
        else:
            assert sharp == [0.0] * len(copies) and d["vertex_rule"][v] == "crease"
    S = limit_surface(mesh)
    assert isinstance(S, TaggedLimitSurface)
    _compare(S, d, mesh.bounding_box_diagonal)


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
    _compare(TaggedLimitSurface(poly), d, diag)
    # vertex limits and normals by input index: NaN at the unused ones, OpenSubdiv's corner values elsewhere
    for T in (S, TaggedLimitSurface(poly)):
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
        pts.write_text("face,u,v\n" + "".join(f"{a},{b!r},{c!r}\n" for a, b, c in zip(f.tolist(), s.tolist(), t.tolist())))
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


def _fan_mesh(k, z, centre):
    """k triangles around ``centre`` (closed fan) with rim vertices offset by ``z``."""
    return [[np.cos(2 * np.pi * i / k), np.sin(2 * np.pi * i / k), z] for i in range(k)]


def test_unsupported_nonmanifold_configurations_are_refused_by_name():
    rng = np.random.default_rng(5)
    # a non-manifold crease vertex (0) with an extra closed cone of faces touching it
    book = [[0, 1, 2], [1, 0, 3], [0, 1, 4]]  # edge (0, 1) in three faces
    book += [[1, 5, 2], [1, 3, 6], [1, 4, 7]]  # nothing else at 0 so far: 0 is a corner
    V = rng.random((14, 3))
    m = PolyMesh(V, book)
    assert not m.is_manifold and m.manifold.vertex_sharpness.get(0) == math.inf
    with pytest.raises(MeshError, match=r"Chaikin creases with a semi-sharp edge at a non-manifold vertex"):
        PolyMesh(V, book, creases={(0, 2): 1.5}, options={"crease_method": "chaikin"})
