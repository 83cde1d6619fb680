"""The first LimitSurface.with_vertices of a tagged triangle mesh: this tree against a git revision.

The surface of an icosphere with an infinitely sharp crease loop (tagged, not all quads: the build
runs the tagged level-1 step) is built, then moved twice; the build, the first and the second move
are timed (the level-1 positions alone, a private method's time, are no longer measured). Each round
runs one fresh process per tree (``--before``, exported with ``git archive``, the compiled kernel
copied over, and this working tree), alternating which goes first: interleaved rounds on a shared
machine. Printed: the medians per tree, and from the first two rounds (tracemalloc, an extra untimed
build) the bytes the surface holds and the build's peak, per ptex face, with the table's bytes per
ptex face; and per level the ratio after/before of each time (min, median, max over the rounds; load).

Usage: ``python scripts/bench_first_move.py [--before main] [--rounds 4] [--levels 4 5] [--smoke]``
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
from _bench import load, ratio_line  # noqa: E402
from _trees import export_revision  # noqa: E402

SNIPPET = r"""
import json, sys, time, tracemalloc
import numpy as np
sys.path.insert(0, "scripts")
from bench_memory import icosphere
from ccproof.evaluate import LimitSurface
from ccproof.mesh.polymesh import PolyMesh

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
    r = dict(build=build, first=first, second=second, P=S.n_faces, table=S.table_bytes)
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
    ap.add_argument("--smoke", action="store_true",
                    help="this tree against itself (no export), level 1, 2 rounds (the test suite's run)")
    args = ap.parse_args(argv)
    if args.smoke:
        args.rounds, args.levels = 1, [1]
    loads = []
    with tempfile.TemporaryDirectory() as tmp:
        old = ROOT if args.smoke else Path(tmp)
        rev = "this tree" if args.smoke else export_revision(args.before, old)
        trees = {f"before ({args.before} = {rev})": old, "after (this tree)": ROOT}
        res: dict = {k: [] for k in trees}
        for i in range(args.rounds):
            loads.append(load())
            for name in (list(trees) if i % 2 == 0 else list(trees)[::-1]):
                res[name].append(_run(trees[name], args.levels, i < 2))
    for L in args.levels:
        L = str(L)
        for name, rs in res.items():
            r0 = next(r[L] for r in rs if "held" in r[L])
            P = r0["P"]
            med = {k: statistics.median(r[L][k] for r in rs) * 1e3 for k in ("build", "first", "second")}
            print(f"icosphere level {L} creased, {P} ptex faces, {name}: build {med['build']:.0f} ms, "
                  f"first move {med['first']:.1f} ms, second move {med['second']:.1f} ms (medians of {len(rs)} "
                  f"interleaved rounds); table {r0['table'] / P:.0f} B per ptex face; tracemalloc: "
                  f"surface held {r0['held'] / P:.0f} B, build peak {r0['peak'] / P:.0f} B per ptex face", flush=True)
        after, before = (res[k] for k in reversed(list(res)))
        for k in ("build", "first", "second"):
            ratios = [a[L][k] / b[L][k] for a, b in zip(after, before)]
            print(ratio_line(f"icosphere level {L} {k}: after/before", ratios, loads), flush=True)


if __name__ == "__main__":
    main()
