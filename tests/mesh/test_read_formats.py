"""One reader for every format (ccproof.mesh.io.read_mesh): OBJ, our OFF reader, meshio's formats, and
every failure a MeshError naming the file and the reason (meshio's own prints and sys.exit caught)."""

import numpy as np
import pytest

from ccproof.errors import CCProofError, MeshError
from ccproof.mesh.io import read_mesh, read_off_polygons

PYRAMID_V = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0.5, 0.5, 1]]
PYRAMID_F = [[0, 3, 2, 1], [0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]]


def _ply(header_case=str.lower):
    head = ["ply", "format ascii 1.0", "element vertex 5", "property float x", "property float y",
            "property float z", "element face 5", "property list uchar int vertex_indices", "end_header"]
    body = [" ".join(map(str, v)) for v in PYRAMID_V] + [f"{len(f)} " + " ".join(map(str, f)) for f in PYRAMID_F]
    return "\n".join([header_case(h) for h in head] + body) + "\n"


def _off(keyword="OFF"):
    body = [" ".join(map(str, v)) for v in PYRAMID_V] + [f"{len(f)} " + " ".join(map(str, f)) for f in PYRAMID_F]
    return "\n".join([keyword, "# a square pyramid", "5 5 8"] + body) + "\n"


def test_every_format_gives_the_same_mesh(tmp_path):
    meshio = pytest.importorskip("meshio")
    (tmp_path / "p.ply").write_text(_ply())
    (tmp_path / "p.off").write_text(_off())
    (tmp_path / "p.obj").write_text("".join(f"v {x} {y} {z}\n" for x, y, z in PYRAMID_V)
                                    + "".join("f " + " ".join(str(i + 1) for i in f) + "\n" for f in PYRAMID_F))
    V = np.array(PYRAMID_V, float)
    meshio.write_points_cells(str(tmp_path / "p.vtk"), V, [("quad", np.array(PYRAMID_F[:1])),
                                                          ("triangle", np.array(PYRAMID_F[1:]))])
    for name in ("p.ply", "p.off", "p.obj", "p.vtk"):
        m = read_mesh(tmp_path / name)
        assert [list(p) for p in m.polygons] == PYRAMID_F, name
        assert np.array_equal(m.vertices, V), name
    # STL (triangles only; meshio merges the repeated corners)
    meshio.write_points_cells(str(tmp_path / "t.stl"), V, [("triangle", np.array(PYRAMID_F[1:]))], binary=True)
    assert read_mesh(tmp_path / "t.stl").n_faces == 4


def test_off_variants_and_counts_on_the_keyword_line(tmp_path):
    p = tmp_path / "c.off"
    # COFF: colours after the coordinates and after the face indices; counts on the keyword line
    lines = ["COFF 5 5 0"] + [" ".join(map(str, v)) + " 255 0 0 255" for v in PYRAMID_V]
    lines += [f"{len(f)} " + " ".join(map(str, f)) + " 0.5 0.5 0.5" for f in PYRAMID_F]
    p.write_text("\n".join(lines) + "\n")
    V, polys, rows = read_off_polygons(p)
    assert polys == PYRAMID_F and np.array_equal(V, np.array(PYRAMID_V, float)) and rows == [7, 8, 9, 10, 11]
    p.write_text("5 5 0\n" + _off().split("5 5 8\n", 1)[1])  # no keyword line at all
    assert read_mesh(p).n_faces == 5


@pytest.mark.parametrize("name,text,msg", [
    ("u.ply", _ply(str.upper), r"u\.ply: not a valid PLY file: the header is upper case \('PLY'\)"),
    ("x.ply", "solid x\n", r"x\.ply: not a PLY file: it does not start with the line 'ply'"),
    ("t.ply", _ply().replace("3 3 0 4\n", ""), r"t\.ply: not a valid PLY file: "),
    ("b.off", "OFF BINARY\n1 1 0\n", r"b\.off:1: binary OFF is not supported"),
    ("n.off", "4OFF\n1 1 0\n", r"n\.off:1: OFF variant '4OFF' is not supported"),
    ("s.off", "OFF\n5 5 0\n0 0 0\n", r"s\.off: the header announces 5 vertices and 5 faces, the file has 1 data lines"),
    ("i.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", r"i\.off:6: face 0 refers to vertex 3 of 3"),
    ("k.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n4 0 1 2\n", r"k\.off:6: face 0 announces 4 vertices, has 3"),
    ("c.off", "OFF\nthree 1 0\n", r"c\.off:2: expected the counts"),
    ("v.off", "OFF\n3 1 0\n0 0 x\n1 0 0\n0 1 0\n3 0 1 2\n", r"v\.off:3: bad vertex coordinate"),
    ("q.xyz", "1 2 3\n", r"q\.xyz: unknown mesh format '\.xyz'"),
    ("e.off", "OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n", r"e\.off: the mesh has no faces"),
    ("f.off", "OFF\n4 1 0\n0 0 0\n1 0 0\n0 1 0\nnan 0 0\n3 0 1 3\n", r"f\.off: vertex 3 has a non-finite coordinate"),
])
def test_unreadable_files_name_the_file_and_the_reason(tmp_path, capsys, name, text, msg):
    p = tmp_path / name
    p.write_text(text)
    with pytest.raises(MeshError, match=msg) as err:
        read_mesh(p)
    assert isinstance(err.value, CCProofError) and str(p) in str(err.value)
    assert capsys.readouterr() == ("", "")  # nothing printed (meshio prints before it exits)


@pytest.mark.parametrize("name,data,msg", [
    ("zero.stl", b"", r"zero\.stl: (the file has no vertices|not a valid STL file)"),
    ("ascii.stl", b"solid empty\nendsolid empty\n", r"ascii\.stl: the file has no vertices \(an empty mesh\)"),
    ("solid.stl", b"solid\n", r"solid\.stl: the file has no vertices \(an empty mesh\)"),
    ("bin0.stl", b"\0" * 80 + (0).to_bytes(4, "little"), r"bin0\.stl: the file has no vertices \(an empty mesh\)"),
    ("hdr.stl", b"\0" * 80, r"hdr\.stl: not a valid STL file"),
    ("short.stl", b"\0" * 80 + (1).to_bytes(4, "little"), r"short\.stl: the file has no vertices"),
])
def test_empty_stl_is_a_mesh_error_naming_the_file(tmp_path, capsys, name, data, msg):
    p = tmp_path / name
    p.write_bytes(data)
    with pytest.raises(MeshError, match=msg) as err:
        read_mesh(p)
    assert str(p) in str(err.value)
    assert capsys.readouterr() == ("", "")


def test_missing_file_and_folder(tmp_path):
    with pytest.raises(MeshError, match=r"nope\.obj: no such file"):
        read_mesh(tmp_path / "nope.obj")
    with pytest.raises(MeshError, match=r"is a folder, not a mesh file"):
        read_mesh(tmp_path)


def test_unused_vertices_of_a_scan_keep_their_indices(tmp_path):
    """A PLY scan with vertices no face uses (NaN coordinates on one): accepted, indices unchanged."""
    text = _ply().replace("element vertex 5", "element vertex 7")
    text = text.replace("0.5 0.5 1\n", "0.5 0.5 1\nnan nan nan\n9 9 9\n")
    (tmp_path / "s.ply").write_text(text)
    m = read_mesh(tmp_path / "s.ply")
    assert m.n_vertices == 7 and m.is_unused_vertex.tolist() == [False] * 5 + [True, True]
    assert [list(p) for p in m.polygons] == PYRAMID_F
