"""The ``ccproof eval`` subcommand."""

import numpy as np
import pytest

from ccproof.cli import main
from ccproof.evaluate import limit_surface
from ccproof.mesh import write_obj
from ccproof.mesh.examples import k_regular_disk


@pytest.fixture()
def disk(tmp_path):
    m = k_regular_disk(5, 2, height=lambda x, y: 0.2 * x * y)
    p = tmp_path / "disk5.obj"
    write_obj(p, m)
    return m, p


def test_points_csv(tmp_path, disk, capsys):
    m, obj = disk
    csv = tmp_path / "pts.csv"
    csv.write_text("face,u,v\n0,0.5,0.25\n3,0,1\n7,1e-9,0.3\n")
    out = tmp_path / "r.npz"
    assert main(["eval", str(obj), "--points", str(csv), "--derivatives", "2", "--out", str(out)]) == 0
    d = np.load(out)
    assert set(d.files) == {"face", "u", "v", "P", "Pu", "Pv", "Puu", "Puv", "Pvv"}
    want = limit_surface(m).evaluate([0, 3, 7], [0.5, 0, 1e-9], [0.25, 1, 0.3], 2)
    for k in want:
        assert np.array_equal(d[k], want[k])
    assert d["face"].tolist() == [0, 3, 7]
    assert "evaluated 3 points" in capsys.readouterr().out


def test_samples_and_plot(tmp_path, disk):
    _, obj = disk
    out, png = tmp_path / "r.npz", tmp_path / "iso.png"
    argv = ["eval", str(obj), "--samples", "500", "--derivatives", "0", "--out", str(out), "--plot", str(png)]
    assert main(argv) == 0
    d = np.load(out)
    assert d["P"].shape == (500, 3) and "Pu" not in d.files
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 10_000


def test_errors_are_reported(tmp_path, disk, capsys):
    _, obj = disk
    csv = tmp_path / "bad.csv"
    csv.write_text("f,u,v\n0,0.5,0.5\n")
    assert main(["eval", str(obj), "--points", str(csv), "--out", str(tmp_path / "x.npz")]) == 2
    assert "header 'face,u,v'" in capsys.readouterr().err
    csv.write_text("face,u,v\n0,0.5,0.5\n99,0.5,0.5\n")
    assert main(["eval", str(obj), "--points", str(csv), "--out", str(tmp_path / "x.npz")]) == 2
    assert "point 1: face id 99 out of range" in capsys.readouterr().err
    csv.write_text("face,u,v\n0,1.5,0.5\n")
    assert main(["eval", str(obj), "--points", str(csv), "--out", str(tmp_path / "x.npz")]) == 2
    assert "u = 1.5 is outside [0, 1]" in capsys.readouterr().err
    tri = tmp_path / "tri.obj"
    tri.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nt crease 2/1/0 0 1 -1\n")
    argv = ["eval", str(tri), "--samples", "3", "--out", str(tmp_path / "x.npz"), "--parameterization", "vanishing"]
    assert main(argv) == 2
    assert "the vanishing parameterization needs an untagged all-quad mesh" in capsys.readouterr().err
    tri.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nt crease 2/1/0 0 3 1\n")
    assert main(["eval", str(tri), "--samples", "3", "--out", str(tmp_path / "x.npz")]) == 2
    assert "crease on edge (0, 3): no such edge in the mesh" in capsys.readouterr().err


def test_tagged_mesh_by_ptex_face(tmp_path, refdir):
    obj = refdir / "osd_features" / "meshes" / "catmark_pyramid_creases1.obj"
    d = __import__("json").loads((refdir / "osd_features" / "osd_limit_catmark_pyramid_creases1.json").read_text())
    rows = [s for s in d["samples"] if s["exact"]][:20]
    csv = tmp_path / "p.csv"
    csv.write_text("face,u,v\n" + "".join(f"{s['ptex']},{s['s']!r},{s['t']!r}\n" for s in rows))
    out = tmp_path / "r.npz"
    assert main(["eval", str(obj), "--points", str(csv), "--out", str(out)]) == 0
    r = np.load(out)
    assert np.abs(r["P"] - np.array([s["P"] for s in rows])).max() < 1e-14
    assert np.abs(r["Pu"] - np.array([s["Ps"] for s in rows])).max() < 1e-12
