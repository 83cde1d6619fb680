"""Benchmark of the inverse characteristic map against the forward map (issue 5).

On the same N points (default 10^6), per valence:

* forward: Phi(y) for y uniform in [0,1]^2 (values only, and values + Jacobian);
* inverse: Phi^-1(t) for t uniform in [0,1]^2;
* location: step 1-2 of Algorithm 1 alone (layer first guess, implicit-cubic layer and piece
  tests), on the same t;
* the fraction of points that needed the fallback, the failures (must be 0), the round-trip error
  max |Phi(Phi^-1(t)) - t|, and the ratios inverse / forward and location / forward.

Times are the minimum over ``--repeat`` runs (the machine is shared; the minimum is the least
disturbed run). Usage: ``python scripts/bench_inverse.py [--n 1000000] [--k 3 5 8 ...]``.
"""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np


def best_time(fn, repeat):
    best = float("inf")
    out = None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def location_only(k, u, v):
    from ccproof.inverse._data import CHUNK, valence_data
    from ccproof.inverse.algorithm import locate

    D = valence_data(k)
    n = u.shape[0]
    for i in range(0, n, CHUNK):
        x, y = u[i:i + CHUNK], v[i:i + CHUNK]
        sw = y > x
        a = np.where(sw, y, x)
        b = np.where(sw, x, y)
        zero = a == 0
        if zero.any():
            a = np.where(zero, 1.0, a)
        locate(D, a, b)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=10**6)
    ap.add_argument("--k", type=int, nargs="*", default=[3, 4, 5, 6, 8, 13, 20, 50, 100, 1000])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--seed", type=int, default=2024)
    args = ap.parse_args(argv)

    from ccproof.inverse import characteristic_map, inverse_characteristic_map

    rng = np.random.default_rng(args.seed)
    u = rng.random(args.n)
    v = rng.random(args.n)
    print(f"N = {args.n} points uniform in [0,1]^2, times = min over {args.repeat} runs (seconds)")
    head = (f"{'k':>5} {'forward':>8} {'fwd+J':>8} {'inverse':>8} {'locate':>8} {'inv/fwd':>8} "
            f"{'inv/fwdJ':>8} {'loc/fwd':>8} {'fallback':>9} {'fail':>5} {'roundtrip':>10}")
    print(head)
    worst = 0
    for k in args.k:
        characteristic_map(k, u[:4], v[:4])
        inverse_characteristic_map(k, u[:4], v[:4])
        tf, _ = best_time(lambda k=k: characteristic_map(k, u, v), args.repeat)
        tj, _ = best_time(lambda k=k: characteristic_map(k, u, v, jacobian=True), args.repeat)
        ti, res = best_time(lambda k=k: inverse_characteristic_map(k, u, v, full_output=True), args.repeat)
        tl, _ = best_time(lambda k=k: location_only(k, u, v), args.repeat)
        x, y = characteristic_map(k, res.r, res.s)
        err = float(np.maximum(np.abs(x - u), np.abs(y - v)).max())
        fails = res.stats["failures"]
        worst = max(worst, fails)
        print(f"{k:>5} {tf:8.4f} {tj:8.4f} {ti:8.4f} {tl:8.4f} {ti / tf:8.2f} {ti / tj:8.2f} {tl / tf:8.2f} "
              f"{res.stats['fallback'] / args.n:9.2e} {fails:>5} {err:10.2e}")
        sys.stdout.flush()
    return 1 if worst else 0


if __name__ == "__main__":
    sys.exit(main())
