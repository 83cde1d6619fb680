"""What one n-gon costs the evaluator: setup time, peak memory and the patch table's arrays, for n and 2n.

For each n of ``--sizes`` a fresh process (disk cache off) builds the surface of a disc (one n-gon, a ring of
quads around it) and evaluates 100 random points; it prints the setup seconds, the peak RSS (``ru_maxrss``), the
table's bytes and its largest arrays: the configuration's layer operators (``ops``, ``vop``: dense, O(n^2) per
layer), the corner rings' positions (``ring``: one ring of 2n + 7 points per sub-face, n of them) and their
indices (``rings``). The ratio line is the growth from one size to the next (table bytes and peak memory of
size 2n over size n, per pair): 2 would be linear, 4 quadratic.

Usage: python scripts/bench_ngon_table.py --sizes 250 500 1000   (n = 1000: 8 to 18 s on a loaded 2-core machine)
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _bench import load, ratio_line  # noqa: E402

_CHILD = r'''
import json, os, resource, sys, time
os.environ["CCPROOF_CACHE"] = "off"
import numpy as np
from ccproof.evaluate import limit_surface
from ccproof.mesh.polymesh import PolyMesh

n = int(sys.argv[1])
th = 2 * np.pi * np.arange(n) / n
V = np.vstack([np.c_[np.cos(th), np.sin(th), np.zeros(n)],
               np.c_[1.5 * np.cos(th), 1.5 * np.sin(th), 0.1 * np.ones(n)]])
faces = [list(range(n))] + [[(i + 1) % n, n + (i + 1) % n, n + i, i] for i in range(n)]
mesh = PolyMesh(V, faces)
t = time.perf_counter()
S = limit_surface(mesh)
setup = time.perf_counter() - t
rng = np.random.default_rng(0)
S.evaluate(rng.integers(0, mesh.n_ptex, 100), rng.random(100), rng.random(100), 1)
print(json.dumps({"setup": setup, "peak": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024,
                  "table": S.table_bytes, "configuration": S.configuration_bytes}))
'''


def measure(n):
    repo = Path(__file__).resolve().parents[1]
    env = dict(os.environ, PYTHONPATH=str(repo))
    out = subprocess.run([sys.executable, "-c", _CHILD, str(n)], capture_output=True, text=True, env=env, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[250, 500, 1000])
    ap.add_argument("--smoke", action="store_true", help="n = 20 and 40")
    args = ap.parse_args()
    sizes = [20, 40] if args.smoke else sorted(args.sizes)
    rows, loads = [], []
    for n in sizes:
        loads.append(load())
        r = measure(n)
        rows.append(r)
        conf = r["configuration"]
        print(f"n = {n}: setup {r['setup']:.2f} s, peak RSS {r['peak'] / 1e9:.3f} GB, table {r['table'] / 1e6:.1f} MB "
              f"(per configuration {conf / 1e6:.1f} MB, per sub-face {(r['table'] - conf) / 1e6:.1f} MB)", flush=True)
    table = [b["table"] / a["table"] for a, b in zip(rows, rows[1:])]
    peak = [b["peak"] / a["peak"] for a, b in zip(rows, rows[1:])]
    print(ratio_line("table bytes, next size / this size:", table, loads))
    print(ratio_line("peak RSS, next size / this size:", peak, loads))
    return 0


if __name__ == "__main__":
    sys.exit(main())
