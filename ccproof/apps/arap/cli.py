"""ARAP parameterization of a Catmull-Clark subdivision surface (He, Schaefer, Hormann 2010).

Optimizes the texture control points of every chart so that the subdivided texture maps the LIMIT
surface as rigidly as possible (hsh10 Eq. 3), with a multi-resolution schedule over the levels
start..K, either with extended charts (hsh10 (c), default) or with boundary rules (b). Charts are
per-face integer labels (--charts FILE, one per face in OBJ order; negative = no chart) or a simple
segmentation (--segment normals); without either the whole mesh must be a topological disk.

Prints E_angle, E_area, E_stretch (hsh10 section 4, at --eval-level, default 5), flipped texture
triangles of the control mesh and flipped samples at the evaluation level, seconds and iterations.
With --baselines also (a) ARAP on the triangulated control mesh, the other variant, and (d) ARAP on
the control mesh subdivided 3 times, all measured the same way.

Output for other tools (--out FILE): the limit surface sampled at --out-level (default 3) as a
triangle (or --cells quad) mesh whose per-vertex UVs are the parameterization evaluated exactly at
the limit points; charts packed into [0, 1]^2 without overlap (shelf packing, one common scale);
seams as duplicated vertices (one UV per chart). FILE.obj is written directly (v, vt, f i/i), any
other extension through meshio (point data "uv"; PLY: "s", "t"); FILE.json holds the metrics, the
packing scale and the written triangles' own distortion. --control-out FILE.obj writes the control
mesh with its texture control points and states the subdivision rule they need.

Example:  ccproof arap bunny_quads.obj --segment normals --baselines --out bunny_uv.obj
"""

from __future__ import annotations

import json
import sys

__all__ = ["add_arguments", "run", "format_table"]


def add_arguments(parser):
    parser.add_argument("mesh", help="all-quad OBJ control mesh")
    parser.add_argument("--charts", metavar="LABELS", help="chart label file: one integer per face")
    parser.add_argument("--segment", choices=["normals"], help="segment into charts (when no --charts)")
    parser.add_argument("--variant", choices=["extended", "boundary"], default="extended",
                        help="chart boundary treatment: extended charts (c) or boundary rules (b)")
    parser.add_argument("--levels", type=int, default=3, metavar="K", help="finest optimization level (default 3)")
    parser.add_argument("--start-level", type=int, default=1, help="coarsest optimization level (default 1)")
    parser.add_argument("--eval-level", type=int, default=5, help="level of the metric samples (default 5)")
    parser.add_argument("--tol", type=float, default=1e-6, help="relative energy decrease to stop a level")
    parser.add_argument("--max-iter", type=int, default=1000, help="iterations per level at most")
    parser.add_argument("--baselines", action="store_true", help="also run (a), the other variant and (d)")
    parser.add_argument("--engine", choices=["auto", "numpy", "igl"], default="auto",
                        help="triangle ARAP engine of the baselines (auto: libigl if installed)")
    parser.add_argument("--out", metavar="FILE",
                        help="write the limit surface sampled at --out-level with exact UVs (.obj, or any "
                             "meshio format such as .vtu .ply), plus FILE.json")
    parser.add_argument("--out-level", type=int, default=3, help="sampling level of --out (default 3)")
    parser.add_argument("--cells", choices=["triangle", "quad"], default="triangle", help="cells of --out")
    parser.add_argument("--control-out", metavar="UV.obj",
                        help="write the control mesh with texture control points (OBJ with vt, plus UV.obj.json)")
    parser.add_argument("--labels-out", metavar="FILE", help="write the chart labels used")


def format_table(results, eval_level=5):
    """The comparison table as text (one row per method)."""
    head = (f"{'method':<30} {'E_angle':>9} {'E_area':>9} {'E_stretch':>9} {'flips T0':>11} "
            f"{'flips L' + str(eval_level):>9} {'seconds':>8} {'iters':>6}")
    rows = [head, "-" * len(head)]
    for r in results.values():
        m = r.metrics
        rows.append(
            f"{r.name:<30} {m.E_angle:9.6f} {m.E_area:9.6f} {m.E_stretch:9.6f} "
            f"{f'{r.flips_control}/{r.triangles_control}':>11} {m.flips:>9d} {r.seconds:8.2f} {r.iterations:6d}"
        )
    return "\n".join(rows)


