"""One point-cloud reader for ``project`` and ``fit``: ``.xyz``, ``.ply`` (ASCII, binary), ``.obj``, ``.csv``.

The points are written here from a known array (the expected values are that array, not a reader's output),
each format by hand; every format must give the same array and ``project`` the same result for each."""

import numpy as np
import pytest

from ccproof.cli import main
from ccproof.errors import CCProofError
from ccproof.mesh.points import read_points

X = np.array([[0.1, 0.2, 0.5], [-0.3, 0.1, -0.2], [0.0, 0.0, 0.0], [1 / 3, -2 / 7, 0.125]])


def _r(x):
    return f"{float(x)!r}"


def _write_all(d):
    """The rows of X in every point format; returns {name: path}."""
    f = {}
    f["a.xyz"] = "# a comment\n" + "".join(" ".join(map(_r, r)) + " 7 8\n" for r in X)
    f["a.obj"] = "o cloud\n" + "".join("v " + " ".join(map(_r, r)) + "\n" for r in X) + "f 1 2 3\n"
    f["a.csv"] = "\ufeffx,y,z\r\n" + "".join(",".join(map(_r, r)) + "\r\n" for r in X) + "\r\n"
    head = ("ply\nformat {}\ncomment c\nelement vertex 4\nproperty float nx\nproperty double x\nproperty double y\n"
            "property double z\nelement face 0\nproperty list uchar int vertex_indices\nend_header\n")
    f["a.ply"] = head.format("ascii 1.0") + "".join("9 " + " ".join(map(_r, r)) + "\n" for r in X)
    paths = {}
    for name, text in f.items():
        (d / name).write_bytes(text.encode())
        paths[name] = d / name
    rec = np.zeros(4, dtype=[("nx", ">f4"), ("x", ">f8"), ("y", ">f8"), ("z", ">f8")])
    rec["x"], rec["y"], rec["z"] = X.T
    (d / "b.ply").write_bytes(head.format("binary_big_endian 1.0").encode() + rec.tobytes())
    paths["b.ply"] = d / "b.ply"
    return paths


def test_every_format_reads_the_same_points(tmp_path):
    for name, p in _write_all(tmp_path).items():
        assert np.array_equal(read_points(p), X), name


def test_project_reads_every_point_format(refdir, tmp_path):
    mesh = refdir / "meshes" / "sector_k5.obj"
    outs = []
    for name, p in _write_all(tmp_path).items():
        out = tmp_path / f"{name}.npz"
        assert main(["project", str(mesh), str(p), "--out", str(out)]) == 0, name
        with np.load(out) as d:
            outs.append({k: d[k] for k in ("face", "u", "v", "P", "distance")})
    for o in outs[1:]:
        assert all(np.array_equal(o[k], outs[0][k]) for k in o)
    assert np.all(np.linalg.norm(outs[0]["P"] - X, axis=1) - outs[0]["distance"] == pytest.approx(0, abs=1e-15))


def test_fit_reads_a_csv_point_cloud(tmp_path, capsys):
    rng = np.random.default_rng(3)
    Y = rng.standard_normal((200, 3))
    Y /= np.linalg.norm(Y, axis=1)[:, None]
    (tmp_path / "s.csv").write_text("x,y,z\n" + "".join(",".join(map(_r, r)) + "\n" for r in Y))
    assert np.array_equal(read_points(tmp_path / "s.csv"), Y)
    out = tmp_path / "fit.obj"
    assert main(["fit", str(tmp_path / "s.csv"), "--out", str(out), "--levels", "0", "--max-steps", "3",
                 "--sample-level", "1"]) == 0, capsys.readouterr().err
    assert out.exists()


@pytest.mark.parametrize("name,text,words", [
    ("l.csv", "x,y,z\n1,2,3\n1,2\n", "l.csv:3: expected 3 comma-separated values"),
    ("h.csv", "face,u,v\n0,0.5,0.5\n", "header 'x,y,z'"),
    ("n.csv", "x,y,z\n1,2,3\n\n4,nan,6\n", "n.csv:4: point 1 has a non-finite coordinate"),
    ("s.xyz", "1 2 3\n# c\n4 5\n", "s.xyz:3: expected 3 numbers"),
    ("i.xyz", "1 2 3\n1 inf 2\n", "i.xyz:2: point 1 has a non-finite coordinate"),
    ("w.obj", "v 0 0 0\nvt 1 1\nv 1 x 2\n", "w.obj:3: bad vertex line"),
    ("e.xyz", "# nothing\n", "e.xyz: empty file"),
    ("t.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
              "end_header\n1 2 3\n", "t.ply:9: truncated vertex list"),
    ("b.ply", "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\n"
              "end_header\n1 2 3\n4 q 6\n", "b.ply:9: not a number in vertex 1"),
    ("f.ply", "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\n"
              "end_header\n1 2 3\n4 nan 6\n", "f.ply:9: point 1 has a non-finite coordinate"),
])
def test_bad_point_files_are_named_with_their_line(tmp_path, name, text, words):
    (tmp_path / name).write_text(text)
    with pytest.raises(CCProofError, match=words):
        read_points(tmp_path / name)


@pytest.mark.parametrize("cmd", ["project", "fit"])
def test_both_commands_name_the_bad_line(refdir, tmp_path, capsys, cmd):
    (tmp_path / "bad.csv").write_text("x,y,z\n1,2,3\n4,5,6,7\n")
    mesh = [str(refdir / "meshes" / "cube.obj")] if cmd == "project" else []
    assert main([cmd, *mesh, str(tmp_path / "bad.csv"), "--out", str(tmp_path / "o.npz" if mesh else "o.obj")]) == 2
    err = capsys.readouterr().err
    assert "bad.csv:3:" in err and len(err.strip().splitlines()) == 1, err


def test_xyz_lines_of_different_widths_and_separators(tmp_path):
    text = "".join(" ".join(map(_r, r)) + (" 1" * i) + "\n" for i, r in enumerate(X))  # 3, 4, 5, 6 columns
    (tmp_path / "w.xyz").write_text(text)
    (tmp_path / "c.xyz").write_text(text.replace(" ", ", "))  # commas too
    for name in ("w.xyz", "c.xyz"):
        assert np.array_equal(read_points(tmp_path / name), X), name
