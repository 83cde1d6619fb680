#!/usr/bin/env python
"""A/B benchmark of :meth:`ccproof.mesh.PolyMesh.refine` on the vectorized step against the former refine.

The former ``refine`` (the exact stencils of :func:`ccproof.mesh.rules.refine_complex`, one vertex and
edge at a time, each row rounded and summed; kept below verbatim as the baseline, ``operator=False``) and
the current one (:func:`ccproof.mesh.step.catmark_operator`), in one process, taking turns round by round
(min, median, max of the ratio new / old per round; the 1-minute load before each round). Before timing,
each pair's child meshes are compared (vertices bit for bit, faces, tags, holes).

1. ``refine(operator=False)`` on an icosphere of triangles (``--tri-levels``, default 6: 81,920
   triangles, the size of a scanned bunny), the same with ``TRI_SUB_SMOOTH``,
   catmark_cubes_infsharp at level 0 and subdivided twice, catmark_pyramid_creases1 (semi-sharp
   creases and corners) subdivided twice, catmark_chaikin1 (semi-sharp, ``CREASE_CHAIKIN``);
2. the evaluator's setup (``natural_limit_surface``, the disk cache filled by the warm-up) of an
   icosphere with ``TRI_SUB_SMOOTH`` (``--setup-levels``, default 5: a tagged triangle mesh, whose setup
   refines once with ``refine(operator=False)``), the former refine patched in as "old".

Usage: python scripts/bench_refine.py [--rounds 5] [--tri-levels 6] [--setup-levels 5]
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_step import _icosphere, _stats  # noqa: E402

from ccproof.mesh import PolyMesh  # noqa: E402
from ccproof.mesh.rules import refine_complex, to_float  # noqa: E402

DATA = Path(__file__).resolve().parent.parent / "tests" / "data"


# ------------------------------------------------------------------ the baseline (the former code)
def _apply_stencils(stencils, X):
    """``S @ X`` for the float matrix S of the stencils, without building it: each row summed over its
    columns in increasing order, from 0, as the CSR product does (the same bits)."""
    n = len(stencils)
    width = max((len(s) for s in stencils if s is not None), default=0)
    cols = np.zeros((n, max(width, 1)), dtype=np.int64)
    vals = np.zeros((n, max(width, 1)))
    size = np.zeros(n, dtype=np.int64)
    bad = []
    for r, s in enumerate(stencils):
        if s is None:
            bad.append(r)
            continue
        items = sorted(s.items())
        size[r] = len(items)
        cols[r, :len(items)] = [c for c, _ in items]
        vals[r, :len(items)] = [to_float(w) for _, w in items]
    out = np.zeros((n, X.shape[1]))
    for k in range(width):  # only the rows' own columns: an unused vertex may hold NaN
        rows = np.flatnonzero(size > k)
        out[rows] += vals[rows, k, None] * X[cols[rows, k]]
    out[bad] = np.nan
    return out


def old_refine(self, operator=False):
    """The former ``PolyMesh.refine`` of a manifold mesh, ``operator=False``."""
    assert self.manifold is self and not operator
    cx = self.complex()
    stencils, children, ces, cvs = refine_complex(cx)
    V1 = _apply_stencils(stencils, np.asarray(self.vertices, dtype=np.float64))
    holes = np.repeat(self.is_hole, self.sizes)
    m = PolyMesh(V1, children, creases=(list(ces.keys()), list(ces.values())) if ces else None,
                 corners=cvs or None, holes=np.flatnonzero(holes), options=self.options)
    m.level = self.level + 1
    return m, None


def _same(a, b):
    return (a.vertices.tobytes() == b.vertices.tobytes() and np.array_equal(a.indices, b.indices)
            and np.array_equal(a.sizes, b.sizes) and list(a.edge_sharpness.items()) == list(b.edge_sharpness.items())
            and list(a.vertex_sharpness.items()) == list(b.vertex_sharpness.items())
            and np.array_equal(a.is_hole, b.is_hole) and a.options == b.options and a.level == b.level)


def _ab(name, old, new, rounds):
    ratios, loads, t_old, t_new = [], [], [], []
    old(), new()  # warm-up (imports, the disk cache)
    for i in range(rounds):
        loads.append(os.getloadavg()[0])
        pair = [(old, t_old), (new, t_new)] if i % 2 == 0 else [(new, t_new), (old, t_old)]
        for f, acc in pair:
            t0 = time.perf_counter()
            f()
            acc.append(time.perf_counter() - t0)
        ratios.append(t_new[-1] / t_old[-1])
    print(f"{name:50s} old {min(t_old) * 1e3:8.1f} / {statistics.median(t_old) * 1e3:8.1f} ms  "
          f"new {min(t_new) * 1e3:8.1f} / {statistics.median(t_new) * 1e3:8.1f} ms (min / median)  "
          f"new/old {_stats(ratios)}  (load {min(loads):.1f}-{max(loads):.1f})", flush=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--tri-levels", type=int, default=6)
    ap.add_argument("--setup-levels", type=int, default=5)
    a = ap.parse_args()
    from ccproof.evaluate.surface import natural_limit_surface
    from ccproof.mesh.io import read_mesh

    print(f"{os.cpu_count()} cpus; rounds {a.rounds}", flush=True)
    V, F = _icosphere(a.tri_levels)
    meshes = [(f"icosphere ({F.shape[0]:,} triangles)", PolyMesh(V, F)),
              (f"icosphere TRI_SUB_SMOOTH ({F.shape[0]:,} triangles)",
               PolyMesh(V, F, options={"triangle_subdivision": "smooth"}))]
    for name, lv in (("catmark_cubes_infsharp", 0), ("catmark_cubes_infsharp", 2),
                     ("catmark_pyramid_creases1", 2), ("catmark_chaikin1", 0)):
        pm = read_mesh(DATA / "osd_features" / "meshes" / f"{name}.obj").manifold
        for _ in range(lv):
            pm, _ = pm.refine(operator=False)
        meshes.append((f"{name} level {lv} ({pm.n_faces:,} faces)", pm))
    for name, pm in meshes:
        if not _same(old_refine(pm)[0], pm.refine(operator=False)[0]):
            raise SystemExit(f"{name}: the two refines differ")
        _ab(f"refine {name}", lambda pm=pm: old_refine(pm), lambda pm=pm: pm.refine(operator=False), a.rounds)

    V, F = _icosphere(a.setup_levels)
    sphere = PolyMesh(V, F, options={"triangle_subdivision": "smooth"})
    new_refine = PolyMesh.refine

    def setup(refine):
        def run():
            PolyMesh.refine = refine
            try:
                natural_limit_surface(sphere, progress=False)
            finally:
                PolyMesh.refine = new_refine
        return run

    _ab(f"setup icosphere TRI_SUB_SMOOTH ({F.shape[0]:,} triangles)", setup(old_refine), setup(new_refine), a.rounds)


if __name__ == "__main__":
    main()
