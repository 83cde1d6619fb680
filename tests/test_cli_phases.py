"""Every long phase has its own figure and bar: ``eval`` prints read, setup and evaluation seconds and a rate of
the evaluation alone (a slow setup, here a monkeypatched build that sleeps, must not change it, wherever the setup
runs: in this process before the tasks, or inside the first task as on a worker); ``--progress`` draws the bars of
every phase on a stderr that is not a terminal (reading, search build, evaluation)."""

import re
import time

import numpy as np

import ccproof.cli.eval as eval_cli
from ccproof.cli import main
from ccproof.mesh.examples import cube
from ccproof.scale import point_chunks, ship
from ccproof.scale.arrays import evaluate_points

SLOW = 1.5


def _slow_build(monkeypatch):
    """build_surface that sleeps SLOW seconds first (picklable by name, as ship needs)."""
    fast = eval_cli.build_surface

    def build_surface(*args, **kwargs):
        time.sleep(SLOW)
        return fast(*args, **kwargs)

    build_surface.__module__, build_surface.__qualname__ = fast.__module__, fast.__qualname__
    monkeypatch.setattr(eval_cli, "build_surface", build_surface)


def _figures(out):
    read, setup = map(float, re.search(r"read in ([\d.]+) s, setup ([\d.]+) s", out).groups())
    ev, rate = re.search(r"evaluated 2000 points .* in ([\d.]+) s \(([\d,]+) points/s, evaluation alone\); "
                         r".*gathering and writing [\d.]+ s", out).groups()
    return read, setup, float(ev), float(rate.replace(",", ""))


def test_a_slow_setup_is_not_counted_as_evaluation(refdir, tmp_path, capsys, monkeypatch):
    mesh = refdir / "meshes" / "torus_8x6.obj"
    argv = ["eval", str(mesh), "--samples", "2000", "--out", str(tmp_path / "a.npz")]
    for extra in ([], ["--serial"]):  # the default scheduler runs one chunk here, building the surface first
        monkeypatch.undo()
        _slow_build(monkeypatch)
        assert main(argv + extra) == 0
        read, setup, ev, rate = _figures(capsys.readouterr().out)
        assert setup >= SLOW, (extra, setup)
        assert ev < SLOW / 2 and rate > 2000 / (SLOW / 2), (extra, ev, rate)


def test_a_setup_inside_the_first_task_is_reported_apart(tmp_path, monkeypatch):
    _slow_build(monkeypatch)
    src = point_chunks(500, samples=2000, seed=1, n_faces=6)
    shipped = ship(eval_cli.build_surface, cube(), False, None)  # built inside a task, as on a worker
    n, names, sweep, setup = evaluate_points(shipped, src, 1, {}, str(tmp_path / "p.npz"), "serial",
                                             progress=False)
    assert n == 2000 and setup >= SLOW
    assert sweep.seconds - setup < SLOW / 2 <= sweep.seconds
    with np.load(tmp_path / "p.npz") as d:
        assert d["P"].shape == (2000, 3) and "seconds" not in d


def test_progress_draws_every_phase_on_a_pipe(refdir, tmp_path, capsys):
    mesh = refdir / "meshes" / "sector_k5.obj"
    argv = ["eval", str(mesh), "--samples", "2000", "--chunk", "500", "--serial", "--out", str(tmp_path / "a.npz")]
    assert main(argv + ["--progress"]) == 0
    err = capsys.readouterr().err
    assert "read sector_k5.obj" in err and "evaluate: 100%" in err, err
    (tmp_path / "p.xyz").write_text("0.1 0.2 0.5\n0 0 0\n")
    assert main(["project", str(mesh), str(tmp_path / "p.xyz"), "--out", str(tmp_path / "p.npz"),
                 "--progress"]) == 0
    cap = capsys.readouterr()
    assert "read sector_k5.obj" in cap.err and "search structure" in cap.err, cap.err
    assert re.search(r"read in [\d.]+ s, setup [\d.]+ s, search structure [\d.]+ s; 2 points projected", cap.out)
    assert main(argv) == 0
    assert capsys.readouterr().err == ""  # no bar without --progress on a pipe
