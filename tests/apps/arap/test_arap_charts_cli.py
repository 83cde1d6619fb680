"""Bad input gives clear errors; chart segmentations give disks; the command line end to end."""

import importlib.util
import json
import pathlib

import numpy as np
import pytest

from ccproof.apps.arap.charts import (
    ChartError,
    charts_from_labels,
    check_disk,
    grow_patch,
    read_labels,
    segment_by_normals,
    write_labels,
)
from ccproof.cli import main
from ccproof.errors import CCProofError, MeshError
from ccproof.mesh import read_obj, write_obj
from ccproof.mesh.examples import cube, grid, torus

_spec = importlib.util.spec_from_file_location("arap_meshes", pathlib.Path(__file__).with_name("_arap_meshes.py"))
M = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(M)


def test_non_disk_charts_are_rejected_with_the_reason():
    g = grid(4, 4)
    with pytest.raises(ChartError, match="chart 0 is not a topological disk: it has 2 connected components"):
        charts_from_labels(g, [0 if f in (0, 15) else 1 for f in range(16)])
    with pytest.raises(ChartError, match=r"chart 1 is not a topological disk: Euler .* 2 boundary loops"):
        charts_from_labels(g, [0 if f in (5, 6, 9, 10) else 1 for f in range(16)])  # an annulus
    with pytest.raises(ChartError, match="non-manifold vertex"):
        check_disk(g, [0, 5], "two faces touching at a vertex")
    with pytest.raises(ChartError, match="Euler characteristic V - E \\+ F = 2"):
        check_disk(cube(), range(6), "the cube")
    with pytest.raises(ChartError, match="Euler characteristic V - E \\+ F = 0"):
        check_disk(torus(4, 4), range(16), "the torus")
    assert [c.tolist() for c in charts_from_labels(g, [-1] * 15 + [3])] == [[15]]


def test_label_files(tmp_path):
    p = tmp_path / "labels.txt"
    p.write_text("0 0\n1 # comment\n1\n")
    assert read_labels(p).tolist() == [0, 0, 1, 1]
    with pytest.raises(ChartError, match="4 chart labels for a mesh of 5 faces"):
        read_labels(p, 5)
    p.write_text("0 x 1\n")
    with pytest.raises(ChartError, match="'x' is not an integer"):
        read_labels(p)
    write_labels(p, [2, 0, 1])
    assert read_labels(p, 3).tolist() == [2, 0, 1]
    with pytest.raises(ChartError, match="got 3 labels for a mesh of 16 faces"):
        charts_from_labels(grid(4, 4), [0, 0, 0])


def test_segmentations_give_disks(bunny_path):
    m = read_obj(bunny_path)
    lab = segment_by_normals(m)
    charts = charts_from_labels(m, lab)  # raises unless every chart is a disk
    assert 5 <= len(charts) <= 40 and sum(c.size for c in charts) == m.n_faces
    patch = grow_patch(m, 1000, 8)
    check_disk(m, patch)
    assert 100 < patch.size < m.n_faces // 2


def _write_case(tmp_path):
    m, chart = M.curved_ev_mesh()
    mp = tmp_path / "ev5.obj"
    write_obj(mp, m)
    lab = -np.ones(m.n_faces, dtype=int)
    lab[chart] = 0
    lp = tmp_path / "ev5.labels"
    write_labels(lp, lab)
    return m, chart, mp, lp


def test_cli_end_to_end(tmp_path, capsys):
    m, chart, mp, lp = _write_case(tmp_path)
    out = tmp_path / "uv.obj"
    rc = main(["arap", str(mp), "--charts", str(lp), "--baselines", "--engine", "numpy", "--levels", "2",
               "--refine", "0", "--control-out", str(out)])
    text = capsys.readouterr().out
    assert rc == 0
    for name in ("(a) ARAP on control mesh", "(b) ours, boundary rules", "(c) ours, extended charts",
                 "(d) ARAP on control mesh x3", "E_angle", "E_area", "E_stretch", "flips", "seconds"):
        assert name in text
    lines = out.read_text().splitlines()
    side = json.loads((tmp_path / "uv.obj.json").read_text())
    ch = side["charts"][0]
    # control UVs for the face-varying corners-only rule: chart vertices only, on the control mesh subdivided
    # as many extra times as the file says
    assert ch["rules"] == "boundary" and len(ch["uv"]) == ch["n_chart_vertices"]
    vt = [tuple(map(float, ln.split()[1:])) for ln in lines if ln.startswith("vt ")]
    assert len(vt) == len(ch["uv"])
    q = 4 ** side["table"]["control_out"]["extra_subdivisions"]
    fts = [ln for ln in lines if ln.startswith("f ")]
    assert sum("/" in ln for ln in fts) == q * len(chart) and len(fts) == q * m.n_faces
    assert side["table"]["c"]["E_area"] < side["table"]["a"]["E_area"]


def test_cli_errors(tmp_path, capsys):
    m, chart, mp, lp = _write_case(tmp_path)
    bad = tmp_path / "bad.labels"
    write_labels(bad, [0] * (m.n_faces - 1))
    assert main(["arap", str(mp), "--charts", str(bad)]) == 2
    assert "labels for a mesh of 80 faces" in capsys.readouterr().err
    annulus = tmp_path / "annulus.labels"
    write_labels(annulus, [0 if f in chart else 1 for f in range(m.n_faces)])
    assert main(["arap", str(mp), "--charts", str(annulus)]) == 2
    assert "chart 1 is not a topological disk" in capsys.readouterr().err
    tri = tmp_path / "tri.obj"
    tri.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 4 3\nf 1 2 3\n")
    # arap reads triangles (one Catmull-Clark step, test_arap_control_fvar.py); read_obj stays all-quad
    write_obj(tmp_path / "cube.obj", cube())
    assert main(["arap", str(tmp_path / "cube.obj")]) == 2
    assert "give --charts" in capsys.readouterr().err
    with pytest.raises(MeshError):
        read_obj(tri)
    assert issubclass(ChartError, CCProofError)
