"""Evaluation speed on scan-like triangle meshes against OpenSubdiv Bfr (and Far where it builds), with the
machine's roofline: compute, bandwidth and latency bounds measured in the same run.

The meshes are those of ``scripts/bench_memory.py``: an icosphere refined L times (L = 5, 6, 7: 20,480 /
81,920 / 327,680 triangles), every vertex moved radially by 1% noise. For each mesh, in one process pinned to
one CPU, ours (the default compiled kernel, one thread) and Bfr (a prepared Surface per face, approximation level
10) and, up to ``--far-max-triangles``, Far (adaptive isolation level 10) evaluate P, Pu, Pv at the same 10^6
random points (uniform over the ptex faces, in random order) in turns, round by round; the ratio ours / Bfr is
taken per round (min, median, max; the load beside it). Setup times (in this process, mesh read excluded) are
printed once per mesh.

The roofline line of each mesh states three bounds of this machine for the same points, one thread:

* compute: the evaluator's own arithmetic on one net held in registers (``ideal`` of ``scripts/bench_ideal.c``);
* bandwidth: read bandwidth of one core / the 92 bytes a point must move (face, u, v in; P, Pu, Pv out);
* latency: the same ideal arithmetic, but each point first gathers the 16-point net of its own face from a
  table holding one net per ptex face of this mesh (``ideal_gather``: 384 B per face, the points' own order):
  what a table that stores every net (as Far's does) reaches when its data come from memory; with the latency
  of one dependent miss (a random pointer chase through 256 MiB) beside it. Ours stores less than a net per
  face and computes the net from the face's ring, so it can be above this bound.

Usage::

    python scripts/bench_scans.py                       # L = 5 6 7, 10^6 points, 5 rounds
    python scripts/bench_scans.py --levels 5 6 --rounds 7
    python scripts/bench_scans.py --smoke               # the test suite's run (tiny)

OpenSubdiv is loaded through ``scripts/_osd.py`` (``apt-get install libosd-dev g++``); without it our side is
measured alone.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _bench import missing, ratio_line  # noqa: E402
from bench_evaluate import (  # noqa: E402
    _ideal_lib,
    _Pinned,
    chase_latency,
    gather_case,
    hardware_bounds,
    interleaved,
    roofline_line,
    uniform_points,
)
from bench_memory import icosphere, write_obj  # noqa: E402

from ccproof.evaluate import available_backends  # noqa: E402
from ccproof.evaluate import natural_limit_surface as limit_surface  # noqa: E402
from ccproof.mesh import read_mesh  # noqa: E402


def scan_mesh(level, folder):
    """The icosphere scan of ``level`` written as OBJ into ``folder`` and read back."""
    V, F = icosphere(level)
    path = Path(folder) / f"icosphere{level}.obj"
    write_obj(path, V, F)
    return read_mesh(path), F.shape[0]


def osd_evaluators(mesh, n_tri, far_max):
    """{"bfr": ..., "far": ...} (Far only up to ``far_max`` triangles) with their setup seconds, or ({}, {})."""
    import _osd

    why = _osd.why_unavailable()
    if why:
        missing("OpenSubdiv", why)
        return {}, {}
    lib = _osd.load()
    ev, setup = {}, {}
    for kind, kw in (("bfr", {"approx": 10}), ("far", {})):
        if kind == "far" and n_tri > far_max:
            print(f"   far: skipped above {far_max:,} triangles (its level-10 table: ~75 kB per ptex face)")
            continue
        w0 = time.perf_counter()
        ev[kind] = _osd.Evaluator(lib, kind, mesh, **kw)
        setup[kind] = time.perf_counter() - w0
    return ev, setup


def one_mesh(level, n, rounds, far_max, bounds, folder):
    """Setup, interleaved rounds and the roofline line of one scan; returns ours / bfr per round."""
    mesh, n_tri = scan_mesh(level, folder)
    w0 = time.perf_counter()
    S = limit_surface(mesh)
    ours_setup = time.perf_counter() - w0
    ev, setup = osd_evaluators(mesh, n_tri, far_max)
    print(f"\nicosphere L={level}: {n_tri:,} triangles, {S.n_faces:,} ptex faces; setup ours "
          f"{ours_setup:.2f} s" + "".join(f", {k} {v:.2f} s" for k, v in setup.items()))
    f, s, t = uniform_points(mesh, n, np.random.default_rng(level))
    be = available_backends()[0]
    out = {k: np.empty((n, 3)) for k in ("P", "Pu", "Pv")}
    cases = {"ours": lambda: S.evaluate(f, s, t, 1, out=out, backend=be, threads=1)}
    for k, e in ev.items():
        o = tuple(np.empty((n, 3)) for _ in range(3))
        cases[k] = lambda e=e, o=o: e.evaluate(f, s, t, out=o)
    lib, table = _ideal_lib(), 0
    if lib is not None:
        cases["gather"], table = gather_case(lib, S.n_faces, f, s, t)
    for c in cases.values():
        c()
    cpu = {}
    with _Pinned():
        times, load = interleaved(cases, rounds, cpu)
    rate = {k: n / np.asarray(v) for k, v in times.items()}
    for k in ev:
        print(ratio_line(f"   ours ({be}) / {k}, {n:,} points, one pinned CPU:", rate["ours"] / rate[k], load))
        print(ratio_line(f"   the same in CPU time (other processes' time left out), ours / {k}:",
                         np.asarray(cpu[k]) / np.asarray(cpu["ours"]), load))
    if "bfr" in ev:
        dP = np.abs(ev["bfr"].evaluate(f[:1000], s[:1000], t[:1000])[0] - out["P"][:1000]).max()
        print(f"   max |P ours - P bfr| on 1,000 points: {dP:.1e} (Bfr approximates at extraordinary vertices)")
    compute, memory, latency_s = bounds
    gather = float(np.median(rate["gather"])) if "gather" in rate else None
    print("   " + roofline_line(float(np.median(rate["ours"])), compute, memory, gather, table, latency_s))
    for e in ev.values():
        e.close()
    return rate["ours"] / rate["bfr"] if "bfr" in rate else None


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--levels", type=int, nargs="+", default=[5, 6, 7], help="icosphere levels (default 5 6 7)")
    ap.add_argument("--points", type=int, default=1_000_000)
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--far-max-triangles", type=int, default=5_120,
                    help="build Far only up to this many triangles (default 5,120; 20,480 needs ~5 GB)")
    ap.add_argument("--smoke", action="store_true", help="the test suite's run: L = 2, 20,000 points, 2 rounds")
    args = ap.parse_args(argv)
    if args.smoke:
        args.levels, args.points, args.rounds = [2], 20_000, 2
    compute, memory, _ = hardware_bounds(quick=args.smoke)
    lib = _ideal_lib()
    latency = chase_latency(lib, 32 if args.smoke else 256) if lib is not None else float("nan")
    print(f"this machine, one thread: compute bound {compute / 1e6:.1f} M points/s, bandwidth bound "
          f"{memory / 1e6:.1f} M points/s, dependent miss {latency * 1e9:.0f} ns")
    summary = []
    with tempfile.TemporaryDirectory() as folder:
        for level in args.levels:
            r = one_mesh(level, args.points, args.rounds, args.far_max_triangles, (compute, memory, latency), folder)
            if r is not None:
                summary.append((level, r))
    for level, r in summary:
        print(f"L={level}: ours / bfr median {np.median(r):.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
