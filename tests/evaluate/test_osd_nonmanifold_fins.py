"""Non-manifold crease vertices with fans that do not span both non-manifold edges, against OpenSubdiv 3.5.

tests/data/osd_nonmanifold (README there): a spine of two edges (vertices 0, 1, 2), pages (fans at vertex 1
bounded by both spine edges) and fins (fans that leave a spine edge and come back to it). OpenSubdiv
gives vertex 1 the crease rule along the spine, 3/4 v + 1/8 (a + b) with a, b the spine's ends, on every
fan; a fin's copy in our split sees one spine end only, so it is made a corner (the vertex stays put).
Checked here: OpenSubdiv's own points say what its rule is (closed form); ours equal its refined points
bit for bit on every copy but the fins' (where ours stay at v: the documented difference, its size
measured); its regular patches away from the fins to 1e-12; the limit point of every fan in closed form;
every command accepts the meshes.
"""

import functools
import json

import numpy as np
import pytest

from ccproof.cli import main
from ccproof.evaluate import limit_surface
from ccproof.mesh import PolyMesh, nonmanifold
from ccproof.mesh.io import read_mesh

#: mesh -> the faces of its fins (make_meshes.py: the pages' faces come first, then the fins')
FINS = {"fin.obj": range(4, 10), "fins_only.obj": range(0, 12), "fin_tri.obj": range(24, 30)}


def _path(refdir, name):
    return refdir / "osd_nonmanifold" / "meshes" / name


@functools.cache
def _ref(refdir, name):
    return json.loads((refdir / "osd_nonmanifold" / f"osd_limit_{name.rsplit('.', 1)[0]}.json").read_text())


def _fin_copies(mesh, name):
    """Copies of vertex 1 in the split mesh whose faces are fin faces (by construction, not by our split)."""
    M, vmap = mesh.manifold, mesh.manifold_vertex_map
    out = set()
    for f in FINS[name]:
        out |= {u for u in M.polygons[f] if vmap[u] == 1}
    return sorted(out)


@pytest.mark.parametrize("name", sorted(FINS))
def test_opensubdiv_rule_and_our_split(refdir, name):
    d = _ref(refdir, name)
    mesh = read_mesh(_path(refdir, name))
    assert mesh.n_vertices == d["num_vertices"] and mesh.n_faces == d["num_faces"]
    assert np.flatnonzero(mesh.is_nonmanifold_vertex).tolist() == d["nonmanifold_vertices"] == [0, 1, 2]
    assert sorted(map(sorted, d["nonmanifold_edges"])) == [[0, 1], [1, 2]]
    assert d["vertex_rule"][1] == "crease" and d["vertex_sharpness"][1] == 0  # not sharpened by OpenSubdiv
    V = mesh.vertices
    crease = 0.75 * V[1] + 0.125 * (V[0] + V[2])  # Sdc's crease mask along the spine
    assert np.abs(np.array(d["vertex_points"][0][1]) - crease).max() <= 1e-15
    M, vmap = mesh.manifold, mesh.manifold_vertex_map
    fins = _fin_copies(mesh, name)
    assert len(fins) == {"fin.obj": 2, "fins_only.obj": 4, "fin_tri.obj": 1}[name]
    assert set(fins) <= set(np.flatnonzero(vmap == 1).tolist())
    for u in np.flatnonzero(vmap == 1).tolist():
        assert M.vertex_sharpness.get(u, 0.0) == (np.inf if u in fins else 0.0), u


