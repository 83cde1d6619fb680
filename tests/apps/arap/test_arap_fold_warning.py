"""``arap --out`` with folded UV triangles says so on stderr with the figure (it used to exit 0 without a word:
the creased cube at an explicit ``--refine 0`` writes 22 of 768 triangles folded). The count is checked
against the written file itself (signed UV areas of its ``f v/vt`` triangles), and the default refinement,
which has no fold there, warns about nothing."""

import re

import numpy as np

from ccproof.cli import main


def _folded_in_file(path):
    vt, tris = [], []
    for line in path.read_text().splitlines():
        s = line.split()
        if s and s[0] == "vt":
            vt.append([float(x) for x in s[1:3]])
        elif s and s[0] == "f":
            tris.append([int(t.split("/")[1]) - 1 for t in s[1:]])
    uv, t = np.array(vt), np.array(tris)
    a, b, c = uv[t[:, 0]], uv[t[:, 1]], uv[t[:, 2]]
    area = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    return int((area <= 0).sum()), len(t)


def test_folded_uv_triangles_are_reported(refdir, tmp_path, capsys):
    mesh = refdir / "osd_features" / "meshes" / "catmark_cube_creases0.obj"
    out = tmp_path / "uv.obj"
    base = ["arap", str(mesh), "--segment", "normals", "--levels", "1", "--eval-level", "2", "--out", str(out)]
    assert main(base + ["--refine", "0"]) == 0
    err = capsys.readouterr().err
    folded, total = _folded_in_file(out)
    assert folded > 0
    hit = re.search(r"warning: --out .*uv\.obj: (\d+) of (\d+) triangles are folded in UV", err)
    assert hit and (int(hit.group(1)), int(hit.group(2))) == (folded, total), err
    assert "--refine 0 was given: raise it" in err
    assert main(base) == 0  # the default refinement: no fold, no warning
    assert "warning" not in capsys.readouterr().err and _folded_in_file(out)[0] == 0
