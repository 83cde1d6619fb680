#!/usr/bin/env python
"""Benchmark of exact limit evaluation (ccproof.evaluate) on the quad-remeshed Stanford bunny.

Measures, in one run:

1. points per second for positions + first derivatives at 10^6 random (face, u, v) on
   ``bunny_quads.obj`` (2,036 quads, 103 extraordinary vertices), for every backend of this install
   (numpy; numba where installed; the C kernel where built); wall-clock and CPU-time rates (the
   CPU-time rate is the single-thread rate even on a loaded machine);
2. (a) a straightforward per-point implementation (Python loop over points, the same tables)
   on a subsample, extrapolated to the same number of points: ratio;
3. (b) uniform Catmull-Clark subdivision with pygel3d (if installed) level by level: time,
   size, and accuracy of the level-L control points as surface points (distance to their own
   limit positions, relative to the bounding-box diagonal), extrapolated to the level that would
   reach the accuracy of exact evaluation;
4. the peak memory beyond inputs and outputs for 10^7 points (tracemalloc);
5. side by side with OpenSubdiv in this process (``scripts/_osd.py`` builds ``scripts/osd_capi.cpp``
   against the system's OpenSubdiv 3.5+, Debian ``apt-get install -y libosd-dev g++``, and loads it with
   ctypes; skipped with that instruction without it): Far (adaptive isolation level 10, Gregory end caps,
   PatchMap, EvaluateBasis) and Bfr (a prepared Surface per face, approximation level 10), on the bunny, a
   crease shape and a triangle shape. Setup times, and points/s for 10^6 uniform points and 10^6 points
   within 10^-3 (in u and v) of the corners at extraordinary vertices; Far, Bfr, our numpy path and
   compiled kernels (C and numba) take turns round by round (at least 7 rounds; min, median, max; the
   1-minute load before each round), the process pinned to one CPU; the ratio to Far is taken per round.
   Also this machine's two bounds on one thread (ideal compiled work on one net, ``scripts/bench_ideal.c``
   built with gcc -O3 -march=native -ffast-math: compute; read bandwidth / 92 bytes: memory), the fraction
   of each reached, and the largest position difference; then, unpinned, the default kernel on all CPUs
   against one thread next to this machine's ceiling: ideal compiled work of the same shape (the same
   points, each reading its face id, u, v and writing P, Pu, Pv; ``ideal_points`` of bench_ideal.c) on one
   thread against split into equal parts over the threads, in the same interleaved rounds (2 x rounds + 1),
   the ratio taken per round; with the CPU seconds of the threaded run over the one-thread run (what each
   core loses when all are busy) and the threads' occupancy (CPU over threads x wall: idling, imbalance,
   other processes);
6. start-up in fresh processes, ours (each compiled backend) and OpenSubdiv Far's: seconds and peak resident
   memory (VmHWM) after importing, the setup, loading the kernel (ours: a first evaluation of one point) and one
   evaluation of 10^6 points.
   Then what ``import ccproof`` (with the evaluator and the mesh reader) and the kernel load add over
   ``python -c 'import numpy'`` (fresh processes in turn, round by round: seconds from start to exit and
   peak memory, per round against the floor of the same round), against the target of 0.3 s and 50 MiB.

The bunny mesh is read from the repository's test data (``tests/data/meshes/bunny_quads.obj``).

Usage: python scripts/bench_evaluate.py [--points 1000000] [--memory-points 10000000] [--quick] [--osd-only]
[--setup-only] [--setup-in-process]  (``--setup-in-process``: only the setup after imports in this process,
ours/Far in CPU time, alternating; ``--setup-only``: only the setup in a fresh process, imports and reading the
OBJ included:
ours, ``python -c`` with the per-configuration disk cache filled and empty, against OpenSubdiv Far's setup as
a program of its own, ``scripts/osd_setup_driver.cpp``, reading the same OBJ; every process timed from start
to exit, in turn round by round; and the floors of a Python process: ``python -c pass``, numpy's import,
ours)
[--threads-only]  (only part 5's threads against one thread with the machine's ceiling; no OpenSubdiv;
about a minute)
[--startup]  (``--startup``: only part 6, start-up and peak memory of fresh processes, ours against Far, and
the import's cost over ``python -c 'import numpy'``)
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time
import tracemalloc
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(Path(__file__).resolve().parent))  # scripts/_osd.py
from _bench import missing, ratio_line  # noqa: E402

from ccproof.evaluate import natural_limit_surface as limit_surface  # noqa: E402
from ccproof.evaluate.backend import available_backends  # noqa: E402
from ccproof.evaluate.local import CORNERS  # noqa: E402
from ccproof.mesh import limit_normals, limit_positions, read_obj, subdivide  # noqa: E402
from ccproof.mesh.io import read_mesh  # noqa: E402

# ------------------------------------------------------------------ 5. side by side with OpenSubdiv
SHAPES = [("bunny", REPO / "tests" / "data" / "meshes" / "bunny_quads.obj"),
          ("cubes_infsharp", REPO / "tests" / "data" / "osd_features" / "meshes" / "catmark_cubes_infsharp.obj"),
          ("smoothtris1", REPO / "tests" / "data" / "osd_features" / "meshes" / "catmark_smoothtris1.obj")]
#: P + Pu + Pv of a bicubic patch: 16-term sums of 3 coordinates for 3 quantities plus the basis
FLOPS_PER_POINT = 310
#: bytes per point that must move at least: (face, u, v) in (4 + 16), P, Pu, Pv out (72)
BYTES_PER_POINT = 92


def extraordinary_corners(mesh):
    """(ptex face, corner) pairs whose corner vertex is extraordinary: an interior vertex with other than
    4 faces, a boundary vertex with other than 2, or the centre of an n-gon (n != 4; valence n after the
    first step). Ptex corner c of a quad is its vertex c; of the sub-face k of an n-gon, corner 0 is the
    n-gon's vertex k, corner 2 its centre, corners 1 and 3 edge midpoints (valence 4 or boundary 2)."""
    fc, bnd = mesh.face_count, mesh.is_boundary_vertex
    ev = np.where(bnd, fc != 2, fc != 4)
    faces, corners = [], []
    for f, poly in enumerate(mesh.polygons):
        if mesh.is_hole[f]:
            continue
        p0 = int(mesh.ptex_start[f])
        if len(poly) == 4:
            for c, v in enumerate(poly):
                if ev[v]:
                    faces.append(p0)
                    corners.append(c)
        else:
            for k, v in enumerate(poly):
                if ev[v]:
                    faces.append(p0 + k)
                    corners.append(0)
                faces.append(p0 + k)  # the centre (valence != 4)
                corners.append(2)
    return np.array(faces, dtype=np.int64), np.array(corners, dtype=np.int64)


def near_ev_points(mesh, n, rng, within=1e-3):
    """n points within ``within`` (in u and v) of a corner at an extraordinary vertex (uniform over the
    pairs of :func:`extraordinary_corners` and over the square of side ``within`` at the corner)."""
    pf, pc = extraordinary_corners(mesh)
    k = rng.integers(0, pf.size, n)
    cu, cv = np.array(CORNERS, dtype=np.float64)[pc[k]].T
    a, b = within * rng.random(n), within * rng.random(n)
    return pf[k], np.where(cu > 0, 1.0 - a, a), np.where(cv > 0, 1.0 - b, b), pf.size


def uniform_points(mesh, n, rng):
    """n points uniform over the ptex faces that are not holes."""
    ok = np.flatnonzero(np.repeat(~mesh.is_hole, np.where(mesh.sizes == 4, 1, mesh.sizes)))
    return ok[rng.integers(0, ok.size, n)], rng.random(n), rng.random(n)


