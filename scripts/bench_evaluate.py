#!/usr/bin/env python
"""Benchmark of exact limit evaluation (ccproof.evaluate) on the quad-remeshed Stanford bunny.

Measures, in one run:

1. points per second for positions + first derivatives at 10^6 random (face, u, v) on
   ``bunny_quads.obj`` (2,036 quads, 103 extraordinary vertices), for the numpy kernel and, when
   numba is installed, the compiled kernel; wall-clock and CPU-time rates (the CPU-time rate is
   the single-thread rate even on a loaded machine);
2. (a) a straightforward per-point implementation (Python loop over points, the same tables)
   on a subsample, extrapolated to the same number of points: ratio;
3. (b) uniform Catmull-Clark subdivision with pygel3d (if installed) level by level: time,
   size, and accuracy of the level-L control points as surface points (distance to their own
   limit positions, relative to the bounding-box diagonal), extrapolated to the level that would
   reach the accuracy of exact evaluation;
4. the peak memory beyond inputs and outputs for 10^7 points (tracemalloc).

The bunny mesh is read from the repository's test data (``tests/data/meshes/bunny_quads.obj``).

Usage: python scripts/bench_evaluate.py [--points 1000000] [--memory-points 10000000] [--quick]
"""

from __future__ import annotations

import argparse
import math
import sys
import time
import tracemalloc
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from ccproof.evaluate import limit_surface  # noqa: E402
from ccproof.evaluate.surface import _CORNER, _SPLIT  # noqa: E402
from ccproof.mesh import limit_normals, limit_positions, read_obj, subdivide  # noqa: E402


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
def _basis(x):
    t = 1.0 - x
    B = (t * t * t / 6, (3 * x**3 - 6 * x * x + 4) / 6, (-3 * x**3 + 3 * x * x + 3 * x + 1) / 6, x**3 / 6)
    D = (-0.5 * t * t, 1.5 * x * x - 2 * x, -1.5 * x * x + x + 0.5, 0.5 * x * x)
    return B, D


def naive_point(S, f, u, v):
    """One point at a time, plain Python on the same tables: locate, basis, 16-term sums."""
    vf = f
    for _ in range(S.split_depth):
        if S._vkind[vf] != _SPLIT:
            break
        half = S._vh[vf] * 0.5
        vf = S._vchild[vf, int(u >= S._vu0[vf] + half) + 2 * int(v >= S._vv0[vf] + half)]
    p = int(S._vpatch[vf])
    if S._vkind[vf] == _CORNER:
        U0, V0, H = S._vu0[vf], S._vv0[vf], S._vh[vf]
        du = ((U0 + H) - u if S._vcu[vf] else u - U0) / H
        dv = ((V0 + H) - v if S._vcv[vf] else v - V0) / H
        mx = max(du, dv)
        n = min(max(-math.frexp(mx)[1], 0), int(S._vnmax[vf])) if mx > 0 else int(S._vnmax[vf])
        du, dv = math.ldexp(du, n), math.ldexp(dv, n)
        a, b = du >= 0.5, dv >= 0.5
        if n >= S.hot_layers:
            p = int(S._vcold[vf])
        p += 3 * n + (0 if (a and not b) else 1 if (a and b) else 2 if b else 1)
    h = S._ph[p]
    s = min(max((u - S._pu0[p]) / h, 0.0), 1.0)
    t = min(max((v - S._pv0[p]) / h, 0.0), 1.0)
    Bs, Ds = _basis(s)
    Bt, Dt = _basis(t)
    net = S._nets[p].tolist()
    P, Pu, Pv = S._nets[p, 16].tolist(), [0.0] * 3, [0.0] * 3
    for j in range(4):
        for i in range(4):
            w = net[i + 4 * j]
            for c in range(3):
                P[c] += Bs[i] * Bt[j] * w[c]
                Pu[c] += Ds[i] * Bt[j] * w[c] / h
                Pv[c] += Bs[i] * Dt[j] * w[c] / h
    return P, Pu, Pv


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--points", type=int, default=1_000_000)
    ap.add_argument("--memory-points", type=int, default=10_000_000)
    ap.add_argument("--naive-points", type=int, default=2000)
    ap.add_argument("--pygel-levels", type=int, default=5)
    ap.add_argument("--quick", action="store_true", help="small sizes (smoke test)")
    args = ap.parse_args(argv)
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
          f"{S.n_patches} stored patches ({S._nets.nbytes / 2**20:.1f} MiB), deepest layer table "
          f"{S.max_layers}, split depth {S.split_depth}")

    rng = np.random.default_rng(2024)
    n = args.points
    f = rng.integers(0, mesh.n_faces, n)
    u, v = rng.random(n), rng.random(n)
    backends = ["numpy"]
    try:
        import numba  # noqa: F401

        backends.append("numba")
        S.evaluate(f[:10], u[:10], v[:10], 1, backend="numba")  # compile (cached on disk)
    except ImportError:
        print("numba not installed: compiled kernel skipped")
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
              f"patch tables {S._nets.nbytes / 2**20:.1f} MiB)")
    print("\nsummary:")
    for be in backends:
        print(f"   {be}: {rates[be][1] / 1e6:.2f} M points/s (P + first derivatives, single thread, CPU time)")
    print("   target (OpenSubdiv 3.6 C++ patch-table evaluation, single thread): ~10 M points/s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
