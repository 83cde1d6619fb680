"""How fast ``ccproof eval`` stops when signalled while its local Dask cluster starts.

Each round runs ``ccproof eval cube.obj --samples 4 --chunk 2 --scheduler local:2`` in a new session. A
``sitecustomize`` (on ``PYTHONPATH`` of the command only) leaves a mark when the command spawns its first
process, that is inside the cluster's start; ``--delay`` seconds later the round sends

* ``int``: SIGINT to the whole process group (a terminal's Ctrl-C),
* ``term``: SIGTERM to the command,
* ``kill``: SIGKILL to the command alone (its workers must end by themselves),

and prints the seconds from the signal to the command's exit and to the moment no process of its session is left
(workers, multiprocessing's resource tracker), the exit status, the lines on stderr and the processes of the
session left 1 s after the exit.

The baseline, measured in the same rounds (alternating): an unsignalled run of the same command, from its mark
to the cluster being up (its ``workers ready`` line): the rest of the start, which a deferred signal waits for.
Ratio = (signal to no process left) / (mark to workers ready).

Usage::

    python scripts/bench_stop.py --rounds 3
    python scripts/bench_stop.py --how kill --rounds 3
"""

from __future__ import annotations

import argparse
import os
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _bench import load, missing, ratio_line  # noqa: E402

_SITE = '''
import os, time
if os.environ.get("BENCH_STOP_MARK") and not os.environ.get("BENCH_STOP_SPAWNED"):
    import multiprocessing.util as mpu, pathlib
    original = mpu.spawnv_passfds
    def spawn(path, args, passfds):  # (stays installed: a hook of the command may wrap it)
        if not os.environ.get("BENCH_STOP_SPAWNED"):
            os.environ["BENCH_STOP_SPAWNED"] = "1"  # (not inherited by this child: its environment is built)
            pathlib.Path(os.environ["BENCH_STOP_MARK"]).write_text(repr(time.time()))
        return original(path, args, passfds)
    mpu.spawnv_passfds = spawn
'''

_READY = '''
import os, time
if os.environ.get("BENCH_STOP_READY"):
    import distributed, pathlib
    _init = distributed.Client.__init__
    def init(self, *a, **k):
        _init(self, *a, **k)
        pathlib.Path(os.environ["BENCH_STOP_READY"]).write_text(repr(time.time()))
    distributed.Client.__init__ = init
'''

CUBE = "\n".join(
    ["v -1 -1 -1", "v 1 -1 -1", "v 1 1 -1", "v -1 1 -1", "v -1 -1 1", "v 1 -1 1", "v 1 1 1", "v -1 1 1",
     "f 1 4 3 2", "f 5 6 7 8", "f 1 2 6 5", "f 2 3 7 6", "f 3 4 8 7", "f 4 1 5 8"]) + "\n"


def _session(sid):
    """The live (not zombie) processes of session ``sid``."""
    out = []
    for d in os.listdir("/proc"):
        if d.isdigit():
            try:
                with open(f"/proc/{d}/stat") as fh:
                    stat = fh.read()
            except OSError:
                continue
            fields = stat[stat.rindex(")") + 2:].split()
            if int(fields[3]) == sid and fields[0] != "Z":
                out.append(int(d))
    return out


def _start(tmp, env):
    repo = Path(__file__).resolve().parents[1]
    code = "import signal, sys; signal.signal(signal.SIGINT, signal.default_int_handler)\n" \
           "from ccproof.cli import main; sys.exit(main(sys.argv[1:]))"
    env = dict(os.environ, PYTHONPATH=f"{tmp / 'site'}{os.pathsep}{repo}", **env)
    return subprocess.Popen([sys.executable, "-c", code, "eval", "cube.obj", "--samples", "4", "--chunk", "2",
                             "--scheduler", "local:2", "--out", "o.npz"], cwd=tmp, env=env, text=True,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True)


