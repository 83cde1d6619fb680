"""The task runner without Dask: scheduler specs, the serial fallback of the default, the error that
names the extra when a cluster is asked for, and the serial retries."""

import pytest

from ccproof.errors import CCProofError
from ccproof.scale import engine


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
        engine.run_tasks(abs, [-1, -2], "local:2", progress=False)


def test_cli_scheduler_options():
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
