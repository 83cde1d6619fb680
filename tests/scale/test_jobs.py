"""``--jobs`` validated the same way by every command (0 and -1 refused, not silently the default), worker counts
capped by the tasks and the cores (``--jobs 1000`` for 2 tasks used to start a worker per requested job), a
scheduler address without a port refused in one line before any work, and a face id ``inf`` named as such."""

import warnings

import pytest

from ccproof.cli import main
from ccproof.errors import CCProofError
from ccproof.mesh import write_obj
from ccproof.mesh.examples import k_regular_disk
from ccproof.scale import engine, processes


def _no_work(*a, **k):
    raise AssertionError("the work started before --jobs was checked")


@pytest.mark.parametrize("jobs", ["0", "-1"])
@pytest.mark.parametrize("argv", [["certify", "5-6"], ["verify", "--all"],
                                  ["table", "--all", "--kmax", "4", "--dir", "{tmp}"]])
def test_jobs_below_one_are_refused_by_every_command(argv, jobs, tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(engine, "run_tasks", _no_work)
    monkeypatch.setattr(processes, "process_pool", _no_work)
    monkeypatch.setattr(engine, "open_scheduler", _no_work)
    assert main([a.format(tmp=tmp_path) for a in argv] + ["--jobs", jobs]) == 2
    err = capsys.readouterr().err
    assert f"--jobs must be an integer >= 1 (1 runs in this process), got {jobs}" in err, err


def test_workers_are_capped_by_the_tasks_and_the_cores(monkeypatch):
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        assert processes.check_jobs(1000, tasks=2) == min(2, processes.usable_cores())
        assert processes.check_jobs(1000) == processes.usable_cores()
    assert len(w) == 2 and "1000" in str(w[0].message) and "worker process" in str(w[0].message)
    started = []

    class Cluster:  # records what would be started (a real cluster takes seconds)
        def __init__(self, n_workers, **kw):
            started.append(n_workers)
            raise RuntimeError("stop here")

    import distributed

    monkeypatch.setattr(distributed, "LocalCluster", Cluster)
    with pytest.raises(RuntimeError, match="stop here"):
        engine.run_tasks(abs, [1, 2], "local:1000", progress=False)
    with pytest.raises(RuntimeError, match="stop here"), engine.open_scheduler("local:1000", n_tasks=3):
        pass
    assert started == [2, 3]


def test_scheduler_local_n_is_checked_like_jobs():
    import argparse

    with pytest.raises(CCProofError, match="local:N needs an integer N >= 1"):
        engine.scheduler_from_args(argparse.Namespace(scheduler="local:0"))
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        s = engine.scheduler_from_args(argparse.Namespace(scheduler=f"local:{processes.usable_cores() + 5}"))
    assert (s.kind, s.workers) in (("local", processes.usable_cores()), ("serial", None)) and len(w) == 1


def test_a_scheduler_address_without_a_port_is_one_line(tmp_path, monkeypatch, capsys):
    write_obj(tmp_path / "d.obj", k_regular_disk(5, rings=2))
    import ccproof.mesh.io as io

    monkeypatch.setattr(io, "read_mesh", _no_work)
    for addr in ("tcp://localhost", "localhost:", "tcp://localhost:http", "tcp://h:99999"):
        assert main(["eval", str(tmp_path / "d.obj"), "--samples", "3", "--out", str(tmp_path / "o.npz"),
                     "--scheduler", addr]) == 2
        err = capsys.readouterr().err
        assert f"--scheduler {addr}: a scheduler address needs a port" in err and len(err.splitlines()) == 1, err


def test_a_face_id_inf_is_named(tmp_path, capsys):
    write_obj(tmp_path / "d.obj", k_regular_disk(5, rings=2))
    (tmp_path / "p.csv").write_text("face,u,v\n0,0.5,0.5\ninf,0.5,0.5\n")
    assert main(["eval", str(tmp_path / "d.obj"), "--points", str(tmp_path / "p.csv"),
                 "--out", str(tmp_path / "o.npz")]) == 2
    err = capsys.readouterr().err
    assert "p.csv:3: face must be an integer, got inf" in err and "-9223372036854775808" not in err, err


def test_a_face_id_beyond_int64_is_named(tmp_path, capsys):
    write_obj(tmp_path / "d.obj", k_regular_disk(5, rings=2))
    (tmp_path / "p.csv").write_text("face,u,v\n0,0.5,0.5\n1e30,0.5,0.5\n")
    assert main(["eval", str(tmp_path / "d.obj"), "--points", str(tmp_path / "p.csv"),
                 "--out", str(tmp_path / "o.npz")]) == 2
    err = capsys.readouterr().err
    assert "p.csv:3: face id 1e+30 is out of range" in err and len(err.strip().splitlines()) == 1, err
    assert "-9223372036854775808" not in err and not (tmp_path / "o.npz").exists()
