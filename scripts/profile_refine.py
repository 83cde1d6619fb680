#!/usr/bin/env python
"""Where :meth:`ccproof.mesh.PolyMesh.refine`'s time goes: cProfile of one refine (functions by cumulative time),
and the child's topology alone, derived (:meth:`ccproof.mesh.halfedges.HalfEdges.refined`) against paired from
the child's faces (with the fans and repeated edges the constructor reads), the fastest of ``--reps`` calls.

Meshes: an icosphere of ``--tri-levels`` (default 6: 81,920 triangles) and catmark_cubes_infsharp subdivided
``--cube-levels`` times (default 5: 24,576 quads, semi-sharp and infinite creases).

Usage: python scripts/profile_refine.py [--tri-levels 6] [--cube-levels 5] [--reps 5]
"""

from __future__ import annotations

import argparse
import cProfile
import io
import pstats
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_step import _icosphere  # noqa: E402

from ccproof.mesh import PolyMesh  # noqa: E402
from ccproof.mesh.halfedges import HalfEdges  # noqa: E402
from ccproof.mesh.io import read_mesh  # noqa: E402

DATA = Path(__file__).resolve().parent.parent / "tests" / "data" / "osd_features" / "meshes"


def _fastest(f, reps):
    ts = []
    for _ in range(reps):
        t = time.perf_counter()
        f()
        ts.append(time.perf_counter() - t)
    return min(ts)


def _paired(c):
    q = HalfEdges(c.org, c.offsets, c.n_vertices, c.options)
    q.fan_of_corner, q.repeat_edge  # noqa: B018 (what the constructor reads)
    return q


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--tri-levels", type=int, default=6)
    ap.add_argument("--cube-levels", type=int, default=5)
    ap.add_argument("--reps", type=int, default=5)
    a = ap.parse_args()
    V, F = _icosphere(a.tri_levels)
    cube = read_mesh(DATA / "catmark_cubes_infsharp.obj").manifold
    for _ in range(a.cube_levels):
        cube, _ = cube.refine(operator=False)
    for name, pm in ((f"icosphere ({F.shape[0]:,} triangles)", PolyMesh(V, F)),
                     (f"catmark_cubes_infsharp level {a.cube_levels} ({cube.n_faces:,} faces, "
                      f"{len(cube.edge_sharpness)} creases)", cube)):
        pm.refine(operator=False)  # warm-up
        print(f"== {name}: refine {_fastest(lambda pm=pm: pm.refine(operator=False), a.reps) * 1e3:.1f} ms, "
              f"its step {_fastest(lambda pm=pm: pm._step(sparse=False), a.reps) * 1e3:.1f} ms")
        c = HalfEdges.refined(pm.halfedges)
        derived = _fastest(lambda pm=pm: HalfEdges.refined(pm.halfedges), a.reps)
        print(f"   child topology: derived {derived * 1e3:.1f} ms, "
              f"paired with fans and repeated edges {_fastest(lambda c=c: _paired(c), a.reps) * 1e3:.1f} ms")
        prof = cProfile.Profile()
        prof.enable()
        pm.refine(operator=False)
        prof.disable()
        out = io.StringIO()
        pstats.Stats(prof, stream=out).sort_stats("cumulative").print_stats(14)
        print(out.getvalue())


if __name__ == "__main__":
    main()
