"""The process pools of ``table --all`` and ``report --jobs`` (and of the local scheduler without Dask) under
signals, at every moment: a Ctrl-C to the process group while the workers are still starting used to end each
starting worker with a "Fatal Python error" and its traceback after the command's line; a worker inside a long
call that holds the interpreter lock outlived a parent killed by SIGKILL until the call ended (its watching
thread could not run); ``report --jobs 1000`` started a worker per certificate on any machine."""

import os
import signal
import subprocess
import sys
import time
import warnings
from pathlib import Path

import pytest

from ccproof.cli import main
from ccproof.scale import processes

ROOT = Path(__file__).resolve().parents[2]
pytestmark = pytest.mark.skipif(not os.path.exists("/proc"), reason="reads processes from /proc")

#: sitecustomize of the command and its workers: a pool worker leaves a mark and sleeps a second while
#: Python starts (before any code of the pool runs in it), so that the test signals inside that window
_SITE = '''
import os, sys
if "--multiprocessing-fork" in sys.argv and os.environ.get("CCPROOF_TEST_WORKER_MARKS"):
    import pathlib, time
    pathlib.Path(os.environ["CCPROOF_TEST_WORKER_MARKS"], str(os.getpid())).touch()
    time.sleep(1.0)
'''


def _alive(pid):
    try:
        with open(f"/proc/{pid}/stat") as fh:
            stat = fh.read()
    except FileNotFoundError:
        return False
    return stat[stat.rindex(")") + 2] != "Z"


def _wait_for(cond, seconds):
    t0 = time.perf_counter()
    while not cond() and time.perf_counter() - t0 < seconds:
        time.sleep(0.05)
    return cond()


def test_ctrl_c_while_the_table_workers_start(tmp_path, session_processes):
    """``table --all --jobs 2``, Ctrl-C while its workers are starting: exit 130, the one line, no traceback,
    no table, no process left. A terminal sends SIGINT to the whole group at once; here the workers get it
    first and the command 0.3 s later, so that the workers' part of the race is deterministic (the command
    used to stop them often, not always, before they printed)."""
    site, marks, out = tmp_path / "site", tmp_path / "marks", tmp_path / "tables"
    for d in (site, marks, out):
        d.mkdir()
    (site / "sitecustomize.py").write_text(_SITE)
    env = dict(os.environ, CCPROOF_TEST_WORKER_MARKS=str(marks), PYTHONPATH=f"{site}{os.pathsep}{ROOT}")
    code = "import sys; from ccproof.cli import main; sys.exit(main(sys.argv[1:]))"
    proc = subprocess.Popen([sys.executable, "-c", code, "table", "--all", "--kmax", "3", "--jobs", "2", "--dir",
                             str(out), "--no-progress"], env=env, text=True, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, start_new_session=True)
    try:
        assert _wait_for(lambda: len(os.listdir(marks)) == 2 or proc.poll() is not None, 60) and \
            proc.poll() is None, proc.communicate()[1]
        for worker in os.listdir(marks):
            os.kill(int(worker), signal.SIGINT)
        time.sleep(0.3)
        os.kill(proc.pid, signal.SIGINT)
        _, err = proc.communicate(timeout=60)
        outlived = "processes of the command outlived it"
        assert _wait_for(lambda: not session_processes(proc.pid, zombies=False), 10), outlived
    finally:
        if session_processes(proc.pid, zombies=False):
            os.killpg(proc.pid, signal.SIGKILL)
    assert proc.returncode == 130, err
    assert err.strip().splitlines() == ["ccproof table: interrupted"], err
    assert os.listdir(out) == []


_GREEDY = '''
import os, re
def task(folder):
    open(os.path.join(folder, str(os.getpid())), "w").close()
    re.match(r"(a+)+$", "a" * 40 + "b")  # minutes in one call that holds the interpreter lock
'''

_PARENT = '''
import sys
sys.path.insert(0, sys.argv[1])
import greedy
from ccproof.scale.processes import process_pool
with process_pool(2) as ex:
    list(ex.map(greedy.task, [sys.argv[2]] * 2))
'''


