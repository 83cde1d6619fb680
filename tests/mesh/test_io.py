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
