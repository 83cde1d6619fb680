"""OBJ input/output keeps face order, vertex order inside faces and polygon sizes."""

import numpy as np
import pytest

from ccproof.errors import MeshError
from ccproof.mesh import QuadMesh, read_obj, read_obj_polygons, write_obj
from ccproof.mesh.examples import k_regular_disk

OBJ = """# comment
mtllib x.mtl
v 0 0 0
v 1 0 0
v 1 1 0 1.0
v 0 1 0
v 2 0 0
v 2 1 0
vt 0 0
vn 0 0 1
g grp
f 2/1/1 5/1/1 6/1/1 3/1/1
f 1//1 2//1 3//1 \\
  4//1
f -4 -1 -3
"""


def test_reader_is_faithful(tmp_path):
    p = tmp_path / "a.obj"
    p.write_text(OBJ)
    V, polys, lines = read_obj_polygons(p)
    assert V.shape == (6, 3)
    assert polys == [[1, 4, 5, 2], [0, 1, 2, 3], [2, 5, 3]]
    assert lines == [12, 13, 15]


def test_non_quad_face_is_named(tmp_path):
    p = tmp_path / "a.obj"
    p.write_text(OBJ)
    with pytest.raises(MeshError, match=r"face 2 \(line 15\) has 3 vertices"):
        read_obj(p)


def test_roundtrip_bitwise(tmp_path):
    m = k_regular_disk(5, rings=2, height=lambda x, y: np.sin(x) * np.exp(y) / 3)
    p = tmp_path / "d.obj"
    write_obj(p, m, comment="test")
    m2 = read_obj(p)
    assert np.array_equal(m2.faces, m.faces)
    assert np.array_equal(m2.vertices, m.vertices)


def test_agrees_with_meshio(refdir):
    import meshio

    for name in ["cube", "sector_k5", "torus_8x6", "bunny_quads"]:
        path = refdir / "meshes" / f"{name}.obj"
        m = read_obj(path)
        mi = meshio.read(path)
        quads = np.concatenate([c.data for c in mi.cells if c.type == "quad"])
        assert np.array_equal(quads, m.faces)
        assert np.array_equal(np.asarray(mi.points, dtype=float), m.vertices)


def test_bad_index(tmp_path):
    p = tmp_path / "a.obj"
    p.write_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 9\n")
    with pytest.raises(MeshError, match="face 0 refers to vertex 9"):
        read_obj(p)


def test_quadmesh_from_polygons_rejects_pentagon():
    with pytest.raises(MeshError, match="face 1 has 5 vertices"):
        QuadMesh.from_polygons(np.zeros((6, 3)), [[0, 1, 2, 3], [0, 1, 2, 3, 4]])


def test_tagged_writers_are_atomic(tmp_path, monkeypatch):
    """write_obj (tags included) and the arap control-mesh writer replace a file only by a complete one: a
    failure while writing leaves the old file and no temporary file; a success leaves the new file only,
    with the usual permissions, and its tags read back."""
    import os

    from ccproof.apps.control_mesh import TaggedQuadMesh
    from ccproof.mesh import write
    from ccproof.mesh.examples import cube
    from ccproof.mesh.io import read_obj_tagged
    from ccproof.mesh.write import write_obj

    c = cube()
    t = TaggedQuadMesh(c.vertices, c.faces, creases=([c.faces[0][:2]], [2.5]), corners=([3], [np.inf]), holes=[5])
    p = tmp_path / "m.obj"
    p.write_text("old\n")
    ref = tmp_path / "ref.txt"
    ref.write_text("x")

    def boom(mesh):
        raise KeyboardInterrupt

    monkeypatch.setattr(write, "obj_tag_lines", boom)
    with pytest.raises(KeyboardInterrupt):
        write_obj(p, t)
    assert p.read_text() == "old\n" and sorted(os.listdir(tmp_path)) == ["m.obj", "ref.txt"]
    monkeypatch.undo()
    write_obj(p, t)
    assert sorted(os.listdir(tmp_path)) == ["m.obj", "ref.txt"]
    assert os.stat(p).st_mode & 0o777 == os.stat(ref).st_mode & 0o777
    back = read_obj_tagged(p)
    assert back.edge_sharpness == {tuple(sorted(c.faces[0][:2].tolist())): 2.5}
    assert list(back.vertex_sharpness) == [3] and back.vertex_sharpness[3] >= 10  # infinitely sharp
    assert back.is_hole_tagged.tolist() == [False] * 5 + [True]

    from ccproof.apps.arap import io as arap_io
    from ccproof.apps.arap.meshes import LevelPlan, compare
    from ccproof.mesh.examples import grid

    res, _ = compare(grid(3, 3), methods=("c",), plan=LevelPlan(levels=1, eval_level=3))
    q = tmp_path / "uv.obj"
    q.write_text("old uv\n")
    monkeypatch.setattr(write, "obj_tag_lines", boom)
    with pytest.raises(KeyboardInterrupt):
        arap_io.write_uv_obj(q, grid(3, 3), res["c"])
    assert q.read_text() == "old uv\n" and sorted(os.listdir(tmp_path)) == ["m.obj", "ref.txt", "uv.obj"]
