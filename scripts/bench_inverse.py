"""Benchmark of the inverse characteristic map against the forward map (docs/inverse.md).

On the same N points (default 10^6), per valence:

* forward: Phi(y) for y uniform in [0,1]^2 (values only, and values + Jacobian);
* inverse: Phi^-1(t) for t uniform in [0,1]^2;
* location: step 1-2 of Algorithm 1 alone (layer first guess, implicit-cubic layer and piece
  tests), on the same t;
* the fraction of points that needed the fallback, the failures (must be 0), the round-trip error
  max |Phi(Phi^-1(t)) - t|, and the ratios inverse / forward and location / forward;
* the same fallback fraction, failures and round-trip error on N/10 points clustered within 1e-12
  of every layer and piece boundary, of the axes and of the origin.

The four computations are run interleaved, ``--repeat`` rounds; times are the minimum over the
rounds (the least disturbed run on a shared machine) and the ratios are also given as the median
over the rounds of the per-round ratios (robust to load changing between rounds).
Usage: ``python scripts/bench_inverse.py [--n 1000000] [--k 3 5 8 ...] [--repeat 7]``.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _bench import load, ratio_line  # noqa: E402


def interleaved(fns, repeat):
    """Run the callables in turn ``repeat`` times: (per-callable list of times, last outputs)."""
    times = [[] for _ in fns]
    outs = [None] * len(fns)
    for _ in range(repeat):
        for i, fn in enumerate(fns):
            t0 = time.perf_counter()
            outs[i] = fn()
            times[i].append(time.perf_counter() - t0)
    return times, outs


def clustered(k, rng, n, eps=1e-12):
    """n points within eps of the images of u = 1/2, u = 1, v = 1/2, v = 1 (layers 0..6), of the
    diagonal, the axis, and (5%) of the origin."""
    from ccproof.inverse import characteristic_map

    w = rng.random(n)
    kind = rng.integers(0, 7, n)
    sc = 0.5 ** rng.integers(0, 7, n)
    u = np.choose(kind, [np.full(n, 0.5), np.ones(n), w, w, w, w, w * 0.5]) * sc
    v = np.choose(kind, [w * 0.5, w, np.full(n, 0.5), np.ones(n), w, np.zeros(n), np.full(n, 0.5)]) * sc
    x, y = characteristic_map(k, u, v)
    x = np.abs(x + rng.uniform(-eps, eps, n))
    y = np.abs(y + rng.uniform(-eps, eps, n) * (rng.random(n) < 0.9))
    o = rng.random(n) < 0.05
    x[o] = rng.random(o.sum()) * eps
    y[o] = rng.random(o.sum()) * eps
    return x, y


def location_only(k, u, v):
    from ccproof.inverse.algorithm import locate
    from ccproof.inverse.data import valence_data
    from ccproof.inverse.kernels import CHUNK

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
    ap.add_argument("--all", action="store_true", help="k = 3..50, 100, 1000 (overrides --k)")
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--seed", type=int, default=2024)
    ap.add_argument("--smoke", action="store_true", help="2,000 points, k = 5, 2 rounds (the test suite's run)")
    args = ap.parse_args(argv)
    if args.smoke:
        args.n, args.k, args.repeat = 2000, [5], 2
    if args.all:
        args.k = list(range(3, 51)) + [100, 1000]

    from ccproof.inverse import characteristic_map, inverse_characteristic_map

    rng = np.random.default_rng(args.seed)
    u = rng.random(args.n)
    v = rng.random(args.n)
    print(f"N = {args.n} points uniform in [0,1]^2; {args.repeat} interleaved rounds; times: minimum (s);"
          " ratios: min/min and [median of per-round ratios]")
    head = (f"{'k':>5} {'forward':>8} {'fwd+J':>8} {'inverse':>8} {'locate':>8} {'inv/fwd':>14} "
            f"{'inv/fwd+J':>14} {'loc/fwd':>14} {'fallback':>9} {'fail':>5} {'roundtrip':>10} "
            f"{'clust.fb':>9} {'fail':>5} {'clust.rt':>9}")
    print(head)
    worst, lines = 0, []
    for k in args.k:
        load0 = load()
        characteristic_map(k, u[:4], v[:4])
        inverse_characteristic_map(k, u[:4], v[:4])
        fns = [lambda k=k: characteristic_map(k, u, v),
               lambda k=k: characteristic_map(k, u, v, jacobian=True),
               lambda k=k: inverse_characteristic_map(k, u, v, full_output=True),
               lambda k=k: location_only(k, u, v)]
        times, outs = interleaved(fns, args.repeat)
        tf, tj, ti, tl = (np.array(t) for t in times)
        res = outs[2]
        x, y = characteristic_map(k, res.r, res.s)
        err = float(np.maximum(np.abs(x - u), np.abs(y - v)).max())
        fails = res.stats["failures"]
        worst = max(worst, fails)

        def ratio(a, b):
            return f"{a.min() / b.min():5.2f} [{np.median(a / b):5.2f}]"

        cx, cy = clustered(k, rng, max(1, args.n // 10))
        cres = inverse_characteristic_map(k, cx, cy, full_output=True)
        X, Y = characteristic_map(k, cres.r, cres.s)
        cerr = float(np.maximum(np.abs(X - cx), np.abs(Y - cy)).max())
        worst = max(worst, cres.stats["failures"])
        print(f"{k:>5} {tf.min():8.4f} {tj.min():8.4f} {ti.min():8.4f} {tl.min():8.4f} {ratio(ti, tf):>14} "
              f"{ratio(ti, tj):>14} {ratio(tl, tf):>14} {res.stats['fallback'] / args.n:9.2e} {fails:>5} "
              f"{err:10.2e} {cres.stats['fallback'] / cx.size:9.2e} {cres.stats['failures']:>5} {cerr:9.2e}")
        lines.append(ratio_line(f"k = {k:>4} inverse/forward:", ti / tf, [load0, load()]))
        sys.stdout.flush()
    print("\n".join(lines))
    return 1 if worst else 0


if __name__ == "__main__":
    sys.exit(main())
