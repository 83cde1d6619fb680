#!/usr/bin/env python
"""Convergence of the Kirchhoff-Love shell benchmarks on Catmull-Clark limit surfaces toward their references.

The Scordelis-Lo roof (R = 25, L = 50, 40 degrees, t = 0.25, E = 4.32e8, nu = 0, gravity 90 per area, rigid
diaphragms at the curved ends): level L has n = 2^(L+1) faces across and along; printed per level the
faces, the free dofs, the downward displacement w at the midpoint of a free edge and its relative error
against 0.3024 (and 0.3006). ``roof-ev``: the same roof on a mesh with extraordinary vertices (four of
valence 3, four of valence 5 around the crown's centre), 4 x 4 faces at level 0, subdivided per level.
The pinched cylinder (R = 300, L = 600, t = 3, E = 3e6, nu = 0.3, unit forces): level L has n = 2^(L+3)
faces around and n/2 along; w the radial displacement under a force, against 1.8248e-5. The hemisphere
with an 18-degree hole (R = 10, t = 0.04, E = 6.825e7, nu = 0.3, four radial forces of 2 alternating in sign
on the equator; both circular edges free): level L has n = 2^(L+1) faces from the equator to the hole and
4 n around; w the radial displacement under a force, against 0.0924 (and 0.094), with its change from the
level before. ``hemisphere-ev``: the same shell with an o-grid block centred at each load point (per block
four vertices of valence 3 and four of valence 5 beside the free equator), 16 x 4 faces at level 0,
subdivided per level, the adaptive rule. See docs/iga.md.

Usage:
  python scripts/iga_shell.py [--benchmark roof|roof-ev|pinched|hemisphere|hemisphere-ev] [--levels 5] [--start 0]
         [--ends exact|edge|rows]
         [--geometry interpolated|mapped]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from ccproof.apps.iga.shell_benchmarks import (  # noqa: E402
    END_CONDITIONS,
    PINCHED_CYLINDER_REFERENCE,
    SCORDELIS_LO_REFERENCE,
    pinched_cylinder,
    scordelis_lo,
    scordelis_lo_ev,
)
from ccproof.apps.iga.shell_hemisphere import (  # noqa: E402
    HEMISPHERE_HOLE_REFERENCE,
    HEMISPHERE_REFERENCE,
    hemisphere_ev,
    hemisphere_with_hole,
)

#: the Kirchhoff-Love value of the roof quoted beside 0.3024 (e.g. Kiendl et al. 2009)
ROOF_KL = 0.3006


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--benchmark", default="roof",
                    choices=("roof", "roof-ev", "pinched", "hemisphere", "hemisphere-ev"))
    ap.add_argument("--levels", type=int, default=5)
    ap.add_argument("--start", type=int, default=0, help="first level")
    ap.add_argument("--ends", choices=END_CONDITIONS, default="exact",
                    help="roof: how the diaphragms are imposed (exact: ghost rows, c_-1 = -4 c_0 - c_1; edge: "
                         "EDGE_ONLY ends, end rows fixed; rows: ghost and end rows fixed)")
    ap.add_argument("--geometry", choices=("interpolated", "mapped"), default="interpolated",
                    help="roof-ev: control points whose limit interpolates the cylinder at the vertices, or "
                         "placed on it (the lattice's radius)")
    a = ap.parse_args(argv)
    if a.benchmark.startswith("hemisphere"):
        return _hemisphere(a)
    roof = a.benchmark != "pinched"
    ref = SCORDELIS_LO_REFERENCE if roof else PINCHED_CYLINDER_REFERENCE
    what = {"roof": f"Scordelis-Lo roof, diaphragms {a.ends}", "pinched": "pinched cylinder, whole cylinder",
            "roof-ev": f"Scordelis-Lo roof with EVs (valence 3 and 5), {a.geometry} geometry"}[a.benchmark]
    print(f"{a.benchmark}: {what}, reference {ref}" + (f" ({ROOF_KL})" if roof else ""))
    head = f"{'level':>5} {'faces':>9} {'dofs':>7} {'w':>12} {'rel. error':>11}"
    print(head + (f" {'vs ' + str(ROOF_KL):>11}" if roof else "") + f" {'time s':>7}")
    for level in range(a.start, a.start + a.levels):
        t0 = time.perf_counter()
        if a.benchmark == "roof-ev":
            n = 4 * 2**level
            r, faces = scordelis_lo_ev(level, geometry=a.geometry), f"{n} x {n}"
        elif roof:
            n = 2 ** (level + 1)
            r, faces = scordelis_lo(n, ends=a.ends), f"{n} x {n}"
        else:
            n = 2 ** (level + 3)
            r, faces = pinched_cylinder(n), f"{n} x {n // 2}"
        dt = time.perf_counter() - t0
        line = f"{level:>5} {faces:>9} {r['dofs']:>7,} {r['w']:>12.6g} {r['w'] / ref - 1:>+11.2e}"
        print(line + (f" {r['w'] / ROOF_KL - 1:>+11.2e}" if roof else "") + f" {dt:>7.1f}", flush=True)


def _hemisphere(a):
    ref, other = HEMISPHERE_HOLE_REFERENCE, HEMISPHERE_REFERENCE
    ev = a.benchmark == "hemisphere-ev"
    what = "o-grid blocks at the loads (valence 3 and 5)" if ev else "regular grid"
    print(f"{a.benchmark}: 18-degree hole, free circular edges, whole shell, {what}, reference {ref} ({other})")
    print(f"{'level':>5} {'faces':>9} {'dofs':>7} {'w':>12} {'vs ' + str(ref):>11} {'vs ' + str(other):>11} "
          f"{'change':>10} {'time s':>7}")
    prev = None
    for level in range(a.start, a.start + a.levels):
        t0 = time.perf_counter()
        n = 4 * 2**level if ev else 2 ** (level + 1)
        r = hemisphere_ev(level) if ev else hemisphere_with_hole(n)
        dt = time.perf_counter() - t0
        change = "" if prev is None else f"{r['w'] - prev:+.2e}"
        print(f"{level:>5} {f'{4 * n} x {n}':>9} {r['dofs']:>7,} {r['w']:>12.6g} {r['w'] / ref - 1:>+11.2e} "
              f"{r['w'] / other - 1:>+11.2e} {change:>10} {dt:>7.1f}", flush=True)
        prev = r["w"]


if __name__ == "__main__":
    main()
