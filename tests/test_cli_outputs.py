"""Output paths of the command line (ccproof/cli/_output.py) and the paths sent to workers: checked before
any work, written atomically, absolute for the workers, shards only when a folder is asked for."""

import argparse
import os

import numpy as np
import pytest

from ccproof.cli import _output, main
from ccproof.errors import CCProofError
from ccproof.mesh import write_obj
from ccproof.mesh.examples import cube


def test_check_file_refuses_what_it_cannot_write(tmp_path):
    (tmp_path / "afile").write_text("x")
    (tmp_path / "adir").mkdir()
    cases = {
        str(tmp_path / "nodir" / "o.npz"): "does not exist",
        str(tmp_path / "afile" / "o.npz"): "is not a folder",
        str(tmp_path / "adir"): "is a folder",
        str(tmp_path / "o.csv"): "use one of .npz",
        str(tmp_path / "o"): "a name without a suffix",
        str(tmp_path / "npz"): "a name without a suffix",
        str(tmp_path / "o.NPZ"): "cannot write '.NPZ' files",  # numpy would write o.NPZ.npz
    }
    for path, why in cases.items():
        with pytest.raises(CCProofError, match=why) as exc:
            _output.check_file(path, (".npz",))
        assert str(exc.value).startswith(f"--out {path}: ")
    got = _output.check_file(os.path.relpath(tmp_path / "o.npz"), (".npz",))
    assert got.is_absolute() and got == tmp_path / "o.npz"


def test_check_folder(tmp_path):
    (tmp_path / "afile").write_text("x")
    assert _output.check_folder(tmp_path / "new" / "deeper") == tmp_path / "new" / "deeper"  # created later
    assert not (tmp_path / "new").exists()  # checking creates nothing
    with pytest.raises(CCProofError, match="is a file, not a folder"):
        _output.check_folder(tmp_path / "afile")
    with pytest.raises(CCProofError, match="afile is a file, not a folder"):
        _output.check_folder(tmp_path / "afile" / "sub" / "deeper")


def test_check_outputs_knows_the_mesh_formats():
    args = argparse.Namespace(out="surface.vtu", preview="p.png", control_out=None)
    _output.check_outputs(args, out="mesh", preview="plot", control_out=(".obj",))
    args.out = "surface.docx"
    with pytest.raises(CCProofError, match=r"--out surface.docx: .*\.obj, .*\.vtu"):
        _output.check_outputs(args, out="mesh")


def test_atomic_leaves_the_old_file_on_an_error(tmp_path):
    out = tmp_path / "o.txt"
    out.write_text("old")
    with pytest.raises(RuntimeError), _output.atomic(out) as tmp:
        with open(tmp, "w") as fh:
            fh.write("half")
        raise RuntimeError("the writer failed")
    assert out.read_text() == "old" and sorted(os.listdir(tmp_path)) == ["o.txt"]
    with _output.atomic(out) as tmp:
        assert tmp.endswith("o.txt") and os.path.dirname(tmp) == str(tmp_path)  # same folder, same suffix
        with open(tmp, "w") as fh:
            fh.write("new")
    assert out.read_text() == "new" and sorted(os.listdir(tmp_path)) == ["o.txt"]


def test_is_folder_request(tmp_path):
    (tmp_path / "d.npz").mkdir()
    assert _output.is_folder_request("shards/") and _output.is_folder_request(str(tmp_path / "d.npz"))
    assert not _output.is_folder_request("o.csv") and not _output.is_folder_request("o.npz")


def test_eval_out_csv_is_refused_and_a_folder_is_sharded(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    write_obj("cube.obj", cube())
    assert main(["eval", "cube.obj", "--samples", "5", "--serial", "--out", "o.csv"]) == 2
    assert "cannot write '.csv' files; use one of .npz" in capsys.readouterr().err
    assert not os.path.exists("o.csv")
    assert main(["eval", "cube.obj", "--samples", "5", "--chunk", "2", "--serial", "--out", "shards/"]) == 0
    assert sorted(os.listdir("shards")) == ["index.json", "part-00000.npz", "part-00001.npz", "part-00002.npz"]
    assert main(["eval", "cube.obj", "--samples", "5", "--serial", "--out", "one.npz"]) == 0
    one = np.load("one.npz")
    first = np.load("shards/part-00000.npz")
    assert one["P"].shape == (5, 3) and first["P"].shape == (2, 3)


def test_workers_get_absolute_paths(tmp_path, monkeypatch):
    """verify and eval send absolute paths to their tasks, whatever folder the command runs in."""
    import ccproof.scale.engine as engine
    from ccproof.scale.arrays import point_chunks

    monkeypatch.chdir(tmp_path)
    write_obj("cube.obj", cube())
    assert main(["eval", "cube.obj", "--samples", "4", "--chunk", "2", "--serial", "--out", "rel/"]) == 0
    assert all(os.path.isabs(src[1]) for src in point_chunks(2, shards="rel"))

    seen = []
    real = engine.run_tasks

    def spy(fn, tasks, *a, **kw):
        tasks = list(tasks)
        seen.extend(tasks)
        return real(fn, tasks, *a, **kw)

    monkeypatch.setattr(engine, "run_tasks", spy)
    (tmp_path / "bad.json").write_text("{}")
    assert main(["verify", "bad.json", "--serial"]) == 1
    assert seen and all(os.path.isabs(t[0]) for t in seen)
    seen.clear()
    assert main(["eval", "cube.obj", "--samples", "4", "--chunk", "2", "--serial", "--out", "rel2/"]) == 0
    assert seen and all(os.path.isabs(t["out"]) for t in seen)


def test_eval_prints_the_retry_report(tmp_path, monkeypatch, capsys):
    """A chunk whose worker was lost (recorded by the task runner) is reported after the sweep."""
    import ccproof.scale.arrays as arrays

    real = arrays.evaluate_points

    def lost_once(*a, **kw):
        n, names, sweep, setup = real(*a, **kw)
        sweep.retried[1] = "its worker was lost 1 time(s); re-run on another worker"
        return n, names, sweep, setup

    monkeypatch.setattr(arrays, "evaluate_points", lost_once)
    monkeypatch.chdir(tmp_path)
    write_obj("cube.obj", cube())
    assert main(["eval", "cube.obj", "--samples", "4", "--chunk", "2", "--serial", "--out", "o.npz"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert "1 task(s) retried; every result is in" in out
    assert "chunk 1: its worker was lost 1 time(s); re-run on another worker" in out