def run(args) -> int:
    from ccproof.apps.arap.charts import read_labels, segment_by_normals, write_labels
    from ccproof.apps.arap.core import VARIANTS, compare
    from ccproof.apps.arap.export import sampled_surface, write_surface
    from ccproof.apps.arap.io import write_uv_obj
    from ccproof.mesh import read_obj

    mesh = read_obj(args.mesh)
    if args.charts:
        labels = read_labels(args.charts, mesh.n_faces)
    elif args.segment == "normals":
        labels = segment_by_normals(mesh)
    else:
        labels = None
    if args.labels_out and labels is not None:
        write_labels(args.labels_out, labels)
    ours = VARIANTS[args.variant]
    methods = [ours]
    engine = args.engine
    if args.baselines:
        other = "b" if ours == "c" else "c"
        methods = ["a", other, ours, "d"]
        methods = sorted(set(methods), key="abcd".index)
        if engine == "auto":
            try:
                import igl  # noqa: F401

                engine = "igl"
            except ImportError:
                engine = "numpy"
    elif engine == "auto":
        engine = "numpy"
    results, _ = compare(mesh, labels, methods, levels=args.levels, start_level=args.start_level,
                         eval_level=args.eval_level, tol=args.tol, max_iter=args.max_iter, engine=engine)
    nch = len(results[ours].textures)
    print(f"{args.mesh}: {mesh.n_vertices} vertices, {mesh.n_faces} faces, {nch} chart(s); "
          f"levels {args.start_level}..{args.levels}, metrics at level {args.eval_level}, baseline engine {engine}")
    print(format_table(results, args.eval_level))
    lv = results[ours].levels
    for k in range(len(lv[0]) if lv and lv[0] else 0):
        its = sum(c[k].iterations for c in lv)
        spi = sum(c[k].seconds for c in lv) / max(its, 1)
        e0 = sum(c[k].energy_start for c in lv)
        e1 = sum(c[k].energy_end for c in lv)
        print(f"  {results[ours].name}: level {lv[0][k].level}: {its} iterations, "
              f"{1e3 * spi:.2f} ms per chart iteration, energy {e0:.6g} -> {e1:.6g}, "
              f"converged: {all(c[k].converged for c in lv)}")
    table = {
        m: {"E_angle": r.metrics.E_angle, "E_area": r.metrics.E_area, "E_stretch": r.metrics.E_stretch,
            "flips_control": r.flips_control, "flips_eval": r.metrics.flips, "seconds": r.seconds,
            "iterations": r.iterations}
        for m, r in results.items()
    }
    comment = f"ccproof arap {args.mesh}: {results[ours].name}, levels {args.start_level}..{args.levels}"
    surf = None
    if args.out or args.control_out:
        surf = sampled_surface(results[ours], args.out_level, args.cells)
    if args.out:
        write_surface(args.out, surf, comment)
        wm = surf.metrics()
        info = {"method": ours, "level": surf.level, "cells": surf.cell_type, "uv_scale": surf.scale,
                "folds": surf.folds(), "seams": "vertices duplicated per chart",
                "written_triangles": {"E_angle": wm.E_angle, "E_area": wm.E_area, "E_stretch": wm.E_stretch,
                                      "note": "E_area at the natural UV scale: divide the file's UVs by uv_scale"},
                "table": table}
        with open(args.out + ".json", "w", encoding="utf-8") as fh:
            json.dump(info, fh, indent=1)
        print(f"wrote {args.out} (level {surf.level}: {surf.points.shape[0]} vertices, {surf.cells.shape[0]} "
              f"{surf.cell_type}s, {surf.folds()} folded; written triangles E_angle {wm.E_angle:.6f} "
              f"E_area {wm.E_area:.6f} E_stretch {wm.E_stretch:.6f}) and {args.out}.json")
    if args.control_out:
        side = write_uv_obj(args.control_out, mesh, results[ours], comment=comment, table=table,
                            transforms=surf.transforms, scale=surf.scale)
        print(f"wrote {args.control_out} and {side}")
    sys.stdout.flush()
    return 0