@pytest.mark.parametrize("name", sorted(FINS))
def test_refined_points_are_opensubdivs_but_at_the_fins(refdir, name):
    """Two uniform steps: OpenSubdiv's PrimvarRefiner against our refine, every vertex point of every copy,
    and every level-1 edge point; the fins' copies of vertex 1 stay at v (a corner) where OpenSubdiv's move."""
    d = _ref(refdir, name)
    mesh = read_mesh(_path(refdir, name))
    diag = mesh.bounding_box_diagonal
    M, vmap = mesh.manifold, mesh.manifold_vertex_map
    R1, _ = mesh.refine(operator=False)
    R2, _ = R1.refine(operator=False)
    fins = _fin_copies(mesh, name)
    others = np.setdiff1d(np.arange(M.n_vertices), fins)
    for R, osd in ((R1, d["vertex_points"][0]), (R2, d["vertex_points"][1])):
        ref = np.array(osd)[vmap]
        assert np.abs(R.vertices[others] - ref[others]).max() <= 1e-15 * diag
        assert (R.vertices[fins] == mesh.vertices[1]).all()  # a corner
        gap = np.abs(R.vertices[fins] - ref[fins]).max() / diag  # what the corner costs (README)
        assert 1e-3 < gap < 1e-2
    E = np.array(d["edge_points"])  # each of OpenSubdiv's edge points is one of ours, bit-close
    dist = np.abs(E[:, None, :] - R1.vertices[None, M.n_vertices:, :]).max(axis=2).min(axis=1)
    assert dist.max() <= 1e-15 * diag


@pytest.mark.parametrize("name", sorted(FINS))
def test_limit_surface_matches_opensubdiv_off_the_fins(refdir, name):
    """Where OpenSubdiv's patch is regular and no control point is a fin's copy (faces outside the
    two-ring of the fin faces at vertex 1), our limit surface is OpenSubdiv's to round-off."""
    d = _ref(refdir, name)
    mesh = read_mesh(_path(refdir, name))
    diag = mesh.bounding_box_diagonal
    M = mesh.manifold
    fins = set(_fin_copies(mesh, name))
    ring1 = {v for p in M.polygons if fins & set(p) for v in p}
    near = {f for f, p in enumerate(M.polygons) if ring1 & set(p)}
    rows = [s for s in d["samples"] if s["exact"] and mesh.face_of_ptex(s["ptex"])[0] not in near]
    assert len(rows) == {"fin.obj": 142, "fins_only.obj": 0, "fin_tri.obj": 2313}[name]
    S = limit_surface(mesh)
    if rows:
        out = S.evaluate([r["ptex"] for r in rows], [r["s"] for r in rows], [r["t"] for r in rows], 1)
        for key, rk, tol in (("P", "P", 1e-12), ("Pu", "Ps", 1e-10), ("Pv", "Pt", 1e-10)):
            assert np.abs(out[key] - [r[rk] for r in rows]).max() <= tol * diag, key
    # the limit point of vertex 1 on every face there, closed form: (a + 4 v + b) / 6 on a page (the
    # crease curve), v on a fin (a corner); OpenSubdiv's crease limit on every fan
    V = mesh.vertices
    crease = (V[0] + 4 * V[1] + V[2]) / 6
    for f in range(mesh.n_faces):
        p = mesh.polygons[f]
        if 1 not in p:
            continue
        k = p.index(1)
        ptex, st = (mesh.ptex_of(f, k), (0.0, 0.0)) if len(p) != 4 else (mesh.ptex_of(f), [(0, 0), (1, 0), (1, 1),
                                                                                           (0, 1)][k])
        P = S.evaluate([ptex], [float(st[0])], [float(st[1])], 0)["P"][0]
        want = V[1] if f in FINS[name] else crease
        assert np.abs(P - want).max() <= 1e-14 * diag, f


def test_a_closed_fan_at_a_crease_vertex_is_a_corner(refdir):
    """A closed cone touching book4's crease vertex: a fan bounded by no spine edge, made a corner; the
    pages keep the crease rule (their refined vertex point, the closed form along the spine)."""
    book = read_mesh(refdir / "osd_nonmanifold" / "meshes" / "book4.obj")
    V, F = np.array(book.vertices), [list(p) for p in book.polygons]
    n = len(V)
    V2 = np.vstack([V, V[1] + [[0.3, 0.1, 0.1], [0.1, 0.3, 0.1], [0.2, 0.2, 0.4]]])
    cone = [[1, n, n + 1], [1, n + 1, n + 2], [1, n + 2, n], [n, n + 2, n + 1]]
    m = PolyMesh(V2, F + cone)
    M, vmap = m.manifold, m.manifold_vertex_map
    cone_copy = M.polygons[len(F)][0]
    assert vmap[cone_copy] == 1 and M.vertex_sharpness[cone_copy] == np.inf
    pages = [u for u in np.flatnonzero(vmap == 1).tolist() if u != cone_copy]
    assert len(pages) == 4 and all(M.vertex_sharpness.get(u, 0.0) == 0.0 for u in pages)
    R, _ = m.refine(operator=False)
    assert (R.vertices[cone_copy] == V[1]).all()
    assert np.abs(R.vertices[pages] - (0.75 * V[1] + 0.125 * (V[0] + V[2]))).max() <= 1e-15


