"""Benchmark: points/s of the natural, vanishing and characteristic parameterizations (bmz04 section 4).

Same mesh, same points, one run, the three evaluations interleaved round by round (the machine is
shared, so the ratios of one round are more meaningful than absolute times); prints the median
over rounds of the per-round ratios vanishing/natural and characteristic/natural (target:
characteristic <= 4 x natural), and the best time of each.

The backend of the natural evaluator is chosen with --backend (sets CCPROOF_BACKEND: "numba" for
the compiled kernel, "numpy" for the pure numpy path); the reparameterization itself is numpy in
both cases. The one-time costs (surface preparation, the first call that builds the per-valence
tables of Phi^-1 and, if needed, the rotated corner frames) are reported separately.

Examples:
  python scripts/bench_reparam.py                                  # bunny, 10^6 points, numba
  python scripts/bench_reparam.py --mesh disk:7 --points 200000 --backend numpy
"""

from __future__ import annotations

import argparse
import os
import statistics
import time
from pathlib import Path

import numpy as np

DEFAULT_MESH = Path(__file__).resolve().parents[1] / "tests" / "data" / "meshes" / "bunny_quads.obj"


def load_mesh(spec):
    from ccproof.mesh import read_obj
    from ccproof.mesh.examples import k_regular_disk

    if spec.startswith("disk:"):
        return k_regular_disk(int(spec[5:]), rings=4)
    return read_obj(spec)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--mesh", default=str(DEFAULT_MESH), help="OBJ file or disk:K (k-regular disk, 4 rings)")
    ap.add_argument("--points", type=int, default=1_000_000)
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--derivatives", type=int, default=1, choices=(0, 1, 2))
    ap.add_argument("--backend", choices=("numba", "numpy"), default="numba")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--sampling", choices=("uniform", "ev-faces"), default="uniform",
                    help="uniform: random face and (u, v); ev-faces: only faces with an extraordinary corner "
                    "(the worst case for the reparameterizations)")
    args = ap.parse_args(argv)
    os.environ["CCPROOF_BACKEND"] = args.backend

    from ccproof.evaluate._numba_kernel import evaluate_points
    from ccproof.reparam import limit_surface
    from ccproof.reparam.blend import face_map

    if args.backend == "numba" and evaluate_points is None:
        raise SystemExit("numba is not installed: use --backend numpy")
    t0 = time.perf_counter()
    mesh = load_mesh(args.mesh)
    S = limit_surface(mesh)
    t1 = time.perf_counter()
    rng = np.random.default_rng(args.seed)
    n = args.points
    if args.sampling == "uniform":
        f = rng.integers(0, mesh.n_faces, n)
    else:
        pool = np.flatnonzero(S.corner_valence.any(axis=1))
        f = pool[rng.integers(0, pool.size, n)]
    u, v = rng.random(n), rng.random(n)
    names = ("natural", "vanishing", "characteristic")
    warm = {}
    for p in names:  # first calls: numba compilation, Phi^-1 tables, rotated frames
        a = time.perf_counter()
        S.evaluate(f, u, v, args.derivatives, parameterization=p)
        warm[p] = time.perf_counter() - a
    act = {p: float(face_map(S.corner_valence[f], u, v, p, S.alpha)["active"].mean()) for p in names[1:]}
    times = {p: [] for p in names}
    for _ in range(args.rounds):
        for p in names:
            a = time.perf_counter()
            S.evaluate(f, u, v, args.derivatives, parameterization=p)
            times[p].append(time.perf_counter() - a)
    ev = mesh.extraordinary_vertices
    print(f"mesh {args.mesh}: {mesh.n_faces} faces, {ev.size} extraordinary vertices "
          f"(valences {sorted({int(k) for k in mesh.valence[ev]})}); prepared in {t1 - t0:.2f} s")
    print(f"{n} random points ({args.sampling}), derivatives {args.derivatives}, backend {args.backend} (natural "
          f"evaluator; the reparameterization is numpy), {args.rounds} interleaved rounds; 2-core shared machine")
    print("first calls (one-time costs included): " + ", ".join(f"{p} {warm[p]:.2f} s" for p in names))
    print(f"fraction of points with w > 0 at an extraordinary corner: vanishing {act['vanishing']:.4f}, "
          f"characteristic {act['characteristic']:.4f}")
    for p in names:
        best = min(times[p])
        print(f"  {p:15s} best {best * 1e3:8.1f} ms  median {statistics.median(times[p]) * 1e3:8.1f} ms  "
              f"{n / best / 1e6:6.2f} M points/s")
    for p in names[1:]:
        r = [a / b for a, b in zip(times[p], times["natural"])]
        print(f"  ratio {p}/natural: median {statistics.median(r):.2f} (rounds {min(r):.2f} .. {max(r):.2f})")
    rc = statistics.median(a / b for a, b in zip(times["characteristic"], times["natural"]))
    print(f"target characteristic <= 4 x natural: {'met' if rc <= 4 else 'MISSED'} ({rc:.2f})")


if __name__ == "__main__":
    main()
