"""Benchmark of closest points on the bunny's limit surface (ccproof.evaluate.closest).

Random points uniform in the bounding box of the limit surface enlarged by 5 % on each side.
Ours: ClosestPointFinder (sampled cell cylinders, BVH, best-first projected Newton). Baseline: scipy
cKDTree over a dense limit sampling ((2^L + 1)^2 samples per face), the nearest sample refined by the
same projected Newton (to the same accuracy; not global: it keeps the nearest sample's face).
Prints rates (points per second, preparation excluded and included), the ratio, the agreement of
the distances, and the certified mode's cost per point on a few points.

    python scripts/bench_project.py [--n 1000000] [--level 5] [--certify 5] [--baseline-n 100000] [--rounds 3]
    python scripts/bench_project.py --smoke          the torus, 200 points (the test suite's run)
"""

import argparse
import sys
import time
from pathlib import Path

import numpy as np
from scipy.spatial import cKDTree

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _bench import load, ratio_line  # noqa: E402

from ccproof.evaluate import limit_surface  # noqa: E402
from ccproof.evaluate.closest import ClosestPointFinder
from ccproof.evaluate.closest_certified import certify_closest  # noqa: E402
from ccproof.evaluate.newton import newton  # noqa: E402
from ccproof.mesh.examples import torus  # noqa: E402

BUNNY = Path(__file__).resolve().parents[1] / "tests" / "data" / "meshes" / "bunny_quads.obj"


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=1_000_000)
    ap.add_argument("--level", type=int, default=5, help="baseline sampling: 2^level intervals per face side")
    ap.add_argument("--certify", type=int, default=5, help="points for the certified mode")
    ap.add_argument("--baseline-n", type=int, default=100_000,
                    help="the baseline runs on the first N points only (its rate is per point)")
    ap.add_argument("--rounds", type=int, default=3, help="interleaved rounds of ours and the baseline")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--smoke", action="store_true",
                    help="the torus of ccproof.mesh.examples, 200 points, 2 rounds (the test suite's run)")
    a = ap.parse_args(argv)
    if a.smoke:
        a.n, a.level, a.certify, a.baseline_n, a.rounds = 200, 2, 0, 200, 2
    S = limit_surface(torus() if a.smoke else BUNNY)
    t0 = time.perf_counter()
    F = ClosestPointFinder(S)
    t_prep = time.perf_counter() - t0
    L = 2**a.level
    t0 = time.perf_counter()
    nf = S.mesh.n_faces
    t = np.arange(L + 1) / L
    U, V = np.meshgrid(t, t, indexing="ij")
    fu = np.repeat(np.arange(nf), (L + 1) ** 2)
    uu, vv = np.tile(U.ravel(), nf), np.tile(V.ravel(), nf)
    samples = S.evaluate(fu, uu, vv, 0)["P"]
    T = cKDTree(samples)
    t_bprep = time.perf_counter() - t0
    lo, hi = samples.min(0), samples.max(0)  # the bounding box of the limit surface (sampled)
    ext = hi - lo
    X = lo - 0.05 * ext + np.random.default_rng(a.seed).random((a.n, 3)) * 1.1 * ext
    nb = min(a.n, a.baseline_n)
    F.query(X[:10])  # warm-up (compiled kernels)
    ours, base, loads = [], [], []
    for r in range(a.rounds):  # ours and the baseline in turn, round by round, per point
        loads.append(load())
        for who in ("ours", "base") if r % 2 == 0 else ("base", "ours"):
            t0 = time.perf_counter()
            if who == "ours":
                res = F.query(X)
                ours.append((time.perf_counter() - t0) / a.n)
            else:
                _, j = T.query(X[:nb], k=1)
                bu, bv, bE = newton(S, X[:nb], fu[j], uu[j], vv[j])
                base.append((time.perf_counter() - t0) / nb)
    t_ours, t_base = min(ours) * a.n, min(base) * a.n  # for all n points at the measured rate
    print(f"ours: preparation {t_prep:.2f} s, {a.n} points in {t_ours:.2f} s: {a.n / t_ours:,.0f} points/s "
          f"({a.n / (t_ours + t_prep):,.0f} with preparation); descents per point {res.descents.mean():.2f}")
    db = np.sqrt(2 * bE)
    print(f"baseline (cKDTree over {fu.size:,} samples + Newton, measured on {nb} points): preparation "
          f"{t_bprep:.2f} s, {a.n / t_base:,.0f} points/s ({a.n / (t_base + t_bprep):,.0f} with preparation)")
    print(f"ratio ours / baseline: {t_base / t_ours:.2f} (queries, best rounds), "
          f"{(t_base + t_bprep) / (t_ours + t_prep):.2f} (with preparation)")
    print(ratio_line("time per point ours/baseline:", [x / y for x, y in zip(ours, base)], loads))
    res_d = res.distance[:nb]
    rel = (db - res_d) / res_d
    diag = float(np.linalg.norm(ext))
    worse = np.flatnonzero(rel < -1e-12)
    real = worse[(res_d[worse] - db[worse]) > 1e-15 * diag]
    print(f"baseline farther than ours (relative > 1e-12) at {(rel > 1e-12).sum()} points (max {rel.max():.3g}); "
          f"ours farther than baseline at {worse.size} points (max relative {-rel.min():.3g}), of which "
          f"{real.size} by more than 1e-15 of the diagonal (the rest: round-off at distances "
          f"<= {res_d[worse].max() / diag if worse.size else 0:.2g} of the diagonal)")
    if a.certify:
        verdicts = {}
        t0 = time.perf_counter()
        for i in range(a.certify):
            c = certify_closest(S, X[i], res.face[i], res.u[i], res.v[i])
            verdicts[c.verdict] = verdicts.get(c.verdict, 0) + 1
        dt = (time.perf_counter() - t0) / a.certify
        print(f"certified mode: {dt:.2f} s per point; verdicts {verdicts}")


if __name__ == "__main__":
    main()
