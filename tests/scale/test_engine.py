"""The task runner without Dask: scheduler specs, the serial fallback of the default, the error that
names the extra when a cluster is asked for, and the serial retries."""

import pytest

from ccproof.errors import CCProofError
from ccproof.scale import engine, processes


def test_default_without_dask_runs_in_process(monkeypatch):
    monkeypatch.setattr(engine, "dask_available", lambda: False)
    sweep = engine.run_tasks(abs, [-1, -2, 3], None, progress=False)
    assert sweep.results == [1, 2, 3] and sweep.scheduler == "serial"


def test_an_explicit_cluster_without_dask_names_the_extra(monkeypatch):
    import builtins

    real = builtins.__import__

    def no_dask(name, *a, **kw):
        if name.split(".")[0] in ("distributed", "dask"):
            raise ImportError(name)
        return real(name, *a, **kw)

    monkeypatch.setattr(builtins, "__import__", no_dask)
    with pytest.raises(CCProofError, match=r"extra 'scale'"):
        engine.run_tasks(abs, [-1, -2], "tcp://127.0.0.1:8786", progress=False)


def _dies_once_then_negates(task):
    """Kill its own worker process the first time task 1 runs (a marker file remembers it), fail task 3
    with an expected error, negate the others."""
    import os
    from pathlib import Path

    value, marker = task
    if value == 1 and not Path(marker).exists():
        Path(marker).write_text("died once")
        os._exit(1)
    if value == 3:
        raise CCProofError("bad task 3")
    return -value


def test_local_workers_without_dask_are_processes(monkeypatch, tmp_path):
    """``local:2`` without Dask: worker processes of the standard library, results in task order, a lost
    worker's task re-run and reported, an expected error not retried and reported with its reason."""
    monkeypatch.setattr(engine, "dask_available", lambda: False)
    marker = str(tmp_path / "died")
    tasks = [(i, marker) for i in range(5)]
    sweep = engine.run_tasks(_dies_once_then_negates, tasks, "local:2", progress=False, raise_errors=False)
    assert sweep.results == [0, -1, -2, None, -4]
    assert set(sweep.errors) == {3} and str(sweep.errors[3]) == "bad task 3"
    assert "its worker was lost" in sweep.retried[1]
    # a re-run task's result is in; task 3 may be re-run too (a lost worker breaks the pool and every task
    # still pending in it is re-run), and then its expected error, not a result, is what it ends with
    assert all(sweep.results[i] is not None for i in sweep.retried if i != 3)
    assert all(i in sweep.errors for i in sweep.retried if sweep.results[i] is None)
    lines = sweep.report([f"t{i}" for i in range(5)])
    assert "t3: FAILED: CCProofError: bad task 3" in lines


def test_cli_scheduler_options(monkeypatch):
    monkeypatch.setattr(processes, "usable_cores", lambda: 8)  # --jobs is capped at the cores (test_jobs.py)

    class A:
        scheduler, serial, jobs = None, False, 3

    assert str(engine.scheduler_from_args(A())) == "local:3"
    A.jobs, A.scheduler = None, "tcp://10.0.0.5:8786"
    assert engine.scheduler_from_args(A()).address == "tcp://10.0.0.5:8786"
    A.serial = True
    assert engine.scheduler_from_args(A()).kind == "serial"


_calls = []


def _flaky(task):
    _calls.append(task)
    if task == 2 and _calls.count(2) == 1:
        raise MemoryError("transient")
    if task == 4:
        raise CCProofError("bad task 4")
    return -task


def test_serial_retries_and_failures_are_reported():
    _calls.clear()
    sweep = engine.run_tasks(_flaky, range(6), "serial", progress=False, raise_errors=False)
    assert sweep.results == [0, -1, -2, -3, None, -5]
    assert _calls.count(2) == 2 and _calls.count(4) == 1  # retried once; a CCProofError is not retried
    assert set(sweep.retried) == {2} and set(sweep.errors) == {4}
    lines = sweep.report([f"t{i}" for i in range(6)])
    assert lines[0] == "1 task(s) retried; every result is in" and any(ln.startswith("t4: FAILED") for ln in lines)


def test_verify_jobs_runs_without_dask(tmp_path):
    """``ccproof verify --jobs 2`` on an install without Dask (its import fails): worker processes."""
    import subprocess
    import sys
    from pathlib import Path

    from ccproof.tables.format import certificates_dir

    c1 = certificates_dir() / "c1"
    files = [str(c1 / "k003.json"), str(c1 / "k004.json")]
    script = ("import sys; sys.modules['distributed'] = None; sys.modules['dask'] = None\n"
              "from ccproof.cli import main; sys.exit(main(sys.argv[1:]))")
    repo = Path(__file__).resolve().parents[2]
    env = dict(__import__("os").environ, PYTHONPATH=str(repo))
    run = subprocess.run([sys.executable, "-c", script, "verify", "--jobs", "2", "--quiet", *files], cwd=tmp_path,
                         env=env, capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    assert [ln.split()[0] for ln in run.stdout.splitlines()[:2]] == ["VERIFIED", "VERIFIED"]
    assert "2 of 2 certificates verified" in run.stdout
