"""``ccproof project``: CSV in, npz out, in point order; --certify adds verdicts; bad CSV refused."""

import numpy as np

from ccproof.cli import main
from ccproof.evaluate import limit_surface
from ccproof.evaluate.closest import closest_points


def test_project_roundtrip(refdir, tmp_path):
    mesh = refdir / "meshes" / "sector_k5.obj"
    X = np.array([[0.1, 0.2, 0.5], [-0.3, 0.1, -0.2], [0.0, 0.0, 0.0]])
    csv = tmp_path / "p.csv"
    csv.write_text("x,y,z\n" + "".join(f"{float(a)!r},{float(b)!r},{float(c)!r}\n" for a, b, c in X))
    out = tmp_path / "o.npz"
    assert main(["project", str(mesh), str(csv), "--out", str(out)]) == 0
    d = np.load(out)
    ref = closest_points(limit_surface(mesh), X)
    for k in ("face", "u", "v", "P", "distance", "normal"):
        np.testing.assert_array_equal(d[k], getattr(ref, k))
    assert "verdict" not in d


def test_project_certify(refdir, tmp_path):
    csv = tmp_path / "p.csv"
    csv.write_text("x,y,z\n0.3,-0.2,0.9\n")
    out = tmp_path / "o.npz"
    assert main(["project", str(refdir / "meshes" / "cube.obj"), str(csv), "--out", str(out), "--certify"]) == 0
    d = np.load(out)
    assert d["verdict"].tolist() == ["certified"]
    assert d["distance_lo"][0] <= d["distance"][0] <= d["distance_hi"][0] * (1 + 1e-15)


def test_project_bad_header(refdir, tmp_path, capsys):
    csv = tmp_path / "p.csv"
    csv.write_text("face,u,v\n0,0.5,0.5\n")
    assert main(["project", str(refdir / "meshes" / "cube.obj"), str(csv), "--out", str(tmp_path / "o.npz")]) == 2
    assert "x,y,z" in capsys.readouterr().err
