"""Benchmark of the qmv98 finite-element implementation (ccproof.apps.dynamics), one core.

  python scripts/bench_fem.py                       cube subdivided 2..6 times (98 ... 24,578 vertices) + fit
  python scripts/bench_fem.py --max-level 5 --json bench.json

For every mesh: the element layout, the assembly of M1 (unit mass, exact special-element sums) and K
(thin plate under tension, special elements truncated at L = 8), and the time of one implicit step of
eq. (31) (mu = gamma = 1, a = b = 1, dt = 0.01, random generalized force, Jacobi-preconditioned CG to a
relative residual of 1e-8, warm start) with the assembled matrix and element by element. Then the fit
of ~2,000 range points (the Stanford bunny's 2,038 scanned vertices in tests/data/meshes, or a
2,031-point synthetic block when that file is absent) from the 98-vertex model to 386 vertices.
The log-log slope of time against vertices is printed (1 = linear growth).

``--fit-large``: the fit of 20,000 points (synthetic ellipsoid, ``--fit-points``) from the 98-vertex model
up to 24,578 control vertices (4 subdivisions, ``--fit-levels``), in its own process: time and peak
memory (maximum resident set size; target <= 1 GB), with the data -> surface and two-sided errors.

  python scripts/bench_fem.py --fit-large --max-level 1 --no-fit
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import json  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _bench import load, ratio_line  # noqa: E402


def _timeit(fn, repeat=3):
    best = float("inf")
    out = None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def bench_levels(levels, matrix_free_max, steps=3):
    from ccproof.apps.dynamics.integrate import ImplicitIntegrator
    from ccproof.apps.dynamics.meshes import paper_initial_model
    from ccproof.apps.dynamics.model import DynamicSurface, Material

    rows = []
    for s in levels:
        mesh = paper_initial_model(subdivisions=s)
        t_layout, model = _timeit(lambda mesh=mesh: DynamicSurface(mesh, Material(), levels=8), 1)
        t_asm_first = time.perf_counter()
        model.assemble(1.0, 0.0)
        t_asm_first = time.perf_counter() - t_asm_first
        t_m, M1 = _timeit(lambda model=model: model.assemble(1.0, 0.0))
        t_k, K = _timeit(lambda model=model: model.assemble(0.0, 1.0))
        rng = np.random.default_rng(0)
        F = 0.1 * rng.standard_normal((model.n_vertices, 3))
        res = {}
        for mf in (False, True):
            if mf and model.n_vertices > matrix_free_max:
                continue
            integ = ImplicitIntegrator(model, 0.01, tol=1e-8, matrix_free=mf)
            t0 = time.perf_counter()
            integ.step(force=F)  # includes the assembly of the step matrix (or its diagonal)
            first = time.perf_counter() - t0
            t0 = time.perf_counter()
            infos = [integ.step(force=F) for _ in range(steps)]
            per = (time.perf_counter() - t0) / steps
            res["matrix_free" if mf else "assembled"] = {
                "first_step_s": first, "step_s": per, "cg_iterations": infos[-1].iterations,
                "residual": max(i.residual for i in infos)}
        rows.append({"subdivisions": s, "vertices": model.n_vertices, "faces": mesh.n_faces,
                     "normal": model.layout.n_normal, "special": model.layout.n_special, "nnz": K.nnz,
                     "layout_s": t_layout, "first_assembly_s": t_asm_first, "assemble_M1_s": t_m,
                     "assemble_K_s": t_k, **res})
        a = res["assembled"]
        mfs = f"{res['matrix_free']['step_s']:9.3f}" if "matrix_free" in res else "        -"
        print(f"{s:3d} {model.n_vertices:8d} {K.nnz:9d} {t_layout:8.3f} {t_m:8.3f} {t_k:8.3f} "
              f"{a['step_s']:9.3f} {a['cg_iterations']:5d} {mfs}", flush=True)
    return rows


def slope(rows, key):
    x = np.log([r["vertices"] for r in rows])
    y = np.log([max(key(r), 1e-9) for r in rows])
    big = x >= np.log(1000)
    if big.sum() < 2:
        big = np.ones_like(x, dtype=bool)
    return float(np.polyfit(x[big], y[big], 1)[0])


def bench_fit():
    from ccproof.apps.dynamics.fit import fit_points, read_points
    from ccproof.apps.dynamics.shapes import synthetic_range_data

    bunny = Path(__file__).resolve().parents[1] / "tests" / "data" / "meshes" / "bunny_quads.obj"
    if bunny.exists():
        name, X = "Stanford bunny, scanned vertices", read_points(bunny)
    else:
        name, X = "synthetic superquadric", synthetic_range_data("superquadric")
    t0 = time.perf_counter()
    res = fit_points(X, levels=1)
    total = time.perf_counter() - t0
    print(f"fit of {X.shape[0]} points ({name}): {total:.1f} s in all")
    for lev in res.levels:
        print(f"   {lev.n_vertices:4d} vertices: {lev.steps:3d} steps, {lev.cg_iterations:5d} CG iterations, "
              f"{lev.seconds:5.1f} s, max error {lev.max_error_percent:.2f} %, mean {lev.mean_error_percent:.3f} % "
              f"of the enclosing-sphere diameter")
    return {"data": name, "points": int(X.shape[0]), "total_s": total,
            "levels": [lev.__dict__ for lev in res.levels]}


def one_fit(points, levels, max_steps):
    """Child process of --fit-large: one fit, printed as one JSON line."""
    import resource

    from ccproof.apps.dynamics.fit import Evolution, fit_points
    from ccproof.apps.dynamics.shapes import synthetic_range_data

    X = synthetic_range_data("ellipsoid", points)
    t0 = time.perf_counter()
    res = fit_points(X, levels=levels, evolution=Evolution(max_steps=max_steps))
    total = time.perf_counter() - t0
    print(json.dumps({
        "points": points, "levels": [lev.__dict__ for lev in res.levels], "total_s": total,
        "max_error_percent": res.max_error_percent, "two_sided_error_percent": res.two_sided_error_percent,
        "stray_fraction": res.surface_report["stray_fraction"], "warnings": res.warnings,
        "peak_rss_gb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e6}, default=float))


def bench_fit_large(points, levels, max_steps, target_gb=1.0):
    import subprocess
    import sys

    p = subprocess.run([sys.executable, __file__, "--one-fit", str(points), str(levels), str(max_steps)],
                       capture_output=True, text=True)
    if p.returncode:
        print(p.stderr[-3000:])
        return {"error": p.stderr[-500:]}
    r = json.loads(p.stdout.strip().splitlines()[-1])
    print(f"fit of {points} points up to {r['levels'][-1]['n_vertices']} control vertices: {r['total_s']:.1f} s, "
          f"peak memory {r['peak_rss_gb']:.2f} GB (target <= {target_gb} GB: "
          f"ratio {r['peak_rss_gb'] / target_gb:.2f}); "
          f"max error {r['max_error_percent']:.3f} %, two-sided {r['two_sided_error_percent']:.3f} %")
    for lev in r["levels"]:
        print(f"   {lev['n_vertices']:6d} vertices: {lev['steps']:3d} steps{'' if lev['converged'] else ' (cap)'}, "
              f"{lev['seconds']:6.1f} s, max error {lev['max_error_percent']:.3f} %")
    return r


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--fit-large", action="store_true", help="the 20k-point fit up to 24,578 vertices")
    ap.add_argument("--fit-points", type=int, default=20000)
    ap.add_argument("--fit-levels", type=int, default=4)
    ap.add_argument("--fit-max-steps", type=int, default=60)
    ap.add_argument("--one-fit", nargs=3, type=int, help=argparse.SUPPRESS)
    ap.add_argument("--max-level", type=int, default=6, help="largest number of cube subdivisions (default 6)")
    ap.add_argument("--matrix-free-max", type=int, default=30000,
                    help="skip the element-by-element step above this many vertices")
    ap.add_argument("--no-fit", action="store_true")
    ap.add_argument("--json", default=None, help="write the numbers here")
    ap.add_argument("--smoke", action="store_true", help="the cube subdivided 1 and 2 times, no fit (the test "
                    "suite's run)")
    args = ap.parse_args(argv)
    if args.one_fit:
        one_fit(*args.one_fit)
        return 0
    print("subdivisions, vertices, nnz(K), layout s, assemble M1 s, assemble K s, implicit step (31) s "
          "(assembled), CG iterations, step s (element by element)")
    load0 = load()
    rows = bench_levels(range(1, 3) if args.smoke else range(2, args.max_level + 1), args.matrix_free_max)
    both = [r for r in rows if "matrix_free" in r]
    if both:  # the element-by-element step is the baseline of the assembled one
        print(ratio_line("implicit step assembled / element by element, over the meshes:",
                         [r["assembled"]["step_s"] / r["matrix_free"]["step_s"] for r in both], [load0, load()]))
    if args.smoke:
        return 0
    if len(rows) >= 2:  # --max-level 1 measures no mesh (the --fit-large run alone)
        print(f"log-log slopes (>= 1k vertices): assemble K {slope(rows, lambda r: r['assemble_K_s']):.2f}, "
              f"step {slope(rows, lambda r: r['assembled']['step_s']):.2f}")
    out = {"levels": rows}
    if not args.no_fit:
        out["fit"] = bench_fit()
    if args.fit_large:
        out["fit_large"] = bench_fit_large(args.fit_points, args.fit_levels, args.fit_max_steps)
    if args.json:
        Path(args.json).write_text(json.dumps(out, indent=1, default=float))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
