"""No worker outlives its parent, SIGKILL included: the workers of a process pool (``table --all --jobs N``,
the local scheduler without Dask) end within about a second of their parent's death (they used to run their
task to its end and stay for ever with the resource tracker)."""

import os
import signal
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

_STALL = '''
import os, time
def task(folder):
    open(os.path.join(folder, str(os.getpid())), "w").close()
    time.sleep(120)
'''

_PARENT = '''
import sys
sys.path.insert(0, sys.argv[1])
import stall
from ccproof.scale.processes import process_pool
with process_pool(2) as ex:
    list(ex.map(stall.task, [sys.argv[2]] * 2))
'''


def _alive(pid):
    try:
        with open(f"/proc/{pid}/status") as fh:
            return not any(line.startswith("State:") and "Z" in line.split()[1] for line in fh)
    except FileNotFoundError:
        return False


def test_pool_workers_end_when_their_parent_is_killed(tmp_path):
    (tmp_path / "stall.py").write_text(_STALL)
    marks = tmp_path / "marks"
    marks.mkdir()
    env = dict(os.environ, PYTHONPATH=ROOT + os.pathsep + os.environ.get("PYTHONPATH", ""))
    parent = subprocess.Popen([sys.executable, "-c", _PARENT, str(tmp_path), str(marks)], env=env)
    try:
        for _ in range(1200):
            if len(os.listdir(marks)) == 2 or parent.poll() is not None:
                break
            time.sleep(0.05)
        workers = [int(p) for p in os.listdir(marks)]
        assert len(workers) == 2, "the workers did not start"
        parent.send_signal(signal.SIGKILL)
        parent.wait()
        t0 = time.perf_counter()
        while any(_alive(w) for w in workers) and time.perf_counter() - t0 < 10:
            time.sleep(0.1)
        left = [w for w in workers if _alive(w)]
    finally:
        if parent.poll() is None:
            parent.kill()
    for w in left:  # clean up after a failure
        os.kill(w, signal.SIGKILL)
    assert not left, f"workers {left} outlived their parent by 10 s"
