"""LimitSurface.with_vertices against a fresh build on PolyMesh surfaces (interleaved rounds).

For each mesh: a surface is built once; then, ``--rounds`` times in turn, a fresh build
``LimitSurface(PolyMesh(X, polygons, tags))`` (the constructor included, as a caller without
``with_vertices`` pays it) and ``S.with_vertices(X)`` on new random control points X; the medians and
the ratio are printed. The first ``with_vertices`` is printed apart, as "first" (on a tagged non-quad
mesh it once assembled the step's stencil matrix; the build keeps the step now: scripts/bench_first_move.py).
Meshes: an icosphere of 1,280 / 5,120 triangles (untagged: the vectorized level-1 step), the same with an
infinitely sharp crease loop (tagged: the kept tagged step),
tests/data/osd_features/meshes/catmark_helmet.obj refined twice with its tags (all quads,
semi-sharp creases) and tests/data/osd_nonmanifold/meshes/two_cubes_creases.obj refined twice
(non-manifold, all quads).

Also printed: the table's bytes per ptex face (less those held once per configuration), and per mesh the ratio
with_vertices / fresh build of each round (min, median, max; load).

Usage: ``python scripts/bench_with_vertices.py [--rounds 5]``
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "scripts"))

from _bench import load, ratio_line  # noqa: E402
from bench_memory import icosphere  # noqa: E402

from ccproof.evaluate import LimitSurface  # noqa: E402
from ccproof.mesh.io import read_mesh  # noqa: E402
from ccproof.mesh.polymesh import PolyMesh  # noqa: E402


def _rebuild(mesh, X):
    es = mesh.edge_sharpness
    return PolyMesh(X, mesh.indices, sizes=mesh.sizes, creases=(list(es.keys()), list(es.values())) if es else None,
                    corners=dict(mesh.vertex_sharpness) or None, holes=np.flatnonzero(mesh.is_hole_tagged),
                    options=mesh.options)


def _meshes(smoke=False):
    out = {}
    for L in (2,) if smoke else (3, 4):
        V, F = icosphere(L)
        out[f"icosphere{L} untagged ({F.shape[0]} tri)"] = PolyMesh(V, F)
        z = V[:, 2]
        band = (z > 0) & (z < np.quantile(z[z > 0], 0.15))
        E = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
        E = np.unique(E[band[E[:, 0]] & band[E[:, 1]]], axis=0)
        out[f"icosphere{L} creased ({F.shape[0]} tri, {E.shape[0]} crease edges)"] = \
            PolyMesh(V, F, creases=(E, [10.0] * E.shape[0]))
    for folder, name in (("osd_features", "catmark_helmet.obj"), ("osd_nonmanifold", "two_cubes_creases.obj")):
        m = read_mesh(ROOT / "tests" / "data" / folder / "meshes" / name)
        for _ in range(2):
            m, _ = m.refine(operator=False)
        out[f"{name} refined twice ({m.n_faces} quads)"] = m
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--smoke", action="store_true", help="2 rounds, icosphere level 2 (the test suite's run)")
    args = ap.parse_args(argv)
    if args.smoke:
        args.rounds = 2
    rng = np.random.default_rng(0)
    for label, mesh in _meshes(args.smoke).items():
        V = np.asarray(mesh.vertices)
        S = LimitSurface(mesh, progress=False)
        t = time.perf_counter()
        S.with_vertices(V + 1e-3 * rng.standard_normal(V.shape))
        first = time.perf_counter() - t
        fresh, moved, loads = [], [], []
        for _ in range(args.rounds):
            loads.append(load())
            X = V + 1e-2 * rng.standard_normal(V.shape)
            t = time.perf_counter()
            LimitSurface(_rebuild(mesh, X), progress=False)
            fresh.append(time.perf_counter() - t)
            t = time.perf_counter()
            S.with_vertices(X)
            moved.append(time.perf_counter() - t)
        a, b = statistics.median(fresh), statistics.median(moved)
        P = S.n_faces
        print(f"{label}: fresh build {a * 1e3:.1f} ms, with_vertices {b * 1e3:.2f} ms (first {first * 1e3:.1f} ms), "
              f"ratio {a / b:.1f}x (medians of {args.rounds} interleaved rounds); table "
              f"{(S.table_bytes - S.configuration_bytes) / P:.0f} bytes per ptex face beyond the configurations",
              flush=True)
        print(ratio_line(f"{label}: with_vertices/fresh build", [y / x for x, y in zip(fresh, moved)], loads),
              flush=True)


if __name__ == "__main__":
    main()