def _loadavg():
    import os

    return os.getloadavg()[0]


class _Pinned:
    """Pin this process to one CPU (the last one it may use) for the one-thread comparisons."""

    def __enter__(self):
        import os

        self.before = os.sched_getaffinity(0)
        self.cpu = max(self.before)
        os.sched_setaffinity(0, {self.cpu})
        return self

    def __exit__(self, *exc):
        import os

        os.sched_setaffinity(0, self.before)


def interleaved(cases, rounds, cpu=None):
    """Run every case once per round, in turn, ``rounds`` times; seconds per case and round, and the
    1-minute load before each round. ``cpu`` (a dict): also the CPU seconds of this thread per case and round
    (the cases run on the calling thread: on a loaded machine the time it was not scheduled is left out)."""
    times = {name: [] for name in cases}
    if cpu is not None:
        cpu.update({name: [] for name in cases})
    load = []
    for r in range(rounds):
        load.append(_loadavg())
        names = list(cases)
        names = names[r % len(names):] + names[:r % len(names)]  # rotate who goes first
        for name in names:
            c0, w0 = time.thread_time(), time.perf_counter()
            cases[name]()
            times[name].append(time.perf_counter() - w0)
            if cpu is not None:
                cpu[name].append(time.thread_time() - c0)
    return times, load


def chase_latency(lib, mib=256, steps=2_000_000):
    """Seconds per dependent load of a random cycle through ``mib`` MiB (one miss each once it outgrows the
    caches): ``chase`` of bench_ideal.c."""
    import ctypes

    lib.chase.argtypes = [ctypes.c_int64, ctypes.c_void_p]
    lib.chase.restype = ctypes.c_int64
    n = (mib << 20) // 8
    order = np.random.default_rng(7).permutation(n)
    nxt = np.empty(n, dtype=np.int64)
    nxt[order] = np.roll(order, -1)  # one cycle through every entry
    lib.chase(min(steps, n), nxt.ctypes.data)  # warm the page tables
    w0 = time.perf_counter()
    lib.chase(steps, nxt.ctypes.data)
    return (time.perf_counter() - w0) / steps


def gather_case(lib, n_faces, f, s, t):
    """A callable running ``ideal_gather`` (bench_ideal.c) on the points (f, s, t) with a table of one random
    net per ptex face, and the table's bytes: the latency bound of a table that stores every net."""
    import ctypes

    lib.ideal_gather.argtypes = [ctypes.c_int64] + [ctypes.c_void_p] * 7
    lib.ideal_gather.restype = None
    nets = np.random.default_rng(3).random((n_faces, 48))
    f, s, t = (np.ascontiguousarray(a) for a in (np.asarray(f, dtype=np.int64), s, t))
    out = [np.empty((f.size, 3)) for _ in range(3)]
    keep = (f, s, t, nets, *out)  # alive as long as the callable (it passes their addresses)
    return lambda: lib.ideal_gather(f.size, *(a.ctypes.data for a in keep)), nets.nbytes


def roofline_line(rate, compute, memory, gather=None, table=0, latency_s=float("nan")):
    """One line: the median rate ``rate`` (points/s) against the compute, bandwidth and (``gather``: the median
    rate of :func:`gather_case` on the same points, its table ``table`` bytes) latency bounds."""
    line = (f"roofline: ours {rate / 1e6:.2f} M points/s = {rate / compute:.1%} of compute, {rate / memory:.1%} of "
            "bandwidth")
    if gather:
        line += (f", {rate / gather:.2f}x the latency bound ({gather / 1e6:.2f} M points/s gathering one net per face "
                 f"from {table / 2**20:.1f} MiB; one dependent miss {latency_s * 1e9:.0f} ns)")
    return line


def _ideal_lib():
    """``scripts/bench_ideal.c`` compiled with gcc (-O3 -march=native -ffast-math) into the temp folder and
    loaded (ctypes), or None without gcc."""
    import ctypes
    import hashlib
    import shutil
    import subprocess
    import tempfile

    src = Path(__file__).with_name("bench_ideal.c")
    if shutil.which("gcc") is None:
        return None
    code = src.read_bytes()
    so = Path(tempfile.gettempdir()) / f"ccproof_bench_ideal-{hashlib.sha256(code).hexdigest()[:16]}.so"
    if not so.exists():
        tmp = so.with_suffix(f".{os.getpid()}.tmp.so")
        r = subprocess.run(["gcc", "-O3", "-march=native", "-ffast-math", "-shared", "-fPIC", str(src), "-o",
                            str(tmp)], capture_output=True, text=True)
        if r.returncode != 0:
            return None
        tmp.replace(so)
    lib = ctypes.CDLL(str(so))
    lib.ideal.argtypes = [ctypes.c_int64] + [ctypes.c_void_p] * 6
    lib.ideal.restype = None
    lib.ideal_points.argtypes = [ctypes.c_int64] + [ctypes.c_void_p] * 7
    lib.ideal_points.restype = None
    return lib


def _ideal_c():
    """``ideal(s, t, net, P, Pu, Pv)`` of ``scripts/bench_ideal.c`` (see :func:`_ideal_lib`), or None without
    gcc."""
    lib = _ideal_lib()
    if lib is None:
        return None

    def ideal(s, t, net, P, Pu, Pv):
        lib.ideal(s.size, *(a.ctypes.data for a in (s, t, net, P, Pu, Pv)))

    return ideal


