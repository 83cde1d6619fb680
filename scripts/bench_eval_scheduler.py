"""Peak memory and wall time of ``ccproof eval`` on the default scheduler against ``--serial``, same points.

Each run is a fresh ``python -m ccproof.cli eval MESH --samples N --chunk C --out ...`` whose process tree (the
command, a local Dask cluster's nannies and workers, any other child) is sampled every ``--interval`` seconds
(/proc/PID/smaps_rollup): the peak of the sum of the processes' RSS (a shared page counted in every process that
maps it) and the peak of the sum of their PSS (a shared page divided among the processes that map it: the
memory the tree takes from the machine; shared memory that no process maps is not counted, but the evaluator
maps what it shares). The parent's own ``ru_maxrss`` is printed as well. The runs of the two schedulers take
turns (``--rounds``); ratios are per round.

The mesh is either given or the scan-like icosphere of ``scripts/bench_memory.py`` (level 6: 81,920 triangles,
level 7: 327,680).

Usage::

    python scripts/bench_eval_scheduler.py --level 6 --samples 1000000 --chunk 250000
    python scripts/bench_eval_scheduler.py --mesh scan.obj --samples 2000000
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _bench import load, ratio_line  # noqa: E402
from bench_memory import _env, icosphere, write_obj  # noqa: E402


def _tree(pid):
    """The pids of ``pid`` and its descendants (from /proc/*/stat)."""
    children: dict = {}
    for d in os.listdir("/proc"):
        if not d.isdigit():
            continue
        try:
            with open(f"/proc/{d}/stat") as fh:
                ppid = int(fh.read().rsplit(")", 1)[1].split()[1])
        except (OSError, ValueError, IndexError):
            continue
        children.setdefault(ppid, []).append(int(d))
    out, todo = [], [pid]
    while todo:
        p = todo.pop()
        out.append(p)
        todo.extend(children.get(p, ()))
    return out


def _rss_pss(pid):
    """(RSS, PSS) bytes of one process (0, 0 when it is gone)."""
    rss = pss = 0
    try:
        with open(f"/proc/{pid}/smaps_rollup") as fh:
            for line in fh:
                if line.startswith("Rss:"):
                    rss = int(line.split()[1]) * 1024
                elif line.startswith("Pss:"):
                    pss = int(line.split()[1]) * 1024
    except OSError:
        pass
    return rss, pss


def run_sampled(cmd, interval):
    """Run ``cmd``; returns (seconds, peak sum RSS, peak sum PSS, most processes, stdout)."""
    t0 = time.perf_counter()
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=_env())
    peak_rss = peak_pss = most = 0
    while proc.poll() is None:
        pids = _tree(proc.pid)
        sums = [_rss_pss(p) for p in pids]
        peak_rss = max(peak_rss, sum(s[0] for s in sums))
        peak_pss = max(peak_pss, sum(s[1] for s in sums))
        most = max(most, len(pids))
        time.sleep(interval)
    out = proc.stdout.read()
    seconds = time.perf_counter() - t0
    if proc.returncode != 0:
        raise SystemExit(f"{' '.join(cmd)} failed ({proc.returncode}):\n{out[-3000:]}")
    return seconds, peak_rss, peak_pss, most, out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--mesh", help="mesh file (default: the icosphere of --level)")
    ap.add_argument("--level", type=int, default=6, help="icosphere level (6: 81,920 triangles; 7: 327,680)")
    ap.add_argument("--samples", type=int, default=1_000_000)
    ap.add_argument("--chunk", type=int, default=250_000, help="points per task (several tasks: the workers run)")
    ap.add_argument("--rounds", type=int, default=1)
    ap.add_argument("--interval", type=float, default=0.05, help="seconds between two samples of the tree")
    ap.add_argument("--smoke", action="store_true", help="level 2, 4,000 samples in 2 chunks (the tests' run)")
    args = ap.parse_args(argv)
    if args.smoke:
        args.level, args.samples, args.chunk = 2, 4000, 2000
    print(f"python {sys.version.split()[0]}, load {os.getloadavg()}, {os.cpu_count()} cores (shared machine)")
    with tempfile.TemporaryDirectory() as tmp:
        mesh = args.mesh
        if mesh is None:
            V, F = icosphere(args.level)
            mesh = str(Path(tmp) / f"icosphere{args.level}.obj")
            write_obj(mesh, V, F)
            print(f"icosphere level {args.level}: {F.shape[0]} triangles")
        base = [sys.executable, "-m", "ccproof.cli", "eval", mesh, "--samples", str(args.samples), "--chunk",
                str(args.chunk), "--out", str(Path(tmp) / "out.npz"), "--no-progress"]
        ratios, times, loads = [], [], []
        for r in range(args.rounds):
            row = {}
            for name, extra in (("default", []), ("--serial", ["--serial"])):
                loads.append(load())
                row[name] = run_sampled(base + extra, args.interval)
                s, rss, pss, most, out = row[name]
                print(f"round {r} {name:>8}: {s:6.1f} s, peak sum PSS {pss / 1e9:.3f} GB, peak sum RSS "
                      f"{rss / 1e9:.3f} GB ({most} processes)", flush=True)
                for line in out.splitlines():
                    if line.startswith(("evaluated", mesh)):
                        print(f"    {line}")
            ratios.append(row["default"][2] / row["--serial"][2])
            times.append(row["default"][0] / row["--serial"][0])
        loads.append(load())
        print(ratio_line("peak PSS default/--serial:", ratios, loads))
        print(ratio_line("wall time default/--serial:", times, loads))
    return 0


if __name__ == "__main__":
    sys.exit(main())
