"""Benchmark: points/s of the natural, vanishing and characteristic parameterizations (bmz04 section 4).

Same mesh, same points, one run, the three evaluations interleaved round by round (the machine is
shared, so the ratios of one round are more meaningful than absolute times); prints the median
over rounds of the per-round ratios vanishing/natural and characteristic/natural (target:
characteristic <= 4 x natural), and the best time of each.

The backend of the natural evaluator is chosen with --backend (sets CCPROOF_BACKEND: "numba" for
the compiled kernel, "numpy" for the pure numpy path); the reparameterization itself is numpy in
both cases. The one-time costs (surface preparation, the first call that builds the per-valence
tables of Phi^-1 and, if needed, the rotated corner frames) are reported separately.

First-call cost per valence (--first-calls): in a fresh interpreter, after the imports, the time of
the first ``valence_data(k)`` (the per-valence data of Phi and Phi^-1, derived from the certified
tables, ccproof/inverse/data.py) and, for k <= 64, of a first characteristic-parameterization
evaluation of 4 points on a k-regular disk (after a natural one, so that the evaluator's own
one-time costs are not counted); the target is <= 0.2 s per new valence. Also the start-up time of
``ccproof --help`` (target < 0.3 s). Both are timings on a shared machine: a benchmark, not a test.

Examples:
  python scripts/bench_reparam.py                                  # bunny, 10^6 points, numba
  python scripts/bench_reparam.py --mesh disk:7 --points 200000 --backend numpy
  python scripts/bench_reparam.py --first-calls 3,5,7,13,100,1000 --points 0   # only the one-time costs
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _bench import load, ratio_line  # noqa: E402

DEFAULT_MESH = Path(__file__).resolve().parents[1] / "tests" / "data" / "meshes" / "bunny_quads.obj"


def load_mesh(spec):
    from ccproof.mesh import read_obj
    from ccproof.mesh.examples import k_regular_disk

    if spec.startswith("disk:"):
        return k_regular_disk(int(spec[5:]), rings=4)
    return read_obj(spec)


_FIRST_CALL = r"""
import json, sys, time
t = time.perf_counter()
from ccproof.inverse.data import valence_data
from ccproof.mesh.examples import k_regular_disk
from ccproof.reparam import limit_surface
import numpy as np, flint  # noqa: E401
imports = time.perf_counter() - t
rows = []
for k in map(int, sys.argv[1].split(",")):
    a = time.perf_counter()
    valence_data(k)
    b = time.perf_counter()
    first_eval = None
    if k <= 64:  # a k-regular disk is a mesh of 8k faces: keep the evaluator's own set-up small
        S = limit_surface(k_regular_disk(k, 2))
        f, u, v = [0, 1, 2, 3], [0.1, 0.3, 0.5, 0.7], [0.2, 0.4, 0.6, 0.1]
        S.evaluate(f, u, v, parameterization="natural")   # the evaluator's own first-call costs
        c = time.perf_counter()
        S.evaluate(f, u, v, parameterization="characteristic")
        first_eval = time.perf_counter() - c
    rows.append((k, b - a, first_eval))
print(json.dumps({"imports": imports, "rows": rows, "sympy": "sympy" in sys.modules}))
"""


def first_call_costs(valences):
    """Run :data:`_FIRST_CALL` in a fresh interpreter: (import time, [(k, valence_data s, first eval s)],
    whether sympy got imported)."""
    import json

    out = subprocess.run([sys.executable, "-c", _FIRST_CALL, ",".join(map(str, valences))], check=True,
                         capture_output=True, text=True).stdout
    res = json.loads(out.strip().splitlines()[-1])
    return res["imports"], res["rows"], res["sympy"]


def help_startup(rounds=3):
    """Best wall time of ``python -m ccproof.cli --help`` over ``rounds`` runs (seconds)."""
    best = float("inf")
    for _ in range(rounds):
        a = time.perf_counter()
        subprocess.run([sys.executable, "-m", "ccproof.cli", "--help"], check=True, capture_output=True)
        best = min(best, time.perf_counter() - a)
    return best


def report_first_calls(valences):
    imports, rows, sympy_loaded = first_call_costs(valences)
    print(f"first call per new valence (fresh interpreter; imports {imports:.2f} s once; target <= 0.2 s):")
    for k, data_s, eval_s in rows:
        ev = "" if eval_s is None else (f", first characteristic evaluation of 4 points (after a natural one) "
                                        f"{eval_s * 1e3:7.1f} ms")
        print(f"  k = {k:5d}: valence_data {data_s * 1e3:7.1f} ms{ev}")
    print(f"sympy imported by the numerics: {'YES (regression)' if sympy_loaded else 'no'}")
    print(f"`ccproof --help` start-up: {help_startup() * 1e3:.0f} ms (best of 3; target < 300 ms)")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--mesh", default=str(DEFAULT_MESH), help="OBJ file or disk:K (k-regular disk, 4 rings)")
    ap.add_argument("--points", type=int, default=1_000_000)
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--derivatives", type=int, default=1, choices=(0, 1, 2))
    ap.add_argument("--backend", choices=("numba", "numpy"), default="numba")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--first-calls", default="3,5,7,13,100,1000",
                    help="comma-separated valences whose first-call cost is measured ('' to skip)")
    ap.add_argument("--sampling", choices=("uniform", "ev-faces"), default="uniform",
                    help="uniform: random face and (u, v); ev-faces: only faces with an extraordinary corner "
                    "(the worst case for the reparameterizations)")
    ap.add_argument("--smoke", action="store_true",
                    help="a 5-regular disk, 3,000 points, 2 rounds, numpy, first call of k = 5 (the test suite's run)")
    args = ap.parse_args(argv)
    if args.smoke:
        args.mesh, args.points, args.rounds, args.backend, args.first_calls = "disk:5", 3000, 2, "numpy", "5"
    os.environ["CCPROOF_BACKEND"] = args.backend
    if args.first_calls:
        report_first_calls([int(k) for k in args.first_calls.split(",")])
    if args.points <= 0:
        return

    from ccproof.evaluate.backend import available_backends
    from ccproof.reparam import corner_valence, limit_surface
    from ccproof.reparam.blend import face_map

    if args.backend == "numba" and "numba" not in available_backends():
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
        pool = np.flatnonzero(corner_valence(mesh).any(axis=1))
        f = pool[rng.integers(0, pool.size, n)]
    u, v = rng.random(n), rng.random(n)
    names = ("natural", "vanishing", "characteristic")
    warm = {}
    for p in names:  # first calls: numba compilation, Phi^-1 tables, rotated frames
        a = time.perf_counter()
        S.evaluate(f, u, v, args.derivatives, parameterization=p)
        warm[p] = time.perf_counter() - a
    cv, alpha = corner_valence(mesh)[f], S.parameterizations["vanishing"].alphas(S)
    act = {p: float(face_map(cv, u, v, p, alpha)["active"].mean()) for p in names[1:]}
    times = {p: [] for p in names}
    loads = []
    for _ in range(args.rounds):
        loads.append(load())
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
        print("  " + ratio_line(f"ratio {p}/natural:", r, loads))
    rc = statistics.median(a / b for a, b in zip(times["characteristic"], times["natural"]))
    print(f"target characteristic <= 4 x natural: {'met' if rc <= 4 else 'MISSED'} ({rc:.2f})")


if __name__ == "__main__":
    main()
