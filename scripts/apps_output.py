"""What a user who takes the applications' output elsewhere gets: the numbers of docs/hsh10.md section 8 and
docs/qmv98.md section 4 ("Equilibrium"), printed, not estimated.

  python scripts/apps_output.py --arap     # bunny, 16 charts: control UVs under OpenSubdiv's corners-only rule
  python scripts/apps_output.py --fit      # bunny scan: fit steps, energy, criterion, two-sided error

--arap: for --refine 0 and the default, method (c) on the bunny's 16 normal-segmented charts; then the folds
(UV quads with a corner triangle of signed area <= 0) of the control UVs subdivided with the face-varying
"corners only" rule at levels 1-3, and the distortion of that texture at the metric level (the same samples as
the exact texture): first for the (c) control UVs as they were written before (the chart's own unknowns), then
for :func:`ccproof.apps.arap.fvar.export_control` (fit + polish under the rule, extra subdivisions).
--fit: ``fit_points`` with the defaults on the scan's 2,038 vertices, and an independent two-sided distance
(exact limit points of the fitted control mesh subdivided 4 times, scipy k-d trees both ways).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

BUNNY = Path(__file__).resolve().parents[1] / "tests" / "data" / "meshes" / "bunny_quads.obj"


def _fmt(m):
    return f"E_angle {m.E_angle:.6f}  E_area {m.E_area:.6f}  E_stretch {m.E_stretch:.6f}"


def arap(eval_level):
    from ccproof.apps.arap.charts import segment_by_normals
    from ccproof.apps.arap.core import ChartTexture, auto_refine, compare, texture_metrics
    from ccproof.apps.arap.fvar import FOLD_LEVELS, export_control, subdivided_folds
    from ccproof.apps.arap.hierarchy import ChartHierarchy
    from ccproof.apps.arap.metrics import Metrics
    from ccproof.mesh import read_obj

    mesh = read_obj(BUNNY)
    labels = segment_by_normals(mesh)
    print(f"bunny: {mesh.n_faces} faces, {labels.max() + 1} charts; metrics at level {eval_level} "
          f"(E_angle, E_area minimum 2, E_stretch minimum 1); folds at levels {FOLD_LEVELS}")
    for refine in (0, auto_refine(mesh, labels)):
        t0 = time.perf_counter()
        res, _ = compare(mesh, labels, methods=("c",), levels=3, eval_level=eval_level, refine=refine,
                         release=True, accel=5)
        r = res["c"]
        t1 = time.perf_counter()
        print(f"\n--refine {refine}: exact texture (c)            {_fmt(r.metrics)}   ({t1 - t0:.1f} s)")
        folds, met = np.zeros(len(FOLD_LEVELS), dtype=np.int64), Metrics()
        for tex in r.textures:  # the former --control-out: the chart's (c) unknowns under the corners-only rule
            h = tex.hierarchy
            hc = ChartHierarchy(h.surface, h.chart_faces, surface_corners=True)
            Y = tex.unknowns[: hc.n_chart_vertices]
            folds += subdivided_folds(hc, Y)
            met = met + texture_metrics(ChartTexture(hc, "boundary", 0, hc.lift_unknowns(Y, "boundary"), Y),
                                        eval_level - refine)
            hc.release()
            h.release()
        print(f"  (c) control UVs as written before:      {_fmt(met)}   folds {folds.tolist()}")
        t2 = time.perf_counter()
        exp = export_control(r, eval_level=eval_level, levels=3, max_faces=150_000)  # the CLI's defaults
        t3 = time.perf_counter()
        for extra, f, m in exp.tried:
            print(f"  corners-only UVs, {extra} extra subdivision(s): {_fmt(m)}   folds {f}")
        er = exp.excess_ratio()
        print(f"  written: {exp.extra} extra ({exp.mesh.n_faces} control faces), excess / exact "
              f"{er[0]:.3f} {er[1]:.3f} {er[2]:.3f}, within 5 %: {exp.accepted} ({t3 - t2:.1f} s)")


def fit():
    from scipy.spatial import cKDTree

    from ccproof.apps.dynamics.fit import fit_points, read_points
    from ccproof.mesh import subdivide
    from ccproof.mesh.masks import limit_positions

    X = read_points(BUNNY)
    t0 = time.perf_counter()
    res = fit_points(X, levels=1)
    t1 = time.perf_counter()
    print(f"bunny scan: {X.shape[0]} points, defaults (tol {res.parameters['tol']:g}, cap "
          f"{res.parameters['max_steps']} steps), {t1 - t0:.1f} s")
    for i, lev in enumerate(res.levels):
        print(f"  level {i}: {lev.n_vertices} vertices, {lev.steps} steps, energy {lev.energy:.6g}, energy change "
              f"{lev.energy_change:.2g}, mean-error change {lev.error_change:.2g}, max / mean error "
              f"{lev.max_error_percent:.3f} / {lev.mean_error_percent:.4f} %: {lev.reason}")
    print(f"  reported: data -> surface {res.max_error_percent:.3f} %, surface -> data "
          f"{res.surface_max_percent:.3f} %, two-sided {res.two_sided_error_percent:.3f} % "
          f"(of the enclosing-sphere diameter)")
    m = res.mesh
    for _ in range(4):
        m = subdivide(m)
    S = limit_positions(m)
    h = float(np.max(np.linalg.norm(S[m.faces[:, 0]] - S[m.faces[:, 2]], axis=1)))
    d1 = cKDTree(S).query(X)[0].max()
    d2 = cKDTree(X).query(S)[0].max()
    D = res.diameter
    print(f"  independent ({S.shape[0]} limit points, spacing <= {100 * h / D:.3f} %): data -> surface "
          f"{100 * d1 / D:.3f} %, surface -> data {100 * d2 / D:.3f} %, two-sided {100 * max(d1, d2) / D:.3f} %")
    print(f"  warnings: {res.warnings or 'none'}")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--arap", action="store_true")
    ap.add_argument("--fit", action="store_true")
    ap.add_argument("--eval-level", type=int, default=4, help="metric level of --arap (default 4)")
    a = ap.parse_args(argv)
    if not (a.arap or a.fit):
        ap.error("give --arap and/or --fit")
    if a.fit:
        fit()
    if a.arap:
        arap(a.eval_level)


if __name__ == "__main__":
    main()