def test_a_closed_surface_on_a_spine_edge_is_a_fin(refdir):
    """A tetrahedron on book4's spine edge (0, 1): at vertex 1 its faces form a fin (from the spine edge
    back to it); at vertex 0 they form one fan, so the fin's two sides meet again in the split, whose
    edge there is manifold and infinitely sharp. The fin's copy is a corner, the pages' keep the crease
    rule; the split is manifold and evaluates (its face points' limits, brute force)."""
    book = read_mesh(refdir / "osd_nonmanifold" / "meshes" / "book4.obj")
    V, F = np.array(book.vertices), [list(p) for p in book.polygons]
    p, q = len(V), len(V) + 1
    m = PolyMesh(np.vstack([V, [[0.4, 0.3, 0.5], [0.3, 0.6, 0.4]]]),
                 F + [[0, 1, p], [1, 0, q], [0, p, q], [1, q, p]])
    M, vmap = m.manifold, m.manifold_vertex_map
    assert M.is_manifold
    fin = M.polygons[len(F)][1]
    assert vmap[fin] == 1 and M.vertex_sharpness[fin] == np.inf
    assert [M.vertex_sharpness.get(u, 0.0) for u in np.flatnonzero(vmap == 1) if u != fin] == [0.0] * 4
    e = M.halfedges.edge_index_of([M.polygons[len(F)][0]], [fin])[0]
    assert M.edge_face_count[e] == 2 and M.edge_sharpness[tuple(M.edges[e].tolist())] == np.inf
    R, _ = m.refine(operator=False)
    S = limit_surface(m)
    for f in range(len(F), len(F) + 4):
        P = S.evaluate([m.ptex_of(f, 0)], [1.0], [1.0], 0)["P"][0]
        want = _limit_of_smooth_vertex(R, M.n_vertices + len(M.edges) + f)
        assert np.abs(P - want).max() <= 1e-14 * m.bounding_box_diagonal


@pytest.mark.parametrize("command", ["eval", "project", "fit", "arap"])
def test_every_command_accepts_a_fin(refdir, tmp_path, command):
    name = "fin_tri.obj"
    path = str(_path(refdir, name))
    mesh = read_mesh(path)
    out = tmp_path / "o.npz"
    if command == "eval":  # on OpenSubdiv's regular samples off the fins
        near = {f for f in range(mesh.n_faces) if set(mesh.polygons[f]) & {1, 0}}
        rows = [s for s in _ref(refdir, name)["samples"] if s["exact"]
                and mesh.face_of_ptex(s["ptex"])[0] not in near][:50]
        pts = tmp_path / "p.csv"
        pts.write_text("face,u,v\n" + "".join(f"{r['ptex']},{r['s']!r},{r['t']!r}\n" for r in rows))
        assert main(["eval", path, "--points", str(pts), "--out", str(out)]) == 0
        assert np.abs(np.load(out)["P"] - [r["P"] for r in rows]).max() <= 1e-12 * mesh.bounding_box_diagonal
        return
    S = limit_surface(mesh)
    rng = np.random.default_rng(3)
    f = rng.integers(0, mesh.n_ptex, 200)
    on = S.evaluate(f, rng.uniform(0.1, 0.9, 200), rng.uniform(0.1, 0.9, 200), 1)
    if command == "project":  # points off the surface by 1e-3 along the normal, on a page and on the fin
        nrm = np.cross(on["Pu"], on["Pv"])[:2]
        X = on["P"][:2] + 1e-3 * nrm / np.linalg.norm(nrm, axis=1)[:, None]
        csv = tmp_path / "x.csv"
        csv.write_text("x,y,z\n" + "".join(f"{a!r},{b!r},{c!r}\n" for a, b, c in X.tolist()))
        assert main(["project", path, str(csv), "--out", str(out)]) == 0
        assert np.abs(np.load(out)["distance"] - 1e-3).max() <= 1e-9
    elif command == "fit":
        xyz = tmp_path / "s.xyz"
        np.savetxt(xyz, on["P"])
        assert main(["fit", str(xyz), "--init", path, "--levels", "0", "--max-steps", "2",
                     "--out", str(tmp_path / "f.obj"), "--no-progress"]) == 0
        assert (tmp_path / "f.obj").stat().st_size > 0
    else:
        assert main(["arap", path, "--segment", "normals", "--levels", "1", "--eval-level", "2", "--refine", "0",
                     "--out", str(tmp_path / "uv.obj"), "--no-progress"]) == 0
        assert (tmp_path / "uv.obj").stat().st_size > 0


