"""A Ctrl-C or SIGTERM while the local Dask cluster starts (1 to 5 s at the start of every multi-chunk run) acts at
once: the start, run in a thread of its own, is given up and the signal's exception raised in the main thread
(it used to raise inside Dask's start-up, 29 to 48 lines of tracebacks, then to wait for the start's end, 1.5 to
5 s). The cluster is a stand-in that signals this process while it "starts" and cannot finish before the test
lets it, so the test is exact about the order; a real cluster is started below."""

import os
import signal
import threading
import time

import pytest

from ccproof.scale import engine


class _Stopped(Exception):
    pass


@pytest.fixture
def fake_cluster(monkeypatch):
    import distributed

    log = []
    release = threading.Event()

    class Cluster:
        def __init__(self, *a, **k):
            os.kill(os.getpid(), log[0])  # the signal arrives in the middle of the start
            release.wait(60)  # the start cannot end before the test says so
            log.append("started")

        def close(self):
            log.append("closed")

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            self.close()

    class Client(Cluster):
        def __init__(self, *a, **k):
            log.append("client")

    monkeypatch.setattr(distributed, "LocalCluster", Cluster)
    monkeypatch.setattr(distributed, "Client", Client)
    yield log, release
    release.set()


def _hook_removed_after(release):
    """Let the given-up start end; then the spawn hook must be gone (multiprocessing spawns as before)."""
    import multiprocessing.util as mpu

    release.set()
    for _ in range(600):
        if mpu.spawnv_passfds.__module__ == "multiprocessing.util":
            return True
        time.sleep(0.05)
    return False


@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGINT])
def test_a_signal_during_the_cluster_start_is_raised_at_once(fake_cluster, signum):
    """The signal's own handler raises in the main thread while the start is still under way (it cannot have
    ended: the stand-in waits for the test); the handlers are this process's, unchanged."""
    log, release = fake_cluster

    def stop(signum, frame):
        raise _Stopped

    handler = stop if signum == signal.SIGTERM else signal.default_int_handler
    expected = _Stopped if signum == signal.SIGTERM else KeyboardInterrupt
    previous = signal.signal(signum, handler)
    try:
        log.append(signum)
        with pytest.raises(expected), engine.client_for("local:2"):
            pytest.fail("the run went on after the signal")
        assert "started" not in log and "client" not in log  # given up, not waited for
        assert signal.getsignal(signum) is handler
        assert _hook_removed_after(release)
    finally:
        signal.signal(signum, previous)


# ---------------------------------------------------------------- a real cluster, a real command
#: sitecustomize of the command and of its workers: the first process spawned by the command (inside the
#: cluster's start) leaves a mark, so that the test signals inside the window (the start takes seconds)
_SITE = '''
import os
if os.environ.get("CCPROOF_TEST_SPAWN_MARK") and not os.environ.get("CCPROOF_TEST_SPAWNED"):
    import multiprocessing.util as mpu, pathlib, time
    original = mpu.spawnv_passfds
    def spawn(path, args, passfds):  # (stays installed: the command's own hook wraps it)
        pid = original(path, args, passfds)
        if not os.environ.get("CCPROOF_TEST_SPAWNED"):
            os.environ["CCPROOF_TEST_SPAWNED"] = "1"  # once, and not in the children (they inherit it)
            pathlib.Path(os.environ["CCPROOF_TEST_SPAWN_MARK"]).touch()
        return pid
    mpu.spawnv_passfds = spawn
'''

CUBE = "\n".join(
    ["v -1 -1 -1", "v 1 -1 -1", "v 1 1 -1", "v -1 1 -1", "v -1 -1 1", "v 1 -1 1", "v 1 1 1", "v -1 1 1",
     "f 1 4 3 2", "f 5 6 7 8", "f 1 2 6 5", "f 2 3 7 6", "f 3 4 8 7", "f 4 1 5 8"]) + "\n"


@pytest.mark.skipif(not os.path.exists("/proc"), reason="reads the processes of a session from /proc")
@pytest.mark.parametrize("how", ["SIGINT to the group", "SIGTERM", "SIGKILL"])
def test_a_signal_while_the_cluster_starts_stops_the_command(tmp_path, how, session_processes):
    """``eval`` on a local cluster, signalled while the cluster starts (a terminal's Ctrl-C reaches the
    whole process group, the first workers too): one line, exit 130 or 143, nothing written, no process of
    the command left (SIGKILL of the command alone: its workers end by themselves). Before, the Ctrl-C was
    discarded and the run wrote its output; then it waited for the start to end (scripts/bench_stop.py times it)."""
    pytest.importorskip("distributed")
    import subprocess
    import sys
    from pathlib import Path

    site = tmp_path / "site"
    site.mkdir()
    (site / "sitecustomize.py").write_text(_SITE)
    (tmp_path / "cube.obj").write_text(CUBE)
    mark = tmp_path / "spawning"
    repo = Path(__file__).resolve().parents[2]
    env = dict(os.environ, CCPROOF_TEST_SPAWN_MARK=str(mark), PYTHONPATH=f"{site}{os.pathsep}{repo}")
    env.pop("CCPROOF_TEST_SPAWNED", None)
    code = "import signal, sys; signal.signal(signal.SIGINT, signal.default_int_handler)\n" \
           "from ccproof.cli import main; sys.exit(main(sys.argv[1:]))"
    proc = subprocess.Popen([sys.executable, "-c", code, "eval", "cube.obj", "--samples", "4", "--chunk", "2",
                             "--scheduler", "local:2", "--out", "o.npz"], cwd=tmp_path, env=env, text=True,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True)
    try:
        for _ in range(2400):  # at most 2 min until the cluster spawns its first process
            if mark.exists() or proc.poll() is not None:
                break
            time.sleep(0.05)
        assert mark.exists() and proc.poll() is None, proc.stderr.read() if proc.poll() is not None else ""
        if how in ("SIGTERM", "SIGKILL"):
            proc.send_signal(getattr(signal, how))
        else:
            os.killpg(proc.pid, signal.SIGINT)
        _, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
    assert "Traceback" not in err, err
    if how != "SIGKILL":
        word, status = ("terminated", 143) if how == "SIGTERM" else ("interrupted", 130)
        lines = err.strip().splitlines()
        assert proc.returncode == status, err
        assert lines[-1] == f"ccproof eval: {word}", err
        assert all(ln.startswith("ccproof eval: warning: ") for ln in lines[:-1]), err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cube.obj", "site", "spawning"]
    for _ in range(100):  # the workers and the resource tracker end with the command (within seconds)
        if not session_processes(proc.pid):
            break
        time.sleep(0.1)
    assert session_processes(proc.pid) == []