def hardware_bounds(quick=False):
    """The two bounds of this machine for P + Pu + Pv, in points/s on one thread:

    * compute: the evaluator's own arithmetic on one bicubic net held in registers/L1 (the 16-term sums
      of ``bspline_basis``), compiled with every freedom (scripts/bench_ideal.c: gcc -O3 -march=native
      -ffast-math, vectorized across points; numba without gcc), no gather, no table: ideal compiled work;
    * memory: read bandwidth of one core (summing a 256 MiB array) / BYTES_PER_POINT.
    """
    ideal = _ideal_c()
    if ideal is None:
        ideal = _ideal_numba()
    n = 200_000 if quick else 2_000_000
    rng = np.random.default_rng(1)
    s, t, net = rng.random(n), rng.random(n), rng.random((16, 3))
    P, Pu, Pv = (np.empty((n, 3)) for _ in range(3))
    ideal(s[:4], t[:4], net, P, Pu, Pv)
    a = np.ones((32 << 20) // (8 if quick else 1))  # 256 MiB (quick: 32 MiB)
    with _Pinned():
        times, _ = interleaved({"ideal": lambda: ideal(s, t, net, P, Pu, Pv), "read": lambda: a.sum()},
                               3 if quick else 7)
    compute = n / min(times["ideal"])
    bandwidth = a.nbytes / min(times["read"])
    return compute, bandwidth / BYTES_PER_POINT, bandwidth


def _ideal_numba():
    """The ideal loop of :func:`hardware_bounds` in numba (scalar: no fastmath), where gcc is missing."""
    import numba

    @numba.njit(nogil=True, inline="always")
    def basis(z):
        w = 1.0 - z
        z2 = z * z
        z3 = z2 * z
        return (w * w * w / 6.0, (3.0 * z3 - 6.0 * z2 + 4.0) / 6.0, (-3.0 * z3 + 3.0 * z2 + 3.0 * z + 1.0) / 6.0,
                z3 / 6.0, -0.5 * w * w, 1.5 * z2 - 2.0 * z, -1.5 * z2 + z + 0.5, 0.5 * z2)

    @numba.njit(nogil=True)
    def ideal(s, t, net, P, Pu, Pv):
        for i in range(s.size):
            b0, b1, b2, b3, d0, d1, d2, d3 = basis(s[i])
            c0, c1, c2, c3, e0, e1, e2, e3 = basis(t[i])
            for c in range(3):
                a0 = b0 * net[0, c] + b1 * net[1, c] + b2 * net[2, c] + b3 * net[3, c]
                a1 = b0 * net[4, c] + b1 * net[5, c] + b2 * net[6, c] + b3 * net[7, c]
                a2 = b0 * net[8, c] + b1 * net[9, c] + b2 * net[10, c] + b3 * net[11, c]
                a3 = b0 * net[12, c] + b1 * net[13, c] + b2 * net[14, c] + b3 * net[15, c]
                g0 = d0 * net[0, c] + d1 * net[1, c] + d2 * net[2, c] + d3 * net[3, c]
                g1 = d0 * net[4, c] + d1 * net[5, c] + d2 * net[6, c] + d3 * net[7, c]
                g2 = d0 * net[8, c] + d1 * net[9, c] + d2 * net[10, c] + d3 * net[11, c]
                g3 = d0 * net[12, c] + d1 * net[13, c] + d2 * net[14, c] + d3 * net[15, c]
                P[i, c] = c0 * a0 + c1 * a1 + c2 * a2 + c3 * a3
                Pu[i, c] = c0 * g0 + c1 * g1 + c2 * g2 + c3 * g3
                Pv[i, c] = e0 * a0 + e1 * a1 + e2 * a2 + e3 * a3

    return ideal


def _print_rates(n, times, cpu, bounds, default, gather, table):
    """The lines of one case of :func:`osd_side_by_side`: per implementation its rate and its ratio to Far, round
    by round, in wall-clock and in CPU time (the pinned thread's: the time other processes took the CPU left out),
    and the roofline line of ``default`` (``bounds``: compute and bandwidth in points/s, a dependent miss in s).
    Returns the per-round ratios to Far, wall-clock and CPU time."""
    compute, memory, latency_s = bounds
    rate = {k: n / np.asarray(v) for k, v in times.items()}
    ratio = {k: rate[k] / rate["far"] for k in rate}  # per round: the same round's Far
    for k in rate:
        lo, md, hi = _stats(rate[k])
        rlo, rmd, rhi = _stats(ratio[k])
        b = f"; {md / compute:5.1%} of compute bound, {md / memory:5.1%} of memory bound" if compute else ""
        print(f"      {k:6s} {md / 1e6:6.2f} M points/s (min {lo / 1e6:.2f}, max {hi / 1e6:.2f}); "
              f"/ far: median {rmd:.2f} ({rlo:.2f}-{rhi:.2f}){b}")
    cpu_ratio = {k: np.asarray(cpu["far"]) / np.asarray(cpu[k]) for k in cpu if k != "far"}
    print("      in CPU time / far, median (min-max): " + ", ".join(
        f"{k} {np.median(r):.2f} ({r.min():.2f}-{r.max():.2f})" for k, r in cpu_ratio.items()))
    if compute:
        print("      " + roofline_line(float(np.median(rate[default])), compute, memory, gather, table, latency_s))
    return ratio, cpu_ratio


def setup_in_process(rounds=15):
    """Setup after imports, in this process (the disk cache and the kept arrays warm): ours (``limit_surface``)
    against OpenSubdiv Far (refiner, adaptive patch table, patch map, local points; the C API of scripts/_osd.py)
    on every mesh of :data:`SHAPES`, alternating round by round; the CPU time of this thread (a loaded machine's
    waits left out): ours/Far per round, min, median, max, and each side's best."""
    print("\nsetup in this process after imports (mesh read; disk cache warm), CPU time of this thread")
    import _osd

    why = _osd.why_unavailable()
    if why:
        missing("OpenSubdiv", why)
        return
    lib = _osd.load()
    for label, path in SHAPES:
        mesh = read_mesh(path)
        limit_surface(mesh)  # warm-up: the disk cache filled, the per-process kept arrays
        _osd.Evaluator(lib, "far", mesh).close()
        cpu = {}
        _, load = interleaved({"far": lambda m=mesh: _osd.Evaluator(lib, "far", m).close(),
                               "ours": lambda m=mesh: limit_surface(m)}, rounds, cpu=cpu)
        print(ratio_line(f"   {label}: setup ours/far CPU time (best: ours {min(cpu['ours']) * 1e3:.2f} ms, far "
                         f"{min(cpu['far']) * 1e3:.2f} ms):", np.array(cpu["ours"]) / np.array(cpu["far"]), load))


def _stats(x):
    x = np.asarray(x, dtype=float)
    return float(x.min()), float(np.median(x)), float(x.max())


def osd_side_by_side(n, rng, quick=False, rounds=7):
    """OpenSubdiv Far and Bfr in this process (scripts/_osd.py, ctypes), alternating with ours round by
    round on one pinned CPU; returns the table rows."""
    print("\n5. side by side with OpenSubdiv in this process (positions + first derivatives)")
    import _osd

    why = _osd.why_unavailable()
    if why:
        missing("OpenSubdiv", why)
        return None
    lib = _osd.load()
    import os

    threads = len(os.sched_getaffinity(0))
    rounds = 2 if quick else rounds
    compute, memory, bw = hardware_bounds(quick)
    ideal_lib = _ideal_lib()
    latency_s = chase_latency(ideal_lib, 32 if quick else 256) if ideal_lib is not None else float("nan")
    print(f"   this machine, one thread: ideal compiled work {compute / 1e6:.1f} M points/s (compute bound); "
          f"read bandwidth {bw / 2**30:.1f} GiB/s / {BYTES_PER_POINT} B = {memory / 1e6:.1f} M points/s "
          f"(memory bound); one dependent miss {latency_s * 1e9:.0f} ns")
    default = available_backends()[0]  # what evaluate uses without backend=
    print(f"   backends: {', '.join(available_backends())} (default {default})")
    rows = []
    for label, path in SHAPES:
        mesh = read_mesh(path)
        # setup, in this process: OpenSubdiv Far (refiner + adaptive patch table + patch map + local points),
        # Bfr (factory + a prepared Surface per face), ours (the evaluator; the disk cache is warm after the
        # first build); interleaved
        limit_surface(mesh)
        st, _ = interleaved({"far": lambda m=mesh: _osd.Evaluator(lib, "far", m).close(),
                             "bfr": lambda m=mesh: _osd.Evaluator(lib, "bfr", m, approx=10).close(),
                             "ours": lambda m=mesh: limit_surface(m)}, 3 if quick else rounds)
        far_setup = min(st["far"])
        print(f"   {label}: setup in this process (mesh read, imports done): far {far_setup * 1e3:.1f} ms, bfr "
              f"{min(st['bfr']) * 1e3:.1f} ms, ours {min(st['ours']) * 1e3:.1f} ms "
              f"({min(st['ours']) / far_setup:.1f}x far; in a fresh process: --setup-only)")
        S = limit_surface(mesh)
        far = _osd.Evaluator(lib, "far", mesh)
        bfr = _osd.Evaluator(lib, "bfr", mesh, approx=10)
        diag = mesh.bounding_box_diagonal
        fu, su, tu = uniform_points(mesh, n, rng)
        fn, sn, tn, npairs = near_ev_points(mesh, n, rng)
        for dist, (f, s, t) in (("uniform", (fu, su, tu)), ("near EVs", (fn, sn, tn))):
            outs = {k: tuple(np.empty((n, 3)) for _ in range(3)) for k in ("far", "bfr", "c", "numba", "numpy")}

            def ours(be, th, key, f=f, s=s, t=t, outs=outs, S=S):
                o = outs[key]
                S.evaluate(f, s, t, 1, out={"P": o[0], "Pu": o[1], "Pv": o[2]}, backend=be, threads=th)

            cases = {"far": lambda f=f, s=s, t=t, o=outs["far"], e=far: e.evaluate(f, s, t, out=o),
                     "bfr": lambda f=f, s=s, t=t, o=outs["bfr"], e=bfr: e.evaluate(f, s, t, out=o),
                     "numpy": lambda: ours("numpy", 1, "numpy")}
            if _has_numba():
                cases["numba"] = lambda: ours("numba", 1, "numba")
            if "c" in available_backends():
                cases["c"] = lambda: ours("c", 1, "c")
            table = 0
            if ideal_lib is not None:
                cases["gather"], table = gather_case(ideal_lib, mesh.n_faces, f, s, t)
            for c in cases.values():  # warm up (compile)
                c()
            cpu = {}
            with _Pinned():
                times, load = interleaved(cases, rounds, cpu)
            gather = float(np.median(n / np.asarray(times.pop("gather")))) if "gather" in times else None
            cpu.pop("gather", None)
            oP = outs["far"][0]
            P = outs[default][0]
            dP = np.abs(P - oP).max() / diag
            dB = np.abs(outs["bfr"][0] - oP).max() / diag
            med_dP = float(np.median(np.abs(P - oP).max(axis=1))) / diag
            extra = f", {npairs} extraordinary corners" if dist != "uniform" else ""
            print(f"   {label}, {dist} ({n:,} points{extra}); load {min(load):.2f}-{max(load):.2f}; "
                  f"{rounds} rounds, one pinned CPU")
            ratio, cpu_ratio = _print_rates(n, times, cpu, (compute, memory, latency_s), default, gather, table)
            two = None
            if default != "numpy" and threads > 1:
                two = two_threads(lambda th: ours(default, th, default), f, s, t, threads, 2 * rounds + 1)
                _print_two(two, threads)
            print(f"      max |P ours - P far| / diagonal {dP:.1e} (median over points {med_dP:.1e}); "
                  f"bfr (approximation level 10) vs far {dB:.1e}; Far's Gregory end caps at extraordinary "
                  f"vertices are approximations")
            rows.append((label, dist, {k: _stats(r) for k, r in ratio.items()}, two, load,
                         {k: _stats(r) for k, r in cpu_ratio.items()}))
        far.close()
        bfr.close()
    return rows


_STARTUP_OURS = """
import json, os, sys, time
t = [time.perf_counter()]
def hwm():
    return int([x for x in open("/proc/self/status") if x.startswith("VmHWM")][0].split()[1]) / 1024
m = [hwm()]
import numpy as np
t.append(time.perf_counter()); m.append(hwm())
import ccproof.evaluate.surface as surface
from ccproof.evaluate import available_backends
from ccproof.mesh.io import read_mesh
t.append(time.perf_counter()); m.append(hwm())
S = surface.natural_limit_surface(read_mesh(sys.argv[1]))
t.append(time.perf_counter()); m.append(hwm())
name = available_backends()[0] if os.environ.get("CCPROOF_BACKEND", "auto") == "auto" else \
    os.environ["CCPROOF_BACKEND"]
S.evaluate([0], [0.5], [0.5], 1, threads=1)  # the first call loads the backend's kernel
t.append(time.perf_counter()); m.append(hwm())
d = np.load(sys.argv[2])
f, s, u = d["f"], d["s"], d["t"]
t.append(time.perf_counter()); m.append(hwm())
S.evaluate(f, s, u, 1, threads=1)
t.append(time.perf_counter()); m.append(hwm())
print(json.dumps({"t": t, "m": m, "backend": name, "numba": "numba" in sys.modules, "scipy": "scipy" in sys.modules}))
"""

_STARTUP_OSD = """
import json, sys, time
t = [time.perf_counter()]
def hwm():
    return int([x for x in open("/proc/self/status") if x.startswith("VmHWM")][0].split()[1]) / 1024
m = [hwm()]
import numpy as np
t.append(time.perf_counter()); m.append(hwm())
sys.path.insert(0, sys.argv[3])
import _osd
lib = _osd.load()
t.append(time.perf_counter()); m.append(hwm())
t.append(time.perf_counter()); m.append(hwm())
d = np.load(sys.argv[1], allow_pickle=True)
far = _osd.Evaluator(lib, "far", d["mesh"].item())
t.append(time.perf_counter()); m.append(hwm())
d = np.load(sys.argv[2])
f, s, u = d["f"], d["s"], d["t"]
t.append(time.perf_counter()); m.append(hwm())
far.evaluate(f, s, u)
t.append(time.perf_counter()); m.append(hwm())
print(json.dumps({"t": t, "m": m, "backend": "far"}))
"""


def startup_and_memory(path, n, rng, env_backends=("c", "numba")):
    """Fresh processes, ours against OpenSubdiv Far: the steps import numpy, import (ours: the evaluator
    and the mesh reader; Far: the compiled C API), setup (the mesh, read by ours, given as arrays to Far) and
    kernel load (ours: after the setup, a first evaluation of one point loads the backend's kernel; Far: none),
    the points, then one evaluation of ``n`` points (P + Pu + Pv, one thread); seconds and the peak resident
    memory (VmHWM of /proc/self/status, MiB) after each."""
    import json
    import os
    import subprocess
    import tempfile

    import _osd

    print(f"\n6. start-up and memory in fresh processes ({n:,} points, P + Pu + Pv, one thread); "
          f"load {_loadavg():.2f}")
    mesh = read_mesh(path)
    f, s, t = uniform_points(mesh, n, rng)
    with tempfile.TemporaryDirectory() as d:
        pts = os.path.join(d, "points.npz")
        np.savez(pts, f=f, s=s, t=t)
        runs = {}
        env0 = {k: v for k, v in os.environ.items() if k != "CCPROOF_BACKEND"}
        for be in env_backends:
            if be != "numpy" and be not in available_backends():
                continue
            env = dict(env0, CCPROOF_BACKEND=be, PYTHONPATH=os.pathsep.join([str(REPO), env0.get("PYTHONPATH", "")]))
            r = subprocess.run([sys.executable, "-c", _STARTUP_OURS, str(path), pts], capture_output=True, text=True,
                               env=env, check=True)
            runs[f"ours ({be})"] = json.loads(r.stdout)
        if not _osd.why_unavailable():
            arr = os.path.join(d, "mesh.npz")
            np.savez(arr, mesh=np.array(_osd.mesh_arrays(mesh), dtype=object))
            r = subprocess.run([sys.executable, "-c", _STARTUP_OSD, arr, pts, str(Path(__file__).resolve().parent)],
                               capture_output=True, text=True, env=env0, check=True)
            runs["OpenSubdiv Far"] = json.loads(r.stdout)
    for name, r in runs.items():
        tt, mm = r["t"], r["m"]
        # ours sets up before loading its kernel (a first evaluation of one point); Far has no kernel load
        steps = ["import numpy", "import", "setup", "kernel load", "points", "evaluate"] if "numba" in r else \
            ["import numpy", "import", "kernel load", "setup", "points", "evaluate"]
        parts = ", ".join(f"{st} {tt[i + 1] - tt[i]:.3f} s -> {mm[i + 1]:.0f} MiB" for i, st in enumerate(steps))
        extra = f" (numba imported: {r['numba']}, scipy: {r['scipy']})" if "numba" in r else ""
        print(f"   {name}: {parts}{extra}")
    base = runs.get("OpenSubdiv Far")
    for name, r in runs.items():
        if base is None or r is base:
            continue
        imp = (r["t"][2] - r["t"][1] + r["t"][4] - r["t"][3], r["m"][2] - r["m"][1] + r["m"][4] - r["m"][3])
        print(f"   {name}: import + kernel load {imp[0]:.3f} s, +{imp[1]:.0f} MiB above numpy; peak "
              f"{r['m'][-1]:.0f} MiB vs OpenSubdiv's {base['m'][-1]:.0f} MiB (+{r['m'][-1] - base['m'][-1]:.0f} MiB); "
              f"before evaluating {r['m'][-3]:.0f} vs {base['m'][-3]:.0f} MiB")
    return runs


#: the import targets: a fresh ``python -c`` that imports numpy (the floor), against one that also imports
#: ccproof, the evaluator and the mesh reader and loads the evaluation kernel (by a first evaluation of one point on
#: the 16-quad torus of ccproof.mesh.examples: its small setup is counted too); each prints
#: its peak resident memory (VmHWM, MiB) as it exits
_HWM = "print(int([x for x in open('/proc/self/status') if x.startswith('VmHWM')][0].split()[1]) / 1024)"
_IMPORT_FLOOR = "import numpy; " + _HWM
_IMPORT_OURS = ("import numpy, ccproof, ccproof.evaluate.surface as s; from ccproof.mesh.io import read_mesh; "
                "from ccproof.mesh.examples import torus; "
                "s.natural_limit_surface(torus()).evaluate([0], [0.5], [0.5], threads=1); " + _HWM)
#: what the import and the kernel load may add over ``python -c 'import numpy'``: seconds, MiB
IMPORT_TARGET = (0.3, 50.0)


def import_over_numpy(rounds=7, backends=("c", "numba")):
    """What ``import ccproof`` with the evaluator and the mesh reader and the kernel load add over
    ``python -c 'import numpy'``: fresh processes, each timed from start to exit here, the floor and ours
    (per backend, ``CCPROOF_BACKEND``) in turn round by round; per round the difference of the seconds and of
    the peak resident memory (VmHWM) against the floor of the same round; min, median, max. Our modules'
    bytecode is written once before (as an installed package has it).

    Returns
    -------
    dict
        backend -> ((min, median, max) added seconds, (min, median, max) added MiB).
    """
    import os
    import subprocess

    env = dict(os.environ, PYTHONPATH=str(REPO) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    env.pop("CCPROOF_BACKEND", None)
    mem = {}

    def run(code, name, backend=None):
        e = env if backend is None else dict(env, CCPROOF_BACKEND=backend)
        r = subprocess.run([sys.executable, "-c", code], env=e, capture_output=True, text=True)
        if r.returncode != 0:
            raise RuntimeError(f"{name} failed: {r.stderr[-2000:]}")
        mem.setdefault(name, []).append(float(r.stdout.split()[-1]))

    cases = {"numpy": lambda: run(_IMPORT_FLOOR, "numpy")}
    for be in backends:
        if be not in available_backends():
            continue
        run(_IMPORT_OURS, "warm-up", be)  # writes our bytecode
        cases[be] = lambda be=be: run(_IMPORT_OURS, be, be)
    mem.clear()
    times, load = interleaved(cases, rounds)
    floor_t, floor_m = np.asarray(times["numpy"]), np.asarray(mem["numpy"])
    print(f"   import ccproof (evaluator, mesh reader) + kernel load over python -c 'import numpy' (fresh processes, "
          f"{rounds} rounds in turn, load {min(load):.2f}-{max(load):.2f}; python -c 'import numpy': median "
          f"{np.median(floor_t):.3f} s, {np.median(floor_m):.0f} MiB):")
    out = {}
    for be in cases:
        if be == "numpy":
            continue
        dt = _stats(np.asarray(times[be]) - floor_t)
        dm = _stats(np.asarray(mem[be]) - floor_m)
        met = dt[1] <= IMPORT_TARGET[0] and dm[1] <= IMPORT_TARGET[1]
        print(f"   {be}: +{dt[1]:.3f} s (min {dt[0]:.3f}, max {dt[2]:.3f}), +{dm[1]:.0f} MiB (min {dm[0]:.0f}, max "
              f"{dm[2]:.0f}); target <= {IMPORT_TARGET[0]} s and <= {IMPORT_TARGET[1]:.0f} MiB (median): "
              f"{'met' if met else 'not met'}")
        out[be] = (dt, dm)
    return out


#: our side of the fresh-process setup: what ``ccproof eval`` does before evaluating (imports, reading the
#: file, building the patch table), in a ``python -c`` of its own
_OURS_SETUP = ("import sys; from ccproof.mesh.io import read_mesh; "
               "from ccproof.evaluate import natural_limit_surface as ls; ls(read_mesh(sys.argv[1]), progress=False)")
_FLOORS = {"python -c pass": "pass", "python -c 'import numpy'": "import numpy",
           "our imports": "from ccproof.mesh.io import read_mesh; from ccproof.evaluate import natural_limit_surface"}


def fresh_process_setup(rounds=7):
    """Setup in a fresh process, imports included (our modules' bytecode written once, as an installed package
    has it): ours (``python -c``: imports, read the OBJ, build) with the
    per-configuration disk cache filled and empty (a new folder every round) against OpenSubdiv Far's driver
    (``scripts/osd_setup_driver.cpp``: a program that reads the same OBJ, refines adaptively to level 10 and
    builds the patch table, its local points and the patch map), each process timed end to end from here
    (start to exit), round by round in turn; ratios per round. Also the floors of a Python process."""
    import os
    import subprocess
    import tempfile

    import _osd

    print("\nsetup in a fresh process, imports and reading the OBJ included (ours: python -c; Far: "
          "scripts/osd_setup_driver.cpp), each timed from start to exit")
    why = _osd.why_unavailable()
    if why:
        print(f"   {why}. Skipped.")
        return None
    exe = str(_osd.setup_driver())
    env = dict(os.environ, PYTHONPATH=str(REPO) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    # our modules' bytecode, as an installed package has it (pip compiles on install): without it every
    # fresh process compiles our sources again (~0.1 s); the first run below writes __pycache__
    env.pop("PYTHONDONTWRITEBYTECODE", None)

    def run(cmd, cache=None):
        e = env if cache is None else dict(env, CCPROOF_CACHE=cache)
        w0 = time.perf_counter()
        r = subprocess.run(cmd, env=e, capture_output=True, text=True)
        dt = time.perf_counter() - w0
        if r.returncode != 0:
            raise RuntimeError(f"{cmd[0]} failed: {r.stderr[-2000:]}")
        return dt, r.stdout

    rows = []
    with tempfile.TemporaryDirectory() as filled, tempfile.TemporaryDirectory() as root:
        for label, path in SHAPES:
            # the driver reads the OBJ itself: check that it sees the mesh of the in-process C API
            mesh = read_mesh(path)
            _, out = run([exe, str(path), "0", "0.3", "0.6"])
            n_ptex, _, *p = out.split()
            lib = _osd.load()
            ref = _osd.Evaluator(lib, "far", mesh)
            P = ref.evaluate(np.array([0]), np.array([0.3]), np.array([0.6]))[0][0]
            ref.close()
            ok = int(n_ptex) == mesh.n_ptex and np.abs(np.array(p, dtype=float) - P).max() <= 1e-12
            if not ok:
                raise RuntimeError(f"osd_setup_driver reads {path.name} differently from the C API: {out}")
            run([sys.executable, "-c", _OURS_SETUP, str(path)], filled)  # fills the cache (and __pycache__)
            folders = iter(range(1 << 30))

            def empty(path=path, folders=folders, label=label):
                d = os.path.join(root, f"{label}-{next(folders)}")  # a new, empty cache every round
                return run([sys.executable, "-c", _OURS_SETUP, str(path)], d)

            cases = {"far": lambda path=path: run([exe, str(path), "0", "0.5", "0.5"]),
                     "filled": lambda path=path: run([sys.executable, "-c", _OURS_SETUP, str(path)], filled),
                     "empty": empty}
            times, load = interleaved(cases, rounds)
            far = np.asarray(times["far"])
            r_f = _stats(np.asarray(times["filled"]) / far)
            r_e = _stats(np.asarray(times["empty"]) / far)
            print(f"   {label} ({mesh.n_faces} faces, {mesh.n_ptex} ptex faces); {rounds} rounds, load "
                  f"{min(load):.2f}-{max(load):.2f}: far {_stats(far)[1] * 1e3:.1f} ms (median); ours, disk cache "
                  f"filled {_stats(times['filled'])[1] * 1e3:.0f} ms, empty {_stats(times['empty'])[1] * 1e3:.0f} ms; "
                  f"ours / far: filled median {r_f[1]:.1f}x (min {r_f[0]:.1f}, max {r_f[2]:.1f}), empty median "
                  f"{r_e[1]:.1f}x (min {r_e[0]:.1f}, max {r_e[2]:.1f})")
            rows.append((label, _stats(far), r_f, r_e))
    fl, load = interleaved({k: (lambda c=c: run([sys.executable, "-c", c])) for k, c in _FLOORS.items()}, rounds)
    print("   floors of a Python process (median): " + ", ".join(f"{k} {_stats(v)[1] * 1e3:.0f} ms"
                                                             for k, v in fl.items()))
    return rows


def two_threads(ours, f, s, t, threads, rounds):
    """``threads`` threads against one, for the default kernel and for this machine's ceiling, in the same
    interleaved rounds (the order rotating): ``ours(th)`` evaluates the points ``f, s, t`` on ``th`` threads;
    the ceiling is ideal compiled work of the same shape (``ideal_points`` of scripts/bench_ideal.c: the same
    points, each reading its face id, u and v and writing P, Pu, Pv, the arithmetic of one bicubic net held
    in L1) on one thread against the points split into ``threads`` equal contiguous parts, one per thread
    (ctypes releases the GIL). Per round: the wall-clock ratio (1 thread / n), the process CPU seconds of
    the n-thread run over the 1-thread run (above 1: each core does less per second when all are busy,
    e.g. a lower clock, shared caches or memory, or a host's hyperthread sibling) and the n-thread run's CPU
    seconds over n times its wall-clock seconds (below 1: threads idle or descheduled: load imbalance,
    serial parts, other processes). The ratio is about n x that occupancy / that CPU factor.

    Returns
    -------
    dict
        ``"ours"``, ``"ceiling"`` -> dict with ``"speedup"``, ``"cpu"``, ``"busy"``: (min, median, max) over
        the rounds.
    """
    from concurrent.futures import ThreadPoolExecutor

    lib = _ideal_lib()
    n = f.size
    nets = np.random.default_rng(3).random((16, 16, 3))
    outs = [np.empty((n, 3)) for _ in range(3)]
    if lib is not None:
        def ideal(lo, hi):
            lib.ideal_points(hi - lo, *(a[lo:].ctypes.data for a in (f, s, t)), nets.ctypes.data,
                             *(o[lo:].ctypes.data for o in outs))
    else:  # numba's scalar loop on one net (nogil)
        loop = _ideal_numba()

        def ideal(lo, hi):
            loop(s[lo:hi], t[lo:hi], nets[0], *(o[lo:hi] for o in outs))
    cuts = np.linspace(0, n, threads + 1).astype(np.int64)
    with ThreadPoolExecutor(threads) as ex:
        cases = {"ceiling 1": lambda: ideal(0, n),
                 f"ceiling {threads}": lambda: list(ex.map(ideal, cuts[:-1], cuts[1:])),
                 "ours 1": lambda: ours(1), f"ours {threads}": lambda: ours(threads)}
        for c in cases.values():  # warm up (thread pools, caches, pages)
            c()
        wall = {k: [] for k in cases}
        cpu = {k: [] for k in cases}
        for r in range(rounds):
            names = list(cases)
            names = names[r % len(names):] + names[:r % len(names)]
            for k in names:
                c0, w0 = time.process_time(), time.perf_counter()
                cases[k]()
                wall[k].append(time.perf_counter() - w0)
                cpu[k].append(time.process_time() - c0)
    out = {}
    for who in ("ours", "ceiling"):
        w1, wn = np.asarray(wall[f"{who} 1"]), np.asarray(wall[f"{who} {threads}"])
        c1, cn = np.asarray(cpu[f"{who} 1"]), np.asarray(cpu[f"{who} {threads}"])
        out[who] = {"speedup": _stats(w1 / wn), "cpu": _stats(cn / np.maximum(c1, 1e-9)),
                    "busy": _stats(cn / (threads * wn))}
    return out


def threads_only(n, rng, rounds=7):
    """Only the two-thread comparison of part 5 (:func:`two_threads`, ``2 rounds + 1`` rounds) on the rows of
    part 5 (the same shapes and points), without OpenSubdiv."""
    threads = len(os.sched_getaffinity(0))
    default = available_backends()[0]
    print(f"\n{threads} threads against one ({n:,} points, P + Pu + Pv, backend {default}); load {_loadavg():.2f}")
    if threads < 2 or default == "numpy":
        print("   one CPU, or no compiled kernel: skipped")
        return None
    rows = []
    for label, path in SHAPES:
        mesh = read_mesh(path)
        S = limit_surface(mesh)
        pts = {"uniform": uniform_points(mesh, n, rng), "near EVs": near_ev_points(mesh, n, rng)[:3]}
        for dist, (f, s, t) in pts.items():
            o = {k: np.empty((n, 3)) for k in ("P", "Pu", "Pv")}

            def ours(th, f=f, s=s, t=t, o=o, S=S):
                S.evaluate(f, s, t, 1, out=o, threads=th)

            l0 = _loadavg()
            two = two_threads(ours, f, s, t, threads, 2 * rounds + 1)
            print(f"   {label}, {dist}; load {l0:.2f}-{_loadavg():.2f}")
            _print_two(two, threads)
            rows.append((label, dist, two))
    return rows


def _print_two(two, threads):
    o, c = two["ours"], two["ceiling"]
    print(f"      {threads} threads / 1 thread, median (min-max) over interleaved rounds: C kernel "
          f"{o['speedup'][1]:.2f} ({o['speedup'][0]:.2f}-{o['speedup'][2]:.2f}); this machine's ceiling "
          f"(ideal compiled work, same points and traffic) {c['speedup'][1]:.2f} "
          f"({c['speedup'][0]:.2f}-{c['speedup'][2]:.2f})")
    print(f"         CPU seconds {threads} threads / 1: C kernel {o['cpu'][1]:.2f}, ceiling {c['cpu'][1]:.2f}; "
          f"threads busy (CPU / ({threads} x wall)): C kernel {o['busy'][1]:.2f}, ceiling {c['busy'][1]:.2f}")


def _has_numba():
    try:
        import numba  # noqa: F401

        return True
    except ImportError:
        return False


def timed(fn, repeat=3):
    """Best wall and CPU seconds over ``repeat`` runs."""
    best_w, best_c = math.inf, math.inf
    for _ in range(repeat):
        w0, c0 = time.perf_counter(), time.process_time()
        fn()
        best_w = min(best_w, time.perf_counter() - w0)
        best_c = min(best_c, time.process_time() - c0)
    return best_w, best_c


# ------------------------------------------------------------------ (a) per-point implementation
#: the kinds of a template's virtual faces (``PatchTable.kind``, documented there)
CORNER, SPLIT = 1, 2


def _basis(x):
    t = 1.0 - x
    B = (t * t * t / 6, (3 * x**3 - 6 * x * x + 4) / 6, (-3 * x**3 + 3 * x * x + 3 * x + 1) / 6, x**3 / 6)
    D = (-0.5 * t * t, 1.5 * x * x - 2 * x, -1.5 * x * x + x + 0.5, 0.5 * x * x)
    return B, D


def naive_point(S, f, u, v):
    """One point at a time, plain Python on the same tables (the public ``S.patch_map.table`` of a surface
    built by :func:`natural_limit_surface`): locate, net, basis, 16-term sums."""
    T = S.patch_map.table
    job = int(T.top[f, int(u >= 0.5) + 2 * int(v >= 0.5)])
    vf = int(T.job_root[job])
    for _ in range(T.split_depth):
        if T.kind[vf] != SPLIT:
            break
        half = T.h[vf] * 0.5
        vf = int(T.child[vf, int(u >= T.u0[vf] + half) + 2 * int(v >= T.v0[vf] + half)])
    if T.kind[vf] == CORNER:
        U0, V0, H = T.u0[vf], T.v0[vf], T.h[vf]
        du = ((U0 + H) - u if T.cu[vf] else u - U0) / H
        dv = ((V0 + H) - v if T.cv[vf] else v - V0) / H
        mx = max(du, dv)
        cfg = int(T.cfg[vf])
        nmax = int(T.n_layers[cfg]) - 1
        n = min(max(-math.frexp(mx)[1], 0), nmax) if mx > 0 else nmax
        du, dv = math.ldexp(du, n), math.ldexp(dv, n)
        a, b = du >= 0.5, dv >= 0.5
        code = 0 if (a and not b) else 1 if (a and b) else 2 if b else 1
        Nc = int(T.op_size[cfg])
        o = int(T.op_start[cfg]) + (3 * n + code) * 16 * Nc
        ring = _ring_rows(T, job, vf, Nc - 1)
        ring = [[0.0] * 3] + [[ring[r][c] for c in range(3)] for r in range(Nc - 1)]  # row 0: the vertex
        ops = T.ops[o:o + 16 * Nc].tolist()
        net = [[sum(ops[16 * k + i] * ring[k][c] for k in range(Nc)) for c in range(3)] for i in range(16)]
        lim = _ring_rows(T, job, vf, 1, int(T.vn[vf]) * (Nc - 1))[0]  # the limit point less X[ring[0]]
        x0 = T.points[int(T.rings[int(T.job_ring[job])])].tolist()
        origin = [lim[c] + x0[c] for c in range(3)]
        sc = math.ldexp(H, -n)
        pu0 = T.unit[cfg, code, 0] * sc + (U0 + H if T.cu[vf] else U0)
        pv0 = T.unit[cfg, code, 1] * sc + (V0 + H if T.cv[vf] else V0)
        h = T.unit[cfg, code, 2] * sc
    else:
        rows = _ring_rows(T, job, vf, 17)
        x0 = T.points[int(T.rings[int(T.job_ring[job])])].tolist()
        net, origin = rows[:16], [rows[16][c] + x0[c] for c in range(3)]
        pu0, pv0, h = T.u0[vf], T.v0[vf], T.h[vf]
    s = min(max((u - pu0) / h, 0.0), 1.0)
    t = min(max((v - pv0) / h, 0.0), 1.0)
    Bs, Ds = _basis(s)
    Bt, Dt = _basis(t)
    P, Pu, Pv = list(origin), [0.0] * 3, [0.0] * 3
    for j in range(4):
        for i in range(4):
            w = net[i + 4 * j]
            for c in range(3):
                P[c] += Bs[i] * Bt[j] * w[c]
                Pu[c] += Ds[i] * Bt[j] * w[c] / h
                Pv[c] += Bs[i] * Dt[j] * w[c] / h
    return P, Pu, Pv


def _ring_rows(T, job, vf, m, skip=0):
    """The m rows ``sum_j op[j] (X[ring[j]] - X[ring[0]])`` of leaf ``vf`` of ``job`` (op: the (N, m) operator
    ``skip`` entries into its block of ``vop``), in plain Python."""
    N, st, r0 = int(T.vn[vf]), int(T.vop_start[vf]) + skip, int(T.job_ring[job])
    X = [T.points[int(T.rings[r0 + j])].tolist() for j in range(N)]
    op = T.vop[st:st + N * m].tolist()
    return [[sum(op[m * j + r] * (X[j][c] - X[0][c]) for j in range(1, N)) for c in range(3)] for r in range(m)]


def smoke(n=20_000, rounds=2):
    """The test suite's run: each backend against numpy on the bunny (interleaved rounds), then OpenSubdiv side by
    side (or the line saying it is missing)."""
    mesh = read_mesh(SHAPES[0][1])
    S = limit_surface(mesh)
    rng = np.random.default_rng(0)
    f, u, v = uniform_points(mesh, n, rng)
    backends = available_backends()
    for be in backends:
        S.evaluate(f[:10], u[:10], v[:10], 1, backend=be)  # numba: compile (cached on disk)
    times, load = interleaved({be: (lambda be=be: S.evaluate(f, u, v, 1, backend=be, threads=1)) for be in backends},
                              rounds)
    for be in backends[:-1]:
        print(ratio_line(f"bunny P + Pu + Pv, {n:,} points, {be}/numpy time:",
                         np.array(times[be]) / np.array(times["numpy"]), load))
    osd_side_by_side(n, rng, True, rounds=rounds)
    setup_in_process(rounds)
    return 0


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--points", type=int, default=1_000_000)
    ap.add_argument("--memory-points", type=int, default=10_000_000)
    ap.add_argument("--naive-points", type=int, default=2000)
    ap.add_argument("--pygel-levels", type=int, default=5)
    ap.add_argument("--quick", action="store_true", help="small sizes")
    ap.add_argument("--smoke", action="store_true",
                    help="the test suite's run: 20,000 points, each backend against numpy and OpenSubdiv, 2 rounds")
    ap.add_argument("--osd-points", type=int, default=1_000_000)
    ap.add_argument("--osd-only", action="store_true", help="only part 5 (OpenSubdiv side by side)")
    ap.add_argument("--rounds", type=int, default=7, help="interleaved rounds of part 5 (at least 7)")
    ap.add_argument("--setup-only", action="store_true", help="only the setup times of part 5")
    ap.add_argument("--setup-in-process", action="store_true",
                    help="only the setup after imports in this process, ours/Far in CPU time (--rounds, 15 or more)")
    ap.add_argument("--threads-only", action="store_true",
                    help="only part 5's two threads against one, with this machine's ceiling (no OpenSubdiv)")
    ap.add_argument("--startup", action="store_true",
                    help="only part 6: start-up times and peak memory in fresh processes, ours and OpenSubdiv's")
    args = ap.parse_args(argv)
    if args.smoke:
        return smoke()
    if args.setup_only:
        fresh_process_setup(args.rounds)
        return 0
    if args.setup_in_process:
        setup_in_process(args.rounds)
        return 0
    if args.threads_only:
        threads_only(args.osd_points if not args.quick else 20_000, np.random.default_rng(2024), args.rounds)
        return 0
    if args.startup:
        startup_and_memory(SHAPES[0][1], 1_000_000 if not args.quick else 20_000, np.random.default_rng(2024))
        import_over_numpy(args.rounds)
        return 0
    if args.osd_only:
        osd_side_by_side(args.osd_points if not args.quick else 20_000, np.random.default_rng(2024), args.quick,
                         rounds=args.rounds)
        startup_and_memory(SHAPES[0][1], 1_000_000 if not args.quick else 20_000, np.random.default_rng(2024))
        return 0
    if args.quick:
        args.points, args.memory_points, args.naive_points, args.pygel_levels = 20_000, 50_000, 200, 2

    path = REPO / "tests" / "data" / "meshes" / "bunny_quads.obj"
    mesh = read_obj(path)
    diag = mesh.bounding_box_diagonal
    print(f"mesh: {path.name}: {mesh.n_vertices} vertices, {mesh.n_faces} quads, "
          f"{mesh.extraordinary_vertices.size} extraordinary vertices (valences "
          f"{sorted(set(mesh.valence[mesh.extraordinary_vertices].tolist()))}), bbox diagonal {diag:.4g}")
    w0 = time.perf_counter()
    S = limit_surface(mesh)
    print(f"prepare (exact corner tables, local splits): {time.perf_counter() - w0:.2f} s; "
          f"{S.n_patches} stored patches, patch table {S.table_bytes / 2**20:.1f} MiB, deepest layer table "
          f"{S.max_layers}, split depth {S.split_depth}")

    rng = np.random.default_rng(2024)
    n = args.points
    f = rng.integers(0, mesh.n_faces, n)
    u, v = rng.random(n), rng.random(n)
    backends = available_backends()[::-1]  # numpy first: the reference
    for be in backends:
        S.evaluate(f[:10], u[:10], v[:10], 1, backend=be)  # numba: compile (cached on disk)
    rates = {}
    ref = None
    print(f"\n1. positions + first derivatives at {n:,} random points (best of 3)")
    for be in backends:
        out = {k: np.empty((n, 3)) for k in ("P", "Pu", "Pv")}
        w, c = timed(lambda be=be, out=out: S.evaluate(f, u, v, 1, out=out, backend=be))
        rates[be] = (n / w, n / c)
        print(f"   {be:6s}: {n / w / 1e6:6.2f} M points/s wall, {n / c / 1e6:6.2f} M points/s per CPU second")
        if ref is None:
            ref = {k: a.copy() for k, a in out.items()}
        else:
            dev = max(np.abs(out[k] - ref[k]).max() for k in out)
            print(f"           max |{be} - numpy| = {dev:.1e}")
    best = max(backends, key=lambda b: rates[b][1])

    # (a) per-point implementation
    m = args.naive_points
    c0 = time.process_time()
    res = [naive_point(S, int(f[i]), float(u[i]), float(v[i])) for i in range(m)]
    cn = time.process_time() - c0
    err = max(np.abs(np.array([r[0] for r in res]) - ref["P"][:m]).max(),
              np.abs(np.array([r[1] for r in res]) - ref["Pu"][:m]).max())
    print(f"\n2. (a) straightforward per-point loop on {m} points: {m / cn:,.0f} points per CPU second "
          f"(agrees to {err:.1e}); extrapolated to {n:,} points: {n / (m / cn):.1f} s CPU")
    for be in backends:
        print(f"       ratio {be} / per-point: {rates[be][1] / (m / cn):,.0f}x")

    # (b) uniform subdivision with pygel3d
    print("\n3. (b) uniform Catmull-Clark subdivision")
    try:
        from pygel3d import hmesh
    except ImportError:
        hmesh = None
        print("   pygel3d not installed (pip install pygel3d): library timings skipped")
    levels = []
    mm = mesh
    for L in range(1, args.pygel_levels + 1):
        mm = subdivide(mm)
        dev = mm.vertices - limit_positions(mm)
        drift = np.abs(dev).max() / diag  # distance to the own limit point (mostly tangential)
        acc = np.abs((dev * limit_normals(mm)).sum(axis=1)).max() / diag  # distance across the surface
        tg = None
        if hmesh is not None:
            g = hmesh.obj_load(str(path))
            c0 = time.process_time()
            for _ in range(L):
                hmesh.cc_subdivide(g)
            tg = time.process_time() - c0
            pos = g.positions()
            if L <= 3:  # same scheme: pygel3d's level-L points are ours
                from scipy.spatial import cKDTree

                d = cKDTree(mm.vertices).query(pos)[0].max() / diag
                if d > 1e-12:
                    print(f"   warning: pygel3d level {L} differs from the reference step by {d:.1e}")
        levels.append((L, mm.n_vertices, mm.n_faces, acc, tg))
        tg_s = f"{tg:7.3f} s" if tg is not None else "    n/a"
        ours = mm.n_vertices / rates[best][1]
        print(f"   level {L}: {mm.n_faces:>9,} quads, {mm.n_vertices:>9,} points, pygel3d {tg_s}; "
              f"control points {acc:.1e} x diagonal off the limit surface along the normal "
              f"({drift:.1e} from their limit points); exact evaluation of as many points: {ours:.3f} s")
    L, nv, nf, acc, tg = levels[-1]
    rate = math.log(levels[-2][3] / acc, 4) if len(levels) > 1 else 1.0
    target = 1e-13
    Lstar = L + math.log(acc / target, 4) / max(rate, 1e-9)
    print(f"   the normal distance shrinks by 4^{rate:.2f} at the last level; reaching {target:g} x diagonal "
          f"(exact evaluation is below it) needs level ~{Lstar:.1f}: ~{nf * 4 ** (Lstar - L):.2e} quads")
    if tg is not None:
        t_star = tg * 4 ** (Lstar - L)
        print(f"   extrapolated pygel3d time {t_star:.2e} s vs exact evaluation of 10^6 points "
              f"{1e6 / rates[best][1]:.3f} s: ratio {t_star / (1e6 / rates[best][1]):.1e}")
        ratio_same = tg / (nv / rates[best][1])
        print(f"   at level {L} ({nv:,} points, accuracy {acc:.0e}): pygel3d / exact evaluation time = "
              f"{ratio_same:.2f}")

    # 4. memory
    nm = args.memory_points
    print(f"\n4. peak memory beyond inputs and outputs for {nm:,} points (tracemalloc)")
    fm = rng.integers(0, mesh.n_faces, nm)
    um, vm = rng.random(nm), rng.random(nm)
    outm = {k: np.empty((nm, 3)) for k in ("P", "Pu", "Pv")}
    for be in backends:
        tracemalloc.start()
        S.evaluate(fm, um, vm, 1, out=outm, backend=be)
        _, peak = tracemalloc.get_traced_memory()
        tracemalloc.stop()
        io = sum(a.nbytes for a in (fm, um, vm)) + sum(a.nbytes for a in outm.values())
        print(f"   {be:6s}: {peak / 2**20:8.1f} MiB extra (inputs + outputs: {io / 2**20:.0f} MiB; "
              f"patch table {S.table_bytes / 2**20:.1f} MiB)")
    osd = osd_side_by_side(args.osd_points if not args.quick else 20_000, rng, args.quick, rounds=args.rounds)
    startup_and_memory(SHAPES[0][1], 1_000_000 if not args.quick else 20_000, rng)
    import_over_numpy(args.rounds if not args.quick else 2)
    print("\nsummary:")
    for be in backends:
        print(f"   {be}: {rates[be][1] / 1e6:.2f} M points/s (P + first derivatives, single thread, CPU time)")
    if osd:
        print("   / OpenSubdiv Far, one pinned CPU, median over rounds (min-max):")
        for label, dist, ratios, two, load, cpu in osd:
            parts = ", ".join(f"{k} {md:.2f} ({lo:.2f}-{hi:.2f})" for k, (lo, md, hi) in ratios.items() if k != "far")
            tt = (f"; 2 threads / 1: {two['ours']['speedup'][1]:.2f} (ceiling {two['ceiling']['speedup'][1]:.2f})"
                  if two else "")
            c = cpu.get(available_backends()[0])
            tc = f"; in CPU time {c[1]:.2f} ({c[0]:.2f}-{c[2]:.2f})" if c else ""
            print(f"      {label:15s} {dist:9s} {parts}{tt}{tc}; load {min(load):.2f}-{max(load):.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
