"""Serial vs a local Dask cluster: certification sweep, verification, batch evaluation, cluster overhead.

Every sweep runs twice through the ``ccproof`` command line, once with ``--serial`` and once on a
LocalCluster of ``--workers`` single-threaded worker processes (started once, timed separately), and
the outputs are compared byte for byte (certificates) or to the bit (evaluation shards).

  python scripts/bench_scale.py                          # certify 3-39, verify them, 1e8 points (long)
  python scripts/bench_scale.py --valences 3-8 --points 2000000   # reduced size (docs/scale-out.md)

Needs the optional extra ``scale`` (pip install 'ccproof[scale]').
"""

from __future__ import annotations

import argparse
import contextlib
import io
import logging
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _noop(task):
    return task


def _quiet(fn, *a):
    """Run fn(*a) with its stdout captured (the progress bars go to stderr)."""
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        t0 = time.perf_counter()
        rc = fn(*a)
        dt = time.perf_counter() - t0
    return rc, dt, buf.getvalue()


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--valences", default="3-39", help="certify sweep (default 3-39)")
    ap.add_argument("--points", type=float, default=1e8, help="points of the evaluation (default 1e8)")
    ap.add_argument("--chunk", type=int, default=1_000_000, help="points per task (default 1e6)")
    ap.add_argument("--mesh", default=str(ROOT / "tests" / "data" / "meshes" / "bunny_quads.obj"))
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--skip", nargs="*", default=[], choices=["certify", "verify", "eval"])
    ap.add_argument("--smoke", action="store_true",
                    help="one worker, 40,000 points on catmark_smoothtris1, no certify or verify (the suite's run)")
    args = ap.parse_args(argv)
    if args.smoke:
        args.workers, args.points, args.chunk, args.skip = 1, 4e4, 20_000, ["certify", "verify"]
        args.mesh = str(ROOT / "tests" / "data" / "osd_features" / "meshes" / "catmark_smoothtris1.obj")
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from _bench import load, missing, ratio_line

    try:
        import distributed
    except ImportError:
        missing("a Dask cluster", "the optional extra scale is not installed: pip install 'ccproof[scale]'")
        from ccproof.scale import run_tasks

        ser = run_tasks(_noop, range(200), "serial", progress=False)
        print(f"our side, serial: 200 empty tasks in {ser.seconds:.3f} s")
        return
    import numpy as np

    from ccproof.cli import main as ccproof
    from ccproof.scale import read_shards, run_tasks

    rows = []
    load0 = load()
    t0 = time.perf_counter()
    cluster = distributed.LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True,
                                       dashboard_address=None, silence_logs=logging.ERROR)
    client = distributed.Client(cluster)
    client.wait_for_workers(args.workers)
    start = time.perf_counter() - t0
    addr = cluster.scheduler_address
    print(f"LocalCluster of {args.workers} worker processes started in {start:.2f} s", flush=True)

    # overhead per task: 200 empty tasks, serial and on the cluster
    n = 200
    ser = run_tasks(_noop, range(n), "serial", progress=False)
    dist = run_tasks(_noop, range(n), client, progress=False)
    print(f"tiny job, {n} empty tasks: serial {ser.seconds * 1e3:.1f} ms, cluster {dist.seconds * 1e3:.0f} ms "
          f"({dist.seconds / n * 1e3:.2f} ms per task)", flush=True)
    rows.append(("cluster start-up", start, None))
    rows.append((f"{n} empty tasks", ser.seconds, dist.seconds))

    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        if "certify" not in args.skip:
            a, b = tmp / "serial", tmp / "cluster"
            _, ts, _ = _quiet(ccproof, ["certify", args.valences, "--serial", "--no-verify", "--out", str(a)])
            _, tc, _ = _quiet(ccproof, ["certify", args.valences, "--scheduler", addr, "--no-verify", "--out", str(b)])
            files = sorted(a.glob("*.json"))
            same = all(f.read_bytes() == (b / f.name).read_bytes() for f in files)
            print(f"certify {args.valences}: serial {ts:.1f} s, cluster {tc:.1f} s, speed-up {ts / tc:.2f}x; "
                  f"{len(files)} certificates byte-identical: {same}", flush=True)
            rows.append((f"certify {args.valences}", ts, tc))
            if "verify" not in args.skip:
                fl = [str(f) for f in files]
                rs, ts, out_s = _quiet(ccproof, ["verify", *fl, "--quiet", "--serial"])
                rc, tc, out_c = _quiet(ccproof, ["verify", *fl, "--quiet", "--scheduler", addr])
                verdicts = [ln.split()[0] for ln in out_s.splitlines() if ln.startswith(("VERIFIED", "FAILED"))]
                same = verdicts == [ln.split()[0] for ln in out_c.splitlines()
                                    if ln.startswith(("VERIFIED", "FAILED"))]
                print(f"verify {len(fl)} certificates: serial {ts:.1f} s, cluster {tc:.1f} s, speed-up "
                      f"{ts / tc:.2f}x; same verdicts: {same} (exit {rs}, {rc})", flush=True)
                rows.append((f"verify {len(fl)} files", ts, tc))
        if "eval" not in args.skip:
            pts = str(int(args.points))
            common = ["eval", args.mesh, "--samples", pts, "--chunk", str(args.chunk), "--derivatives", "1"]
            # serial on one thread (one core, as the certify and verify sweeps), then serial with the
            # evaluator's own threads on every core, against the cluster's workers (one thread each)
            _, t1, _ = _quiet(ccproof, [*common, "--serial", "--threads", "1", "--out", str(tmp / "e1")])
            _, ts, _ = _quiet(ccproof, [*common, "--serial", "--out", str(tmp / "es")])
            _, tc, _ = _quiet(ccproof, [*common, "--scheduler", addr, "--out", str(tmp / "ec")])
            e1, es, ec = read_shards(tmp / "e1"), read_shards(tmp / "es"), read_shards(tmp / "ec")
            same = all(np.array_equal(es[k].blocks[i].compute(), ec[k].blocks[i].compute())
                       and np.array_equal(e1[k].blocks[i].compute(), ec[k].blocks[i].compute())
                       for k in ("P", "Pu", "Pv") for i in range(es[k].numblocks[0]))
            print(f"evaluate {pts} points: serial 1 thread {t1:.1f} s, serial all threads {ts:.1f} s, cluster "
                  f"{tc:.1f} s, speed-up {t1 / tc:.2f}x over one thread ({ts / tc:.2f}x over the threaded "
                  f"process); identical to the bit: {same}", flush=True)
            rows.append((f"evaluate {pts} points (serial: 1 thread)", t1, tc))
            rows.append((f"evaluate {pts} points (serial: all threads)", ts, tc))
    client.close()
    cluster.close()
    timed = [(s, c) for _, s, c in rows if c is not None]
    print(ratio_line("serial/cluster time, over the jobs:", [s / c for s, c in timed], [load0, load()]))
    print("\n| job | serial (s) | cluster (s) | speed-up |\n|---|---|---|---|")
    for name, s, c in rows:
        print(f"| {name} | {s:.2f} | {'' if c is None else f'{c:.2f}'} | "
              f"{'' if c is None else f'{s / c:.2f}x'} |")


if __name__ == "__main__":
    main()
