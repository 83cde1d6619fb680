#!/usr/bin/env python
"""Exact Loop evaluation (``ccproof.limit_surface(mesh, scheme="loop")``) against OpenSubdiv's Far Loop
PatchTable (isolation level 10, Gregory-triangle end caps) in one process, per thread, rounds interleaved.

Per mesh, each round times (the order alternating round by round): the setup of ours (the per-configuration
data warm in the process after the first round, as a disk cache would be) and Far's (TopologyRefiner,
adaptive refinement, PatchTable, local points, PatchMap), then the evaluation of the same random points
(uniform triangle, uniform (u, v) in it; positions and first derivatives) by ours and by Far's loop
(``scripts/osd_capi.cpp``). Printed per mesh: ``setup ours/Far`` and ``evaluation Far/ours`` (above 1: ours
faster), min / median / max over the rounds, with the load, and the median times per point; and once the
largest difference to Far on points of its regular Loop patches (no end cap).

Clock: the CPU time of the process (``time.process_time``; both sides run on one thread), so that on a shared
machine the time others take the cores from us is not counted; ``--wall`` times the wall clock instead.

Meshes: an icosphere (valence 5 at 12 vertices, 6 elsewhere: scan-like), the same with random edge flips
(valences 3 to 8 everywhere), ``catmark_smoothtris1`` (80 triangles) and a grid with boundary corners and an
infinitely sharp crease.

Usage: python scripts/bench_loop.py [--levels 5] [--points 400000] [--rounds 5] [--wall]
       python scripts/bench_loop.py --smoke     tiny (the test suite's run)
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "scripts"))
import _osd  # noqa: E402
from _bench import load, missing, ratio_line  # noqa: E402

import ccproof  # noqa: E402
from ccproof.mesh import PolyMesh  # noqa: E402
from ccproof.mesh.io import read_mesh  # noqa: E402


def icosphere(levels):
    t = (1 + 5**0.5) / 2
    V = [[-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0], [0, -1, t], [0, 1, t], [0, -1, -t], [0, 1, -t],
         [t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]]
    F = [[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4], [11, 10, 2],
         [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8], [3, 8, 9], [4, 9, 5], [2, 4, 11],
         [6, 2, 10], [8, 6, 7], [9, 8, 1]]
    V = [np.array(v, dtype=float) / np.linalg.norm(v) for v in V]
    for _ in range(levels):
        mid, G = {}, []
        for a, b, c in F:
            m = []
            for p, q in ((a, b), (b, c), (c, a)):
                k = (min(p, q), max(p, q))
                if k not in mid:
                    x = V[p] + V[q]
                    V.append(x / np.linalg.norm(x))
                    mid[k] = len(V) - 1
                m.append(mid[k])
            G += [[a, m[0], m[2]], [b, m[1], m[0]], [c, m[2], m[1]], m]
        F = G
    return np.array(V), F


def flipped(F, fraction, seed):
    """Random edge flips (about ``fraction`` of the faces), valences kept in [3, 8]."""
    rng = np.random.default_rng(seed)
    F = [list(f) for f in F]
    opp, nb = {}, {}
    for i, (a, b, c) in enumerate(F):
        opp[(a, b)], opp[(b, c)], opp[(c, a)] = i, i, i
        for x, y in ((a, b), (b, c), (c, a)):
            nb.setdefault(x, set()).add(y)
            nb.setdefault(y, set()).add(x)
    for _ in range(int(fraction * len(F))):
        i = int(rng.integers(len(F)))
        a, b, c = F[i]
        j = opp.get((b, a))
        if j is None:
            continue
        d = [x for x in F[j] if x not in (a, b)][0]
        if d in nb[c] or min(len(nb[a]), len(nb[b])) <= 3 or max(len(nb[c]), len(nb[d])) >= 8:
            continue
        for f in (F[i], F[j]):
            x, y, z = f
            for e in ((x, y), (y, z), (z, x)):
                del opp[e]
        F[i], F[j] = [c, a, d], [d, b, c]
        nb[a].discard(b)
        nb[b].discard(a)
        nb[c].add(d)
        nb[d].add(c)
        for k in (i, j):
            x, y, z = F[k]
            opp[(x, y)], opp[(y, z)], opp[(z, x)] = k, k, k
    return F


def grid(n):
    V = np.array([[i, j, 0.3 * math.sin(i + 2 * j)] for j in range(n + 1) for i in range(n + 1)], dtype=float)
    F = []
    for j in range(n):
        for i in range(n):
            a, b, c, d = j * (n + 1) + i, j * (n + 1) + i + 1, (j + 1) * (n + 1) + i, (j + 1) * (n + 1) + i + 1
            F += [[a, b, c], [b, d, c]]
    mid = n // 2 * (n + 1)
    creases = {(mid + i, mid + i + 1): math.inf for i in range(n // 2)}
    return PolyMesh(V, F, creases=creases)


def meshes(levels):
    V, F = icosphere(levels)
    rng = np.random.default_rng(1)
    noisy = V * (1 + 0.02 * rng.standard_normal((len(V), 1)))
    return [(f"icosphere{levels}", PolyMesh(noisy, F)),
            (f"icosphere{levels}_flips", PolyMesh(noisy, flipped(F, 0.05, 2))),
            ("smoothtris1", read_mesh(REPO / "tests/data/osd_features/meshes/catmark_smoothtris1.obj")),
            ("grid_crease", grid(max(4, 2 ** (levels - 1))))]


def points(mesh, n, seed=0):
    rng = np.random.default_rng(seed)
    f = rng.integers(0, mesh.n_faces, n)
    u, v = rng.random(n), rng.random(n)
    flip = u + v > 1
    u[flip], v[flip] = 1 - u[flip], 1 - v[flip]
    return f, u, v


def bench_mesh(name, mesh, lib, n, rounds, clock=time.process_time):
    f, u, v = points(mesh, n)
    ccproof.limit_surface(mesh, scheme="loop").evaluate(f[:10], u[:10], v[:10], 1)  # warm: compile, caches
    setup, ev, loads, per_point = [], [], [], []
    S = far = None
    for r in range(rounds):
        loads.append(load())
        order = (0, 1) if r % 2 == 0 else (1, 0)
        t_s, t_e = [0.0, 0.0], [0.0, 0.0]
        for side in order:
            if side == 0:
                t = clock()
                S = ccproof.limit_surface(mesh, scheme="loop")
                t_s[0] = clock() - t
                t = clock()
                S.evaluate(f, u, v, 1)
                t_e[0] = clock() - t
            elif lib is not None:
                if far is not None:
                    far.close()
                t = clock()
                far = _osd.Evaluator(lib, "far", mesh, level=10, scheme="loop")
                t_s[1] = clock() - t
                t = clock()
                far.evaluate(f, u, v)
                t_e[1] = clock() - t
        per_point.append((t_e[0] / n * 1e9, t_e[1] / n * 1e9))
        if lib is None:
            setup.append(t_s[0])
            ev.append(t_e[0])
        else:
            setup.append(t_s[0] / t_s[1])
            ev.append(t_e[1] / t_e[0])
    print(f"{name}: {mesh.n_faces} triangles, {n} points (positions and first derivatives), one thread", flush=True)
    if lib is None:
        print(f"  {ratio_line('setup ours (s)', setup, loads)}\n  {ratio_line('evaluation ours (s)', ev, loads)}")
        return
    print(f"  {ratio_line('setup ours/Far', setup, loads)}")
    print(f"  {ratio_line('evaluation Far/ours', ev, loads)}")
    print(f"  evaluation per point (medians): ours {statistics.median(x for x, _ in per_point):.0f} ns, "
          f"Far {statistics.median(y for _, y in per_point):.0f} ns")
    exact = far.patch_types(f, u, v) == 5  # PatchDescriptor::LOOP: no end cap
    P, Ps, Pt = far.evaluate(f[exact], u[exact], v[exact])
    R = S.evaluate(f[exact], u[exact], v[exact], 1)
    err = max(float(np.max(np.abs(a - b) / np.maximum(1, np.abs(b)))) for a, b in
              ((R["P"], P), (R["Pu"], Ps), (R["Pv"], Pt)))
    print(f"  largest difference to Far on its {int(exact.sum())} points of regular Loop patches: {err:.1e} "
          "(relative to max(1, |value|))", flush=True)
    far.close()


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--levels", type=int, default=5)
    ap.add_argument("--points", type=int, default=400_000)
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--smoke", action="store_true", help="tiny: icosphere level 1, 2000 points, 2 rounds")
    ap.add_argument("--wall", action="store_true", help="time the wall clock (default: the process's CPU time)")
    a = ap.parse_args(argv)
    if a.smoke:
        a.levels, a.points, a.rounds = 1, 2000, 2
    why = _osd.why_unavailable()
    lib = None
    if why is None:
        try:
            lib = _osd.load()
        except RuntimeError as e:
            why = str(e)
    if lib is None:
        missing("OpenSubdiv Far (Loop)", why)
    clock = time.perf_counter if a.wall else time.process_time
    print(f"(the machine is shared: load average {load():.2f} at the start; clock: "
          f"{'wall' if a.wall else 'CPU time of the process'})")
    for name, mesh in meshes(a.levels):
        bench_mesh(name, mesh, lib, a.points, a.rounds, clock)
    return 0


if __name__ == "__main__":
    sys.exit(main())
