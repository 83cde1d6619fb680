"""Every input reader (meshes, ``--points``, fit's point clouds and ``--init``, arap's ``--charts``) reads regular
files or a pipe once, up to a size cap; a link to /dev/zero is refused by name at once (it used to be read until
memory ran out: the subprocess runs under a 2 GB address-space limit and a timeout, so the old behaviour fails
here instead of taking the machine); UTF-8 byte-order marks and CRLF line ends (a spreadsheet's CSV) are read;
binary or malformed point files end in one line naming the file and line."""

import os
import resource
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

from ccproof.cli import main
from ccproof.mesh import write_obj
from ccproof.mesh.examples import k_regular_disk

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def _limited():
    resource.setrlimit(resource.RLIMIT_AS, (2 << 30, 2 << 30))


def _ccproof(*argv, cwd, timeout=60):
    env = dict(os.environ, PYTHONPATH=ROOT + os.pathsep + os.environ.get("PYTHONPATH", ""))
    t0 = time.perf_counter()
    try:
        r = subprocess.run([sys.executable, "-m", "ccproof.cli", *map(str, argv)], cwd=cwd, env=env,
                           capture_output=True, text=True, timeout=timeout, preexec_fn=_limited)
    except subprocess.TimeoutExpired:
        pytest.fail(f"ccproof {' '.join(map(str, argv))} still ran after {timeout} s")
    return r.returncode, r.stdout, r.stderr, time.perf_counter() - t0


@pytest.fixture
def work(tmp_path):
    write_obj(tmp_path / "disk.obj", k_regular_disk(5, rings=3, height=lambda x, y: 0.1 * x * y))
    os.symlink("/dev/zero", tmp_path / "zero.obj")
    for name in ("zero.csv", "zero.xyz", "zero.labels"):
        os.symlink("/dev/zero", tmp_path / name)
    np.savetxt(tmp_path / "pts.xyz", np.random.default_rng(0).normal(size=(60, 3)))
    return tmp_path


@pytest.mark.parametrize("argv, name", [
    (["eval", "zero.obj", "--samples", "10", "--out", "o.npz"], "zero.obj"),
    (["eval", "disk.obj", "--points", "zero.csv", "--out", "o.npz"], "zero.csv"),
    (["project", "disk.obj", "zero.csv", "--out", "o.npz"], "zero.csv"),
    (["fit", "zero.xyz", "--out", "o.obj"], "zero.xyz"),
    (["fit", "pts.xyz", "--init", "zero.obj", "--out", "o.obj"], "zero.obj"),
    (["arap", "disk.obj", "--charts", "zero.labels"], "zero.labels"),
])
def test_a_link_to_dev_zero_is_refused_by_name_at_once(work, argv, name):
    rc, out, err, seconds = _ccproof(*argv, cwd=work)
    assert rc == 2 and len(err.strip().splitlines()) == 1, err
    assert f"{name} -> /dev/zero: not a regular file (a character device)" in err
    assert seconds < 30


def test_the_size_cap_is_stated_and_raised_by_an_option(work, capsys):
    assert main(["eval", str(work / "disk.obj"), "--samples", "5", "--out", str(work / "o.npz"),
                 "--max-input", "1e-6"]) == 2
    err = capsys.readouterr().err
    assert "above the input limit of 1000 bytes" in err and "--max-input" in err
    assert main(["eval", str(work / "disk.obj"), "--samples", "5", "--out", str(work / "o.npz"),
                 "--max-input", "0.001"]) == 0
    for bad in ("nan", "0", "-1", "inf"):
        assert main(["eval", str(work / "disk.obj"), "--samples", "5", "--out", str(work / "o.npz"),
                     "--max-input", bad]) == 2
        assert "--max-input must be a positive number" in capsys.readouterr().err


def test_a_ply_mesh_through_a_fifo_is_read_once(work):
    """The PLY reader looked at the header and then let meshio open the file again: a pipe hung."""
    import meshio

    m = k_regular_disk(5, rings=3, height=lambda x, y: 0.1 * x * y)
    meshio.write(work / "disk.ply", meshio.Mesh(m.vertices, [("quad", m.faces)]), binary=False)
    fifo = work / "pipe.ply"
    os.mkfifo(fifo)
    data = (work / "disk.ply").read_bytes()

    def writer():
        time.sleep(0.5)  # the reader is already waiting
        with open(fifo, "wb") as fh:
            fh.write(data)

    t = threading.Thread(target=writer, daemon=True)
    t.start()
    rc, out, err, _ = _ccproof("eval", "pipe.ply", "--samples", "50", "--out", "a.npz", cwd=work, timeout=30)
    if t.is_alive():  # the reader gave up: release the writer
        os.close(os.open(fifo, os.O_RDONLY | os.O_NONBLOCK))
    t.join()
    assert rc == 0, err
    rc, out, err, _ = _ccproof("eval", "disk.ply", "--samples", "50", "--out", "b.npz", cwd=work)
    with np.load(work / "a.npz") as a, np.load(work / "b.npz") as b:
        assert np.array_equal(a["P"], b["P"])


def test_byte_order_marks_and_crlf_are_read(work, capsys):
    text = (work / "disk.obj").read_text()
    (work / "bom.obj").write_bytes(b"\xef\xbb\xbf" + text.replace("\n", "\r\n").encode())
    csv = "face,u,v\n0,0.25,0.5\n3,0.75,0.125\n"
    (work / "plain.csv").write_text(csv)
    (work / "bom.csv").write_bytes(b"\xef\xbb\xbf" + csv.replace("\n", "\r\n").encode())
    for mesh, pts, out in (("disk.obj", "plain.csv", "a.npz"), ("bom.obj", "bom.csv", "b.npz")):
        assert main(["eval", str(work / mesh), "--points", str(work / pts), "--out", str(work / out)]) == 0, \
            capsys.readouterr().err
    with np.load(work / "a.npz") as a, np.load(work / "b.npz") as b:
        assert all(np.array_equal(a[k], b[k]) for k in ("P", "Pu", "Pv", "face", "u", "v"))
    from ccproof.apps.dynamics.fit import read_points

    (work / "bom.xyz").write_bytes(b"\xef\xbb\xbf" + (work / "pts.xyz").read_text().replace("\n", "\r\n").encode())
    assert np.array_equal(read_points(work / "bom.xyz"), read_points(work / "pts.xyz"))


def test_fit_point_files_end_in_one_line(work, capsys):
    (work / "bin.xyz").write_bytes(np.random.default_rng(1).normal(size=300).tobytes())
    (work / "two.obj").write_text("v 0 0 0\nv 1 2\nv 1 1 1\n")
    for name, words in (("bin.xyz", "a binary file"), ("two.obj", "two.obj:2: bad vertex line")):
        assert main(["fit", str(work / name), "--out", str(work / "o.obj")]) == 2
        err = capsys.readouterr().err
        assert words in err and len(err.strip().splitlines()) == 1, err
