#!/usr/bin/env python
"""``ccproof fit`` on tagged start meshes before and after one change, in interleaved rounds: wall time.

Two source trees of ccproof (``--old`` and ``--new``, e.g. ``git archive <commit> | tar -x -C DIR`` with the C
kernel built or copied into each) take turns, round by round (the order alternating), one process per tree and
mesh. A process imports ccproof (not timed), writes the range data (500 points of the synthetic ellipsoid, seed
1) and times one call of the command line ``fit DATA --init MESH --levels 1 --max-steps S`` (``main``, in the
process: the elements' construction, the assembly, the steps and the output); the output OBJ's vertex lines
are hashed, so that both trees can be seen to give the same bits. Printed: per tree and mesh the times of the
rounds and their min / median / max, and whether the outputs of the two trees were identical.

Usage: python scripts/bench_fit_tagged.py --old DIR --new DIR [--rounds 3] [--max-steps 5] [MESH ...]
(default meshes: catmark_cube_creases0 and catmark_dart_edgeonly of tests/data/osd_features/meshes).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]

WORKER = r"""
import contextlib, hashlib, io, json, os, sys, tempfile, time
import numpy as np
sys.path.insert(0, sys.argv[1])
import ccproof
assert ccproof.__file__.startswith(sys.argv[1]), ccproof.__file__
from ccproof.apps.dynamics.shapes import synthetic_range_data
from ccproof.cli import main
d = tempfile.mkdtemp()
xyz, out = os.path.join(d, "s.xyz"), os.path.join(d, "f.obj")
np.savetxt(xyz, synthetic_range_data("ellipsoid", 500, seed=1))
argv = ["fit", xyz, "--init", sys.argv[2], "--levels", "1", "--max-steps", sys.argv[3], "--out", out,
        "--no-progress"]
t = time.perf_counter()
with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
    rc = main(argv)
t = time.perf_counter() - t
if rc != 0:
    print(json.dumps({"rc": rc}))
    sys.exit(0)
v = b"".join(x for x in open(out, "rb").read().splitlines(True) if x.startswith(b"v "))
print(json.dumps({"rc": rc, "s": t, "sha": hashlib.sha256(v).hexdigest()}))
"""


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--old")
    ap.add_argument("--new")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--max-steps", type=int, default=5)
    ap.add_argument("meshes", nargs="*")
    ap.add_argument("--smoke", action="store_true",
                    help="this tree against itself, 1 round, 1 step, one mesh (the test suite's run)")
    a = ap.parse_args(argv)
    if a.smoke:
        a.old = a.new = str(REPO)
        a.rounds, a.max_steps = 1, 1
        a.meshes = [str(REPO / "tests/data/osd_features/meshes/catmark_cube_creases0.obj")]
    if a.old is None or a.new is None:
        ap.error("--old and --new are required (or --smoke)")
    meshes = a.meshes or [str(REPO / "tests/data/osd_features/meshes" / f"{m}.obj")
                          for m in ("catmark_cube_creases0", "catmark_dart_edgeonly")]
    trees = {"old": str(Path(a.old).resolve()), "new": str(Path(a.new).resolve())}
    times = {(t, m): [] for t in trees for m in meshes}
    loads = []
    shas = {(t, m): set() for t in trees for m in meshes}
    for r in range(a.rounds):
        order = ["old", "new"] if r % 2 == 0 else ["new", "old"]
        loads.append(os.getloadavg()[0])
        for m in meshes:
            for t in order:
                with tempfile.TemporaryDirectory() as cwd:
                    res = subprocess.run([sys.executable, "-c", WORKER, trees[t], m, str(a.max_steps)], cwd=cwd,
                                         capture_output=True, text=True, env={"PATH": "/usr/bin:/bin"})
                if res.returncode != 0:
                    sys.exit(res.stderr)
                o = json.loads(res.stdout.strip().splitlines()[-1])
                if o["rc"] != 0:
                    sys.exit(f"{t} {m}: fit returned {o['rc']}")
                times[(t, m)].append(o["s"])
                shas[(t, m)].add(o["sha"])
                print(f"round {r} {t} {Path(m).stem}: {o['s']:.2f} s", flush=True)
    for m in meshes:
        for t in trees:
            x = times[(t, m)]
            print(f"{Path(m).stem} {t}: min {min(x):.2f} median {statistics.median(x):.2f} max {max(x):.2f} s "
                  f"({len(x)} rounds)")
        ratios = [n / o for o, n in zip(times[("old", m)], times[("new", m)])]
        print(f"{Path(m).stem} new/old: min {min(ratios):.3f}  median {statistics.median(ratios):.3f}  max "
              f"{max(ratios):.3f}  ({len(ratios)} rounds; load {min(loads):.2f}-{max(loads):.2f})")
        same = len(shas[("old", m)] | shas[("new", m)]) == 1
        print(f"{Path(m).stem}: outputs identical across trees and rounds: {same}")


if __name__ == "__main__":
    main()
