"""One output plan per command, checked before any computation: every path a run writes (derived names and
sidecars too) distinct from the others and from the inputs (whatever the spelling, a symbolic or a hard
link), within the file system's name limits; options that could only fail after the work refused up front;
on a failure during the writes nothing of the run is left, and temporary files of killed runs are removed.

The computation is replaced by one that fails the test, so a check that comes after the work is caught
at once (on the code before these checks, fit ran for minutes and then overwrote its first output)."""

import errno
import os
import subprocess
import sys
import time

import numpy as np
import pytest

from ccproof.cli import _output, main
from ccproof.mesh import write_obj
from ccproof.mesh.examples import k_regular_disk


def _no_work(*a, **k):
    raise AssertionError("the work started before the outputs were checked")


@pytest.fixture
def cloud(tmp_path, monkeypatch):
    import ccproof.apps.dynamics.fit as fit

    monkeypatch.setattr(fit, "fit_points", _no_work)
    monkeypatch.chdir(tmp_path)
    rng = np.random.default_rng(0)
    p = tmp_path / "pts.xyz"
    np.savetxt(p, rng.normal(size=(50, 3)))
    return p


@pytest.fixture
def disk(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    p = tmp_path / "ev5.obj"
    write_obj(p, k_regular_disk(5, rings=3, height=lambda x, y: 0.1 * x * y))
    return p


def _refused(argv, capsys, *words):
    t0 = time.perf_counter()
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err, err
    for w in words:
        assert w in err, err
    assert time.perf_counter() - t0 < 5
    return err


def test_fit_refuses_two_outputs_naming_one_file(cloud, tmp_path, capsys):
    _refused(["fit", str(cloud), "--out", "x.obj", "--surface-out", "x.obj"], capsys, "--surface-out", "--out",
             "same file")
    _refused(["fit", str(cloud), "--out", "x.obj", "--surface-out", "sub/../x.obj"], capsys, "same file")
    (tmp_path / "sub").mkdir()
    os.symlink(tmp_path / "x.obj", tmp_path / "sub" / "link.obj")
    _refused(["fit", str(cloud), "--out", "x.obj", "--surface-out", "sub/link.obj"], capsys, "same file")


def test_fit_refuses_an_output_replacing_an_input(cloud, tmp_path, capsys):
    write_obj(tmp_path / "start_limit.obj", k_regular_disk(4, rings=2))
    # the derived name of the limit surface is the --init mesh
    _refused(["fit", str(cloud), "--init", "start_limit.obj", "--out", "start.obj"], capsys, "--init",
             "derived", "replace an input")
    os.link(cloud, tmp_path / "hard.csv")  # a hard link to the points
    _refused(["fit", str(cloud), "--out", "o.obj", "--errors", "hard.csv"], capsys, "POINTS", "replace an input")


def test_fit_refuses_a_derived_name_beyond_the_name_limit(cloud, capsys):
    out = "o" * 240 + ".obj"  # 244 bytes: fits, but OUT_limit.obj and the temporary names do not
    err = _refused(["fit", str(cloud), "--out", out], capsys, "bytes")
    assert "--surface-out" in err or "--out" in err


def test_arap_refuses_colliding_outputs_and_negative_levels_before_the_work(disk, monkeypatch, capsys):
    import ccproof.apps.arap.meshes as meshes

    monkeypatch.setattr(meshes, "compare", _no_work)
    _refused(["arap", str(disk), "--out", "x.obj", "--control-out", "x.obj"], capsys, "--control-out", "same file")
    _refused(["arap", str(disk), "--out", "x.obj", "--labels-out", "x.obj.json"], capsys, "sidecar", "same file")
    _refused(["arap", str(disk), "--out", "x.obj", "--labels-out", str(disk)], capsys, "MESH", "replace an input")
    _refused(["arap", str(disk), "--out", "x.obj", "--out-level", "-1"], capsys, "--out-level must be >= 0")
    _refused(["arap", str(disk), "--control-out", "c.obj", "--control-extra", "-1"], capsys, "--control-extra")
    _refused(["arap", str(disk), "--max-memory", "nan"], capsys, "--max-memory")


def test_arap_leaves_nothing_when_a_late_write_fails(disk, tmp_path, monkeypatch, capsys):
    """A full disk at the last file: the files written before it are not left either."""
    import ccproof.apps.arap.io as io

    def full(path, *a, **k):
        with open(path, "w") as fh:
            fh.write("half a file")
        raise OSError(errno.ENOSPC, "No space left on device")  # as zipfile and numpy raise it: no file name

    monkeypatch.setattr(io, "write_uv_obj", full)
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    stale = tmp_path / f".tmp-{dead.pid}-abcdef-u.obj"  # left by a SIGKILLed run
    stale.write_text("killed")
    before = set(os.listdir(tmp_path)) - {stale.name}
    rc = main(["arap", str(disk), "--levels", "1", "--refine", "0", "--eval-level", "1", "--out", "u.obj",
               "--labels-out", "l.txt", "--control-out", "c.obj", "--control-extra", "0"])
    err = capsys.readouterr().err
    assert rc == 2 and "error: c.obj: no space left on device" in err and "Traceback" not in err, err  # named
    assert set(os.listdir(tmp_path)) == before, sorted(set(os.listdir(tmp_path)) - before)


def test_certify_tagged_refuses_a_file_as_out_folder_at_once(tmp_path, capsys):
    f = tmp_path / "FILE"
    f.write_text("x")
    _refused(["certify", "crease:4", "--c1", "--out", str(f)], capsys, "is a file, not a folder")


def test_plan_keeps_temporaries_of_live_writers(tmp_path):
    live = tmp_path / f".tmp-{os.getpid()}-abcdef-o.obj"
    other = tmp_path / ".tmp-1-abcdef-notours.obj"
    live.write_text("being written")
    other.write_text("x")
    plan = _output.OutputPlan()
    plan.add("--out", tmp_path / "o.obj", (".obj",))
    plan.check()
    assert live.exists() and other.exists()


def test_eval_and_project_refuse_an_output_replacing_an_input(disk, tmp_path, monkeypatch, capsys):
    import ccproof.mesh.io as io

    monkeypatch.setattr(io, "read_mesh", _no_work)
    (tmp_path / "pts.npz").write_text("x,y,z\n0,0,1\n")  # the CSV reader does not look at the suffix
    _refused(["project", str(disk), "pts.npz", "--out", "./pts.npz"], capsys, "POINTS", "replace an input")
    (tmp_path / "shards").mkdir()
    _refused(["eval", str(disk), "--points", "shards", "--out", "shards/"], capsys, "--points", "replace an input")