def _limit_of_smooth_vertex(R, c):
    """Catmull-Clark limit position of the smooth interior vertex c of the all-quad mesh R, from its
    one-ring alone: (n^2 v + 4 sum(edge neighbours) + sum(diagonal ones)) / (n (n + 5))."""
    quads = [p for p in R.polygons if c in p]
    n = len(quads)
    e = sum(R.vertices[q[(q.index(c) + 1) % 4]] for q in quads)  # each edge neighbour once (interior)
    f = sum(R.vertices[q[(q.index(c) + 2) % 4]] for q in quads)
    return (n * n * R.vertices[c] + 4 * e + f) / (n * (n + 5))


@pytest.mark.parametrize("name", sorted(FINS))
def test_fins_and_pages_are_the_limit_of_our_refinement(refdir, name):
    """Brute force, independent of the evaluator: one step of our refinement, then the closed-form limit
    of each face point (a smooth interior vertex: its one-ring decides it) against the evaluated surface
    at that parameter, on every face, fins included (the surface there is the corner's)."""
    mesh = read_mesh(_path(refdir, name))
    M = mesh.manifold
    R, _ = mesh.refine(operator=False)
    S = limit_surface(mesh)
    first_face_point = M.n_vertices + len(M.edges)
    for f in range(mesh.n_faces):
        want = _limit_of_smooth_vertex(R, first_face_point + f)
        ptex, st = (mesh.ptex_of(f), (0.5, 0.5)) if mesh.sizes[f] == 4 else (mesh.ptex_of(f, 0), (1.0, 1.0))
        P = S.evaluate([ptex], [st[0]], [st[1]], 0)["P"][0]
        assert np.abs(P - want).max() <= 1e-14 * mesh.bounding_box_diagonal, f


def test_manifold_meshes_never_take_the_split(refdir, monkeypatch):
    """A manifold mesh is its own evaluated mesh: the split (and its handling of fins) is never called."""
    def refuse(self, *args):
        raise AssertionError("the split was called on a manifold mesh")

    monkeypatch.setattr(PolyMesh, "_split_nonmanifold", refuse)
    monkeypatch.setattr(nonmanifold, "fans_off_the_crease", refuse)
    for name in ("unused.obj", "prism.off"):
        m = read_mesh(_path(refdir, name))
        assert m.is_manifold and m.manifold is m
        limit_surface(m).evaluate([0], [0.5], [0.5], 1)


def test_a_fin_made_a_corner_is_said_and_a_mesh_of_pages_says_nothing(refdir, recwarn):
    """The fin's copy is not OpenSubdiv's surface: the split says so once, naming the vertices; book4 (pages
    only: every fan bounded by both non-manifold edges) is OpenSubdiv's surface and warns nothing."""
    limit_surface(read_mesh(refdir / "osd_nonmanifold" / "meshes" / "book4.obj"))
    assert not [w for w in recwarn if "fin" in str(w.message)]
    with pytest.warns(UserWarning, match=r"non-manifold crease vertices \[\d+.*a fin\) is made a sharp corner"):
        limit_surface(read_mesh(_path(refdir, "fin.obj")))