def _wait_for(path, proc, seconds=120.0):
    end = time.time() + seconds
    while time.time() < end and not path.exists() and proc.poll() is None:
        time.sleep(0.005)
    while path.exists() and not path.read_text() and time.time() < end:  # (being written)
        time.sleep(0.005)
    return float(path.read_text()) if path.exists() and path.read_text() else None


def signalled(tmp, how, delay):
    """((seconds from the signal to the command's exit, to no process of its session left), status, stderr lines,
    processes left 1 s later)."""
    mark = tmp / "mark"
    mark.unlink(missing_ok=True)
    proc = _start(tmp, {"BENCH_STOP_MARK": str(mark)})
    try:
        if _wait_for(mark, proc) is None:
            raise SystemExit(f"the command never spawned a process: {proc.communicate()[1]}")
        time.sleep(delay)
        t0 = time.perf_counter()
        if how == "int":
            os.killpg(proc.pid, signal.SIGINT)
        else:
            proc.send_signal(signal.SIGTERM if how == "term" else signal.SIGKILL)
        while proc.poll() is None and time.perf_counter() - t0 < 120:
            time.sleep(0.005)
        exited = time.perf_counter() - t0
        while _session(proc.pid) and time.perf_counter() - t0 < 120:
            time.sleep(0.005)
        seconds = (exited, time.perf_counter() - t0)
        err = proc.communicate(timeout=120)[1]
        time.sleep(1.0)
        left = _session(proc.pid)
    finally:
        if proc.poll() is None or _session(proc.pid):
            with_killpg(proc.pid)
    return seconds, proc.returncode, err.strip().splitlines(), left


def with_killpg(pid):
    try:
        os.killpg(pid, signal.SIGKILL)
    except ProcessLookupError:
        pass


def rest_of_start(tmp):
    """Seconds from the first spawn to the cluster's client connected, unsignalled."""
    mark, ready = tmp / "mark", tmp / "ready"
    for p in (mark, ready):
        p.unlink(missing_ok=True)
    proc = _start(tmp, {"BENCH_STOP_MARK": str(mark), "BENCH_STOP_READY": str(ready)})
    try:
        t_mark = _wait_for(mark, proc)
        t_ready = _wait_for(ready, proc)
        proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            with_killpg(proc.pid)
    if t_mark is None or t_ready is None:
        raise SystemExit("the unsignalled run did not start its cluster")
    return t_ready - t_mark


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--how", choices=("int", "term", "kill"), default="int")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--delay", type=float, default=0.1, help="seconds from the first spawn to the signal")
    ap.add_argument("--verbose", action="store_true", help="print the command's stderr")
    ap.add_argument("--smoke", action="store_true", help="one round")
    args = ap.parse_args()
    rounds = 1 if args.smoke else args.rounds
    import importlib.util

    if importlib.util.find_spec("distributed") is None:
        missing("a local Dask cluster", "the extra 'scale' is not installed: pip install 'ccproof[scale]'")
        print("no cluster start to signal: nothing measured")
        return 0
    ratios, loads = [], []
    with tempfile.TemporaryDirectory() as d:
        tmp = Path(d)
        (tmp / "site").mkdir()
        (tmp / "site" / "sitecustomize.py").write_text(_SITE + _READY)
        (tmp / "cube.obj").write_text(CUBE)
        for r in range(rounds):
            loads.append(load())
            seconds, rc, lines, left = signalled(tmp, args.how, args.delay)
            rest = rest_of_start(tmp)
            tail = lines[-1] if lines else ""
            if args.verbose:
                print("\n".join(lines))
            print(f"round {r}: SIG{args.how.upper()} {args.delay:.2f} s after the first spawn: exit {rc} after "
                  f"{seconds[0]:.2f} s, no process after {seconds[1]:.2f} s, {len(lines)} stderr line(s) "
                  f"(last: {tail!r}), {len(left)} process(es) left; unsignalled: rest of the start {rest:.2f} s",
                  flush=True)
            ratios.append(seconds[1] / rest)
    print(ratio_line("signal to no process left / rest of the cluster start (what a deferred signal waited):",
                     ratios, loads))
    return 0


if __name__ == "__main__":
    sys.exit(main())
