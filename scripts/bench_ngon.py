#!/usr/bin/env python
"""A/B benchmark of the corner scheme of an n-gon's centre (valence n): exact layers on classes of equal columns
against the dense exact products they replaced.

For a disc (one n-gon, a ring of quads around it) and each n, the stationary one-ring of a sub-face read from
the centre (:func:`ccproof.evaluate.local.canonical_ring`, :func:`~ccproof.evaluate.local.refine_key`), then

* old: the former code, kept below verbatim as the baseline: the limit mask by a dense ``fmpq_mat`` solve and
  the layers ``M A^t - 1 l^T`` by ``fmpz_mat`` products (48 (2n + 8)^2 big-integer operations a layer);
* new: :func:`ccproof.evaluate.local.corner_scheme` computed afresh (its cached wrapper bypassed, the disk
  cache off);

in one process, taking turns round by round (min, median, max of the ratio new / old per round; the 1-minute
load before each round). The layers of both are checked equal bit for bit.

Usage: python scripts/bench_ngon.py [--rounds 2] [--sizes 50 100] [--smoke]   (n = 200: about 45 s a round for old)
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

os.environ["CCPROOF_CACHE"] = "off"
sys.path.insert(0, str(Path(__file__).resolve().parent))
from _bench import load, ratio_line  # noqa: E402

from ccproof.evaluate.local import (  # noqa: E402
    canonical_ring,
    corner_scheme,
    refine_key,
    regular_net,
    ring_key,
)
from ccproof.mesh import PolyMesh  # noqa: E402

LAYER_TOLERANCE, MAX_LAYERS = 2.0**-60, 400


def disc(n):
    t = np.arange(n) * 2 * np.pi / n
    V = np.vstack([np.c_[np.cos(t), np.sin(t), 0 * t], np.c_[2 * np.cos(t), 2 * np.sin(t), 0 * t + 0.3]])
    return PolyMesh(V, [list(range(n))] + [[i, n + i, n + (i + 1) % n, (i + 1) % n] for i in range(n)])


def stationary_key(n):
    """The ring key at the centre of the disc's n-gon, refined until the scheme exists (stationary)."""
    m1, _ = disc(n).refine()
    counts = np.bincount(np.concatenate([np.asarray(p) for p in m1.polygons]))
    v = int(np.flatnonzero(counts == n)[0])
    g = next(g for g, poly in enumerate(m1.polygons) if v in poly)
    cx = m1.complex()
    ring, faces, nr = canonical_ring(cx, g, m1.polygons[g].index(v))
    key = ring_key(cx, ring, faces, nr)
    for _ in range(4):
        if corner_scheme(key) is not None:
            return key
        _, _, child = refine_key(key, 4)
        ring, faces, nr = canonical_ring(child, 0, 0, 1)
        key = ring_key(child, ring, faces, nr)
    raise SystemExit(f"no stationary ring at the centre of a {n}-gon")


# ------------------------------------------------------------------ the baseline (the former code)
def old_scheme(key):
    """The limit mask and the layers as before: a dense fmpq solve, dense fmpz_mat products."""
    import flint

    _, stencils, child = refine_key(key, 4)
    ring1, _, _ = canonical_ring(child, 0, 0, 1)
    rows = [stencils[v] for v in ring1]
    N = len(ring1)
    nets = []
    for j in (1, 2, 3):
        for s in regular_net(child, j):
            row = {}
            for v, w in s.items():
                for u, x in stencils[v].items():
                    row[u] = row.get(u, 0) + w * x
            nets.append(row)
    A = flint.fmpq_mat(N, N)
    for i, s in enumerate(rows):
        for j, w in s.items():
            A[i, j] = w
    M = flint.fmpq_mat(48, N)
    for i, s in enumerate(nets):
        for j, w in s.items():
            M[i, j] = w
    Bt = (A - flint.fmpq_mat(N, N, [int(i == j) for i in range(N) for j in range(N)])).transpose()
    for j in range(N):
        Bt[N - 1, j] = 1
    lvec = Bt.solve(flint.fmpq_mat(N, 1, [0] * (N - 1) + [1]))
    l_row = flint.fmpq_mat(1, N, [lvec[i, 0] for i in range(N)])
    return power_layers(M, A, l_row)


def power_layers(M, A, l_row):
    import flint

    N = A.nrows()
    Ai, a = A.numer_denom()
    Mi, m = M.numer_denom()
    li, c = l_row.numer_denom()
    a, m, c = int(a), int(m), int(c)
    Lrow = [int(x) for x in li.entries()]
    ones = flint.fmpz_mat(48, 1, [1] * 48)
    L1 = ones * flint.fmpz_mat(1, N, Lrow)
    R = Mi
    den = m
    layers = []
    for _ in range(MAX_LAYERS):
        num = R * c - L1 * den
        q = c * den
        D = np.array([int(p) / q for p in num.entries()], dtype=np.float64).reshape(48, N)
        layers.append(D.reshape(3, 16, N))
        if np.abs(D).max() < LAYER_TOLERANCE:
            return np.array(layers)
        R = R * Ai
        den *= a
    raise RuntimeError("no convergence")


def _ab(n, rounds):
    key = stationary_key(n)
    ratios, loads, t_old, t_new = [], [], [], []
    for _ in range(rounds):
        loads.append(load())
        t0 = time.perf_counter()
        old = old_scheme(key)
        t_old.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        new = corner_scheme.__wrapped__(key).layers
        t_new.append(time.perf_counter() - t0)
        assert np.array_equal(old, new), f"n = {n}: the layers differ"
        ratios.append(t_new[-1] / t_old[-1])
    print(f"corner scheme of a {n}-gon centre (ring {old.shape[-1]}, {old.shape[0]} layers): old "
          f"{min(t_old):.2f} s  new {min(t_new):.3f} s  layers equal bit for bit", flush=True)
    print(ratio_line(f"  new/old n={n}", ratios, loads), flush=True)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--sizes", type=int, nargs="+", default=[50, 100])
    ap.add_argument("--smoke", action="store_true", help="one round at n = 12 (the test suite's run)")
    a = ap.parse_args(argv)
    rounds, sizes = (1, [12]) if a.smoke else (a.rounds, a.sizes)
    print(f"{os.cpu_count()} cpus; rounds {rounds}; the machine is shared (see the load)", flush=True)
    for n in sizes:
        _ab(n, rounds)


if __name__ == "__main__":
    main()
