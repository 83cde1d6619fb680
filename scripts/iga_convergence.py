#!/usr/bin/env python
"""Convergence of a Galerkin solution of -Laplace_Gamma u + u = f on a closed Catmull-Clark limit surface.

Manufactured solution u = sin(x) cos(y) exp(z/2) restricted to the surface (f exact from the surface's
normal and mean curvature); the space is spanned by the limit functions of the control vertices
(LimitSurface.basis), the mesh refined uniformly per level. Prints per level the faces, dofs, L2 and H1
(seminorm) errors and the rates log2(e_(L-1)/e_L) (per sqrt(dofs)), and last ``rates: L2 X H1 Y`` (the
last level's). See docs/iga.md.

Usage:
  python scripts/iga_convergence.py --mesh cube|icosahedron|prism6|torus [--levels 5] [--start 0]
         [--rule adaptive|plain|split] [--parameterization natural|characteristic] [--order 4] [--depth 12]
         [--space graded [--margin 1] [--width 0.5] | --graded EXTRA] [--rings 5]
  python scripts/iga_convergence.py --mesh grid|annulus|ogrid|disk5 [--bc dirichlet|neumann] [--ghost] ...
  python scripts/iga_convergence.py --mesh fan3|fan5 --bc neumann [--ghost [--space graded --start 2]] ...
         (a boundary vertex with 3 or 5 faces; u = y^3 cos(pi x); graded toward it with --ghost, Neumann)
  python scripts/iga_convergence.py --mesh torus|cube|... --problem biharmonic ...
  python scripts/iga_convergence.py --mesh grid --problem plate [--support clamped|simple] [--levels 5]

The default rule is "adaptive" (dyadic rings toward the extraordinary vertices) with the natural
parameterization and "split" (cells cut at the blend's breakpoints) with the characteristic one.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from ccproof.apps.iga.convergence import (  # noqa: E402
    OPEN_MESHES,
    PROBLEMS,
    STUDY_MESHES,
    convergence_study,
    fit_rate,
    rates,
)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--mesh", choices=STUDY_MESHES + OPEN_MESHES, default="cube")
    ap.add_argument("--levels", type=int, default=5)
    ap.add_argument("--start", type=int, default=0, help="first level")
    ap.add_argument("--rule", choices=("adaptive", "plain", "split"), default=None)
    ap.add_argument("--parameterization", choices=("natural", "characteristic"), default="natural")
    ap.add_argument("--order", type=int, default=4)
    ap.add_argument("--depth", type=int, default=12)
    ap.add_argument("--space", choices=("uniform", "graded"), default="uniform",
                    help="graded: the hierarchical space refined toward every EV as deep as its eigenvalue "
                         "needs for the regular rates at each level (graded_levels; rates per sqrt(dofs))")
    ap.add_argument("--margin", type=int, default=1, help="--space graded: levels beyond graded_levels' minimum")
    ap.add_argument("--width", type=float, default=0.5,
                    help="--space graded: where the grading starts, in level-0 faces (graded_rings; 0: --rings "
                         "rings at every level)")
    ap.add_argument("--graded", type=int, default=None, metavar="EXTRA",
                    help="the hierarchical space graded EXTRA levels toward every EV at every level")
    ap.add_argument("--rings", type=int, default=5, help="face rings refined around every EV (graded spaces)")
    ap.add_argument("--bc", choices=("dirichlet", "neumann"), default="dirichlet", help="open meshes")
    ap.add_argument("--ghost", action="store_true",
                    help="open meshes: a ring of ghost control vertices (free) outside the boundary")
    ap.add_argument("--problem", choices=PROBLEMS, default="screened",
                    help="-Laplace u + u = f, Laplace^2 u + u = f (closed meshes), or the clamped plate "
                         "Delta^2 w = f (--mesh grid: the unit square); the last two also print the H2 error")
    ap.add_argument("--support", choices=("clamped", "simple"), default="clamped", help="--problem plate")
    a = ap.parse_args(argv)
    rule = a.rule or ("adaptive" if a.parameterization == "natural" else "split")
    graded = None if a.graded is None else (a.graded, a.rings)
    space = "uniform" if graded is None else f"graded {a.graded} levels over {a.rings} rings toward the EVs"
    if a.space == "graded":
        graded = (f"auto:{a.margin}", a.rings, a.width)
        space = (f"graded toward the EVs (graded_levels with margin {a.margin}, "
                 + (f"graded_rings width {a.width:g}, at least {a.rings} rings)" if a.width > 0 else
                    f"{a.rings} rings per level)"))
    if a.mesh in OPEN_MESHES:
        space += f", {a.bc} boundary, " + ("ghost ring (Nitsche if Dirichlet)" if a.ghost else
                                            "OpenSubdiv EDGE_ONLY space (strong if Dirichlet)")
    if a.problem == "plate":
        sol = "sin^2(pi x) sin^2(pi y)" if a.support == "clamped" else "sin(pi x) sin(pi y)"
        print(f"plate problem ({a.support}, w = {sol}), the unit square with a ghost ring, level L at "
              "mesh size 1/(4 2^L), plain rule (order 4)", flush=True)
    else:
        print(f"{a.problem} problem, mesh {a.mesh}, {space}, {a.parameterization} parameterization, {rule} rule "
              f"(order {a.order}, depth {a.depth})", flush=True)
    h2 = a.problem in ("biharmonic", "plate")
    print(f"{'level':>5} {'faces':>8} {'dofs':>8} {'L2 error':>12} {'rate':>6} {'H1 error':>12} {'rate':>6}"
          + (f" {'H2 error':>12} {'rate':>6}" if h2 else "")
          + (f"   {'per level L2':>15} {'H1':>5}" if graded is not None else "") + f" {'time':>7}")
    rows = []
    t0 = time.perf_counter()
    per = "level" if graded is None else "dofs"
    options = {"order": a.order, "depth": a.depth, "bc": a.bc, "ghost": a.ghost, "support": a.support}
    for r in convergence_study(a.mesh, a.levels, rule, a.parameterization, start=a.start, graded=graded,
                               problem=a.problem, options=options):
        rows.append(r)
        r2, r1 = rates(rows, "L2", per)[-1], rates(rows, "H1", per)[-1]
        extra = f" {r['H2']:12.4e} {rates(rows, 'H2', per)[-1]:6.2f}" if h2 else ""
        if graded is not None:
            extra = f"   per level {rates(rows, 'L2')[-1]:5.2f} {rates(rows, 'H1')[-1]:5.2f}"
        print(f"{r['level']:5d} {r['faces']:8d} {r['dofs']:8d} {r['L2']:12.4e} {r2:6.2f} {r['H1']:12.4e} {r1:6.2f}"
              f"{extra} {time.perf_counter() - t0:6.1f}s", flush=True)
        if graded is not None:
            print("      errors on the leaves of levels L, L+1, ...: "
                  + ", ".join(f"{a:.2e} / {b:.2e}" for a, b in r["leaves"]), flush=True)
    if graded is not None:
        per_level = " ".join(f"{k} {rates(rows, k)[-1]:.2f}" for k in ("L2", "H1"))
        print(f"last rates per level (h halves, the refinement toward the EVs deepens): {per_level}")
    if len(rows) >= 3:
        fit = " ".join(f"{k} {fit_rate(rows, k, per):.2f}" for k in ("L2", "H1", "H2") if k in rows[0])
        print(f"fitted rates (all levels, per {'level' if per == 'level' else 'sqrt(dofs)'}): {fit}")
    r2, r1 = rates(rows, "L2", per)[-1], rates(rows, "H1", per)[-1]
    print(f"rates: L2 {r2:.2f} H1 {r1:.2f}" if not math.isnan(r2) else "rates: L2 nan H1 nan")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