def test_workers_in_a_long_call_end_with_their_killed_parent(tmp_path):
    (tmp_path / "greedy.py").write_text(_GREEDY)
    marks = tmp_path / "marks"
    marks.mkdir()
    env = dict(os.environ, PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    parent = subprocess.Popen([sys.executable, "-c", _PARENT, str(tmp_path), str(marks)], env=env)
    workers = []
    try:
        assert _wait_for(lambda: len(os.listdir(marks)) == 2 or parent.poll() is not None, 60)
        workers = [int(p) for p in os.listdir(marks)]
        assert len(workers) == 2, "the workers did not start"
        time.sleep(0.3)  # inside the call
        parent.send_signal(signal.SIGKILL)
        parent.wait()
        gone = _wait_for(lambda: not any(_alive(w) for w in workers), 3)
    finally:
        if parent.poll() is None:
            parent.kill()
        for w in workers:  # clean up after a failure
            if _alive(w):
                os.kill(w, signal.SIGKILL)
    assert gone, "a worker in a long call outlived its parent by 3 s"


def test_report_jobs_is_checked_and_capped_like_every_command(monkeypatch, capsys):
    import ccproof.cli.report as report

    started = []

    class Pool:  # records the workers asked for (a real report takes minutes)
        def __init__(self, n):
            started.append(n)

        def __enter__(self):
            raise KeyboardInterrupt

        def __exit__(self, *exc):
            return False

    monkeypatch.setattr(processes, "process_pool", Pool)
    for jobs in ("0", "-1"):
        assert main(["report", "--jobs", jobs]) == 2
        assert f"--jobs must be an integer >= 1 (1 runs in this process), got {jobs}" in capsys.readouterr().err
    with warnings.catch_warnings():
        warnings.simplefilter("always")
        assert main(["report", "--jobs", "1000", "--no-progress"]) == 130
    err = capsys.readouterr().err
    assert started and started[0] <= processes.usable_cores(), started
    assert "--jobs 1000:" in err and "worker process" in err, err
    n = len(report.injectivity_files())
    assert started[0] <= n


def test_table_removes_the_temporaries_of_its_stopped_workers(tmp_path, monkeypatch, capsys):
    """A worker terminated (Ctrl-C) or killed (with its parent) while it writes a table leaves its temporary
    file; ``table --all`` removes those whose writer is gone, before and after its work, and keeps the others."""
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True,
                          text=True).stdout.strip()
    stale = [tmp_path / f".tmp-{dead}-k003.json", tmp_path / f".tmp-{dead}-k_ge_40.json"]
    live = tmp_path / f".tmp-{os.getpid()}-k004.json"
    mine = tmp_path / "k005.json"
    for p in [*stale, live, mine]:
        p.write_text("{")

    class Pool:  # the workers start, one of them dies in the middle of a write, then Ctrl-C
        def __init__(self, n):
            pass

        def __enter__(self):
            (tmp_path / f".tmp-{dead}-k006.json").write_text("{")
            raise KeyboardInterrupt

        def __exit__(self, *exc):
            return False

    monkeypatch.setattr(processes, "process_pool", Pool)
    assert main(["table", "--all", "--kmax", "6", "--jobs", "1", "--dir", str(tmp_path), "--no-progress"]) == 130
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([live.name, mine.name])
    new = tmp_path / "new"  # a folder the first table creates
    assert main(["table", "--all", "--kmax", "6", "--jobs", "1", "--dir", str(new), "--no-progress"]) == 130, \
        capsys.readouterr().err
    assert not new.exists()


@pytest.mark.slow  # about 10 s: a real cluster
def test_a_local_cluster_says_nothing_when_the_dashboard_port_is_taken(tmp_path):
    """The scheduler of a local cluster (no dashboard) still serves a small HTTP page, on Dask's port 8787
    by default; with that port taken (another cluster on the machine) every run printed a warning line."""
    pytest.importorskip("distributed")
    import socket

    from ccproof.mesh import write_obj
    from ccproof.mesh.examples import k_regular_disk

    write_obj(tmp_path / "d.obj", k_regular_disk(5, rings=2))
    with socket.socket() as sock:
        try:
            sock.bind(("", 8787))
            sock.listen()
        except OSError:
            pass  # taken already
        r = subprocess.run([sys.executable, "-m", "ccproof.cli", "eval", "d.obj", "--samples", "400", "--chunk", "200",
                            "--scheduler", "local:2", "--out", "o.npz", "--no-progress"], cwd=tmp_path,
                           capture_output=True, text=True, timeout=120,
                           env=dict(os.environ, PYTHONPATH=str(ROOT)))
    assert r.returncode == 0 and r.stderr == "", r.stderr
