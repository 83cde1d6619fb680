"""``ccproof arap --control-out`` on a non-manifold mesh: written in the file's numbering (the split mesh's
copies of a vertex, one per fan, merged), the UVs per face corner."""

from pathlib import Path

import numpy as np

from ccproof.apps.control_file import read_control_mesh
from ccproof.mesh.io import read_obj_polygons

MESHES = Path(__file__).resolve().parents[2] / "data" / "osd_nonmanifold" / "meshes"


def test_control_out_in_file_numbering(tmp_path, capsys):
    from ccproof.cli import main

    src = MESHES / "book4.obj"
    V, polygons, _ = read_obj_polygons(src)
    out = tmp_path / "ctl.obj"
    assert main(["arap", str(src), "--segment", "normals", "--levels", "1", "--eval-level", "3", "--refine", "0",
                 "--control-extra", "0", "--control-out", str(out), "--no-progress"]) == 0
    capsys.readouterr()
    W, wpolys, _ = read_obj_polygons(out)
    # the file's 27 vertices (not the split mesh's 36) and its faces, in its order; positions unchanged
    split, _ = read_control_mesh(src)
    assert (len(V), split.n_vertices) == (27, 36)
    assert wpolys == polygons and np.array_equal(W, V)
    # every face corner has its own texture point (f v/vt)
    faces = [ln.split()[1:] for ln in out.read_text().splitlines() if ln.startswith("f ")]
    assert all(len(c.split("/")) == 2 for f in faces for c in f)
