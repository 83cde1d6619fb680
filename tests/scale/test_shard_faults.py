"""Shard folders under faults: a truncated shard is named in the one-line error, and the temporary files a
killed run left in an output folder are removed by the next run (those of live writers are kept)."""

import os
import subprocess
import sys

from ccproof.cli import main
from ccproof.mesh import write_obj
from ccproof.mesh.examples import k_regular_disk


def test_truncated_shard_is_named(tmp_path, capsys):
    write_obj(tmp_path / "d.obj", k_regular_disk(5, rings=2))
    assert main(["eval", str(tmp_path / "d.obj"), "--samples", "30", "--chunk", "10", "--serial",
                 "--out", str(tmp_path / "sh") + "/"]) == 0
    part = tmp_path / "sh" / "part-00001.npz"
    part.write_bytes(part.read_bytes()[:200])
    capsys.readouterr()
    assert main(["eval", str(tmp_path / "d.obj"), "--points", str(tmp_path / "sh"), "--serial",
                 "--out", str(tmp_path / "o.npz")]) == 2
    err = capsys.readouterr().err
    assert f"{part}: not a readable shard" in err and len(err.strip().splitlines()) == 1, err


def test_stale_temporaries_in_an_output_folder_are_removed(tmp_path):
    write_obj(tmp_path / "d.obj", k_regular_disk(5, rings=2))
    (tmp_path / "sh").mkdir()
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    stale = tmp_path / "sh" / f".tmp-{dead.pid}-abcdef-part-00000.npz"
    live = tmp_path / "sh" / f".tmp-{os.getpid()}-abcdef-part-00009.npz"
    stale.write_bytes(b"killed")
    live.write_bytes(b"being written")
    out = str(tmp_path / "sh") + "/"
    assert main(["eval", str(tmp_path / "d.obj"), "--samples", "10", "--serial", "--out", out]) == 0
    assert not stale.exists() and live.exists()


def test_a_shard_index_linked_to_dev_zero_is_refused_at_once(tmp_path, capsys):
    write_obj(tmp_path / "d.obj", k_regular_disk(5, rings=2))
    (tmp_path / "sh").mkdir()
    os.symlink("/dev/zero", tmp_path / "sh" / "index.json")
    assert main(["eval", str(tmp_path / "d.obj"), "--points", str(tmp_path / "sh"), "--out", str(tmp_path / "o.npz"),
                 "--max-input", "0.001"]) == 2  # (the old code read it until memory ran out)
    err = capsys.readouterr().err
    assert "index.json -> /dev/zero: not a regular file (a character device)" in err, err


def _full_disk(*args, **kwargs):
    import errno

    raise OSError(errno.ENOSPC, "No space left on device")  # as numpy's zip writer raises it: no file name


def test_a_full_disk_names_the_result_file(tmp_path, capsys, monkeypatch):
    import numpy as np

    write_obj(tmp_path / "d.obj", k_regular_disk(5, rings=2))
    monkeypatch.setattr(np, "savez", _full_disk)
    for out in (tmp_path / "o.npz", tmp_path / "sh"):
        spec = str(out) + ("/" if out.suffix != ".npz" else "")
        assert main(["eval", str(tmp_path / "d.obj"), "--samples", "30", "--chunk", "10", "--serial",
                     "--out", spec]) == 2
        err = capsys.readouterr().err
        named = str(out / "part-00000.npz") if out.suffix != ".npz" else str(out)
        assert named in err and "no space left on device" in err.lower() and len(err.strip().splitlines()) == 1, err
        assert not out.exists() or not [p for p in out.iterdir() if p.name.startswith(".tmp-")]
