"""``arap --out`` judges its UVs before writing them. The creased cube at an explicit ``--refine 0`` folds
UV triangles (it used to write 22 of 768 folded with exit 0): the run refuses with exit 1, one line with the
count and the options that fix it, and leaves no file; ``--allow-folds`` writes them with a warning; the
default refinement writes none folded. Counts are checked against the written file itself (signed UV areas of
its ``f v/vt`` triangles), never against the code's own count."""

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


def _base(refdir, out):
    mesh = refdir / "osd_features" / "meshes" / "catmark_cube_creases0.obj"
    return ["arap", str(mesh), "--segment", "normals", "--levels", "1", "--eval-level", "2", "--out", str(out)]


def test_explicit_refine_that_folds_is_refused_and_writes_nothing(refdir, tmp_path, capsys):
    out = tmp_path / "uv.obj"
    assert main(_base(refdir, out) + ["--refine", "0"]) == 1
    err = capsys.readouterr().err
    lines = [ln for ln in err.splitlines() if "refused" in ln]
    assert len(lines) == 1, err
    hit = re.search(r"refused: --out .*uv\.obj: (\d+) of 768 triangles are folded in UV at --refine 0", lines[0])
    assert hit and int(hit.group(1)) > 0, err
    assert "--allow-folds" in lines[0] and "higher --refine" in lines[0]
    assert sorted(p.name for p in tmp_path.iterdir()) == []  # neither uv.obj, nor its sidecar, nor a temporary


def test_allow_folds_writes_them_and_warns_with_the_figure(refdir, tmp_path, capsys):
    out = tmp_path / "uv.obj"
    assert main(_base(refdir, out) + ["--refine", "0", "--allow-folds"]) == 0
    err = capsys.readouterr().err
    folded, total = _folded_in_file(out)
    assert folded > 0
    hit = re.search(r"warning: --out .*uv\.obj: (\d+) of (\d+) triangles are folded in UV", err)
    assert hit and (int(hit.group(1)), int(hit.group(2))) == (folded, total), err
    assert "--refine 0 was given: raise it" in err


def test_default_refinement_writes_no_fold(refdir, tmp_path, capsys):
    out = tmp_path / "uv.obj"
    assert main(_base(refdir, out)) == 0
    err = capsys.readouterr().err
    assert "warning" not in err and "refused" not in err
    folded, total = _folded_in_file(out)
    assert folded == 0 and total == 768


def test_default_refine_that_folds_is_refined_until_none_fold(refdir, tmp_path, capsys, monkeypatch):
    """The default --refine (here made to pick 0, which folds) is raised until the written UVs do not fold."""
    import ccproof.apps.arap.meshes as meshes

    monkeypatch.setattr(meshes, "auto_refine", lambda mesh, labels: 0)
    out = tmp_path / "uv.obj"
    assert main(_base(refdir, out)) == 0
    err = capsys.readouterr().err
    hit = re.search(r"--out .*uv\.obj: (\d+) of 768 triangles folded in UV at refine 0; chosen refine (\d)", err)
    assert hit and int(hit.group(1)) > 0 and int(hit.group(2)) >= 1, err
    assert _folded_in_file(out) == (0, 768)
