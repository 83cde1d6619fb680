"""The first LimitSurface.with_vertices of a tagged triangle mesh: this tree against a git revision.

The surface of an icosphere with an infinitely sharp crease loop (tagged, not all quads: the build
runs the tagged level-1 step) is built, then moved twice; the build, the first and the second move
are timed, and, on a second surface, the part of a move that needs the step (the level-1 positions
the rings index, ``LimitSurface._classified_positions``) on its first and second call. Each round
runs one fresh process per tree (``--before``, exported with ``git archive``, the compiled kernel
copied over, and this working tree), alternating which goes first: interleaved rounds on a shared
machine. Printed: the medians per tree, and from the first two rounds (tracemalloc, an extra untimed
build) the bytes the surface holds and the build's peak, per ptex face, with the table's bytes per
ptex face and, where the build keeps it, the kept step's.

Usage: ``python scripts/bench_first_move.py [--before main] [--rounds 4] [--levels 4 5]``
(level 4: 5,120 triangles, level 5: 20,480).
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "scripts"))
from _trees import export_revision  # noqa: E402

SNIPPET = r"""
import json, sys, time, tracemalloc
import numpy as np
sys.path.insert(0, "scripts")
from bench_memory import icosphere
from ccproof.evaluate import LimitSurface
from ccproof.mesh.polymesh import PolyMesh
try:  # the revisions before PolyMesh.with_vertices
    from ccproof.evaluate.surface import _polymesh_with_vertices
except ImportError:
    pass

def mesh(L):
    V, F = icosphere(L)
    z = V[:, 2]
    band = (z > 0) & (z < np.quantile(z[z > 0], 0.15))
    E = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
    E = np.unique(E[band[E[:, 0]] & band[E[:, 1]]], axis=0)
    return PolyMesh(V, F, creases=(E, [10.0] * E.shape[0]))

out = {}
rng = np.random.default_rng(0)
for L in LEVELS:
    m = mesh(L)
    LimitSurface(mesh(2), progress=False).with_vertices(np.asarray(mesh(2).vertices))  # warm: imports, caches
    t = time.perf_counter(); S = LimitSurface(m, progress=False); build = time.perf_counter() - t
    V = np.asarray(m.vertices)
    t = time.perf_counter(); S.with_vertices(V + 1e-3 * rng.standard_normal(V.shape)); first = time.perf_counter() - t
    t = time.perf_counter(); S.with_vertices(V + 1e-3 * rng.standard_normal(V.shape)); second = time.perf_counter() - t
    # the level-1 positions alone (the part of a move that needs the step), on a second surface
    T = LimitSurface(m, progress=False)
    X = V + 1e-3 * rng.standard_normal(V.shape)
    m2 = m.with_vertices(X) if hasattr(m, "with_vertices") else _polymesh_with_vertices(m, X)
    t = time.perf_counter(); T._classified_positions(m2); pos1 = time.perf_counter() - t
    t = time.perf_counter(); T._classified_positions(m2); pos2 = time.perf_counter() - t
    del T
    r = dict(build=build, first=first, second=second, pos1=pos1, pos2=pos2, P=S.n_faces, table=S.table_bytes,
             step=S._moving["step"].nbytes if "step" in S._moving and hasattr(S._moving["step"], "nbytes") else 0)
    if MEMORY:
        del S
        tracemalloc.start()
        a = tracemalloc.get_traced_memory()[0]
        S = LimitSurface(m, progress=False)
        held, peak = tracemalloc.get_traced_memory()
        tracemalloc.stop()
        r.update(held=held - a, peak=peak - a)
    out[L] = r
print(json.dumps(out))
"""


def _run(tree, levels, memory):
    code = SNIPPET.replace("LEVELS", repr(list(levels))).replace("MEMORY", repr(memory))
    env = {"PYTHONPATH": str(tree), "PATH": "/usr/bin:/bin", "HOME": str(Path.home())}
    p = subprocess.run([sys.executable, "-c", code], cwd=tree, env=env, capture_output=True, text=True, check=True)
    return json.loads(p.stdout.strip().splitlines()[-1])


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--before", default="main")
    ap.add_argument("--rounds", type=int, default=4)
    ap.add_argument("--levels", type=int, nargs="+", default=[4, 5])
    args = ap.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        old = Path(tmp)
        rev = export_revision(args.before, old)
        trees = {f"before ({args.before} = {rev})": old, "after (this tree)": ROOT}
        res: dict = {k: [] for k in trees}
        for i in range(args.rounds):
            for name in (list(trees) if i % 2 == 0 else list(trees)[::-1]):
                res[name].append(_run(trees[name], args.levels, i < 2))
    for L in args.levels:
        L = str(L)
        for name, rs in res.items():
            r0 = next(r[L] for r in rs if "held" in r[L])
            P = r0["P"]
            med = {k: statistics.median(r[L][k] for r in rs) * 1e3
                   for k in ("build", "first", "second", "pos1", "pos2")}
            print(f"icosphere level {L} creased, {P} ptex faces, {name}: build {med['build']:.0f} ms, "
                  f"first move {med['first']:.1f} ms, second move {med['second']:.1f} ms, of a move the level-1 "
                  f"positions {med['pos1']:.1f} ms first, {med['pos2']:.1f} ms then (medians of {len(rs)} "
                  f"interleaved rounds); table {r0['table'] / P:.0f} B per ptex face, kept step "
                  f"{r0['step'] / P:.1f} B ({100 * r0['step'] / r0['table']:.2f} % of the table); tracemalloc: "
                  f"surface held {r0['held'] / P:.0f} B, build peak {r0['peak'] / P:.0f} B per ptex face", flush=True)


if __name__ == "__main__":
    main()
