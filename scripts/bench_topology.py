#!/usr/bin/env python
"""Setup of the exact evaluator before and after one change, in interleaved rounds: time and peak memory.

Two source trees of ccproof (``--old`` and ``--new``, e.g. ``git archive <commit> | tar -x -C DIR`` with the C
kernel built or copied into each) take turns, round by round (the order alternating), each round one process
per tree. A process builds its meshes (not timed), runs one warm-up setup of each (imports, the per-key caches
and the template disk cache filled), then times ``--reps`` setups of each mesh in the process
(``natural_limit_surface``, as ``ccproof eval`` builds a surface; the median is the round's time) and
measures one more under ``tracemalloc`` (the peak of Python allocations during the setup, numpy's included);
the same for ``build_tagged`` alone on the polygon meshes (the topology, the first step and the classification:
the setup less the patch table's float data).

Meshes: ``catmark_cubes_infsharp`` (tagged quads, infinitely sharp creases) as read and refined twice
(the tagged level-1 path on a bigger mesh), ``catmark_smoothtris1`` (tagged triangles), an icosphere of
triangles (scan-like; untagged: the vectorized step) and the same icosphere with one infinitely sharp crease
loop and ``triangle_subdivision="smooth"``, one level coarser (tagged: the tagged step and the tagged walk), and
``bunny_quads`` (an all-quad mesh).

``--tables``: instead, whether both trees build the same patch tables, bit for bit (a SHA-256 of every array of
``PatchTable``), on every mesh of ``tests/data`` (``osd_features``, ``osd_nonmanifold``, ``meshes``) and on five
feature meshes refined twice. (The Python ring walk, chosen by assigning a private function, and the untagged step
``catmark_step`` of a private module, alone, are no longer measured: the script uses public names only.)

Usage: python scripts/bench_topology.py --old DIR --new DIR [--rounds 5] [--reps 3] [--tri-levels 4] [--tables]
       python scripts/bench_topology.py --smoke     this tree against itself, tiny (the test suite's run)
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "scripts"))
from _bench import ratio_line  # noqa: E402

WORKER = r"""
import json, statistics, sys, time, tracemalloc
import numpy as np
sys.path.insert(0, sys.argv[1])
import ccproof
assert ccproof.__file__.startswith(sys.argv[1]), ccproof.__file__
from ccproof.evaluate.surface import natural_limit_surface
from ccproof.mesh import PolyMesh
from ccproof.mesh.io import read_mesh, read_obj_tagged

def _icosphere(levels):  # (the icosphere of scripts/bench_step.py)
    t = (1 + 5 ** 0.5) / 2
    V = [[-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0], [0, -1, t], [0, 1, t], [0, -1, -t], [0, 1, -t],
         [t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]]
    F = [[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4], [11, 10, 2],
         [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8], [3, 8, 9], [4, 9, 5], [2, 4, 11],
         [6, 2, 10], [8, 6, 7], [9, 8, 1]]
    V = [np.array(v, dtype=float) / np.linalg.norm(v) for v in V]
    for _ in range(levels):
        mid, G = {}, []
        for a, b, c in F:
            m = []
            for p, q in ((a, b), (b, c), (c, a)):
                k = (min(p, q), max(p, q))
                if k not in mid:
                    x = V[p] + V[q]
                    V.append(x / np.linalg.norm(x))
                    mid[k] = len(V) - 1
                m.append(mid[k])
            G += [[a, m[0], m[2]], [b, m[1], m[0]], [c, m[2], m[1]], m]
        F = G
    return np.array(V), np.array(F)


data, reps, levels = __import__("pathlib").Path(sys.argv[3]), int(sys.argv[4]), int(sys.argv[5])
feat = data / "osd_features" / "meshes"
cubes = read_obj_tagged(feat / "catmark_cubes_infsharp.obj")
cubes2 = cubes.refine(operator=False)[0].refine(operator=False)[0]
V, F = _icosphere(levels)
Vt, Ft = _icosphere(levels - 1)
loop = [(a, b) for a, b in {tuple(sorted((int(f[i]), int(f[(i + 1) % 3])))) for f in Ft for i in range(3)}
        if abs(Vt[a, 2]) < 1e-9 and abs(Vt[b, 2]) < 1e-9]
meshes = {
    "cubes_infsharp": cubes,
    f"cubes_infsharp x2 ({cubes2.n_faces} quads)": cubes2,
    "smoothtris1": read_obj_tagged(feat / "catmark_smoothtris1.obj"),
    f"icosphere ({F.shape[0]} triangles)": PolyMesh(V, F),
    f"icosphere tagged ({Ft.shape[0]} triangles, {len(loop)} crease edges, smooth rule)": PolyMesh(
        Vt, Ft, creases=(loop, 10.0), options={"triangle_subdivision": "smooth"}),
    "bunny_quads": read_mesh(data / "meshes" / "bunny_quads.obj"),
}
from ccproof.evaluate.tagged import build_tagged


def measure(f):
    f()  # warm-up
    ts = []
    for _ in range(reps):
        t0 = time.perf_counter()
        f()
        ts.append(time.perf_counter() - t0)
    tracemalloc.start()
    f()
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    return statistics.median(ts), peak


out = {}
for name, m in meshes.items():
    out[name] = measure(lambda: natural_limit_surface(m, progress=False))
    if isinstance(m, PolyMesh):
        out[name + ": build_tagged"] = measure(lambda: build_tagged(m, False))
print(json.dumps(out))
"""


TABLES = r"""
import hashlib, json, sys
from pathlib import Path
import numpy as np
sys.path.insert(0, sys.argv[1])
import ccproof
assert ccproof.__file__.startswith(sys.argv[1]), ccproof.__file__
from ccproof.evaluate.surface import LimitSurface
from ccproof.mesh.io import read_mesh, read_obj_tagged

data = Path(sys.argv[2])
feat = data / "osd_features" / "meshes"
meshes = [(p.name, read_obj_tagged(p)) for p in sorted(feat.glob("*.obj"))]
meshes += [(p.name, read_mesh(p)) for p in sorted((data / "osd_nonmanifold" / "meshes").iterdir())
           if p.suffix in (".obj", ".off")]
meshes += [(p.name, read_mesh(p)) for p in sorted((data / "meshes").glob("*.obj"))]
for name in ("catmark_pyramid_creases1", "catmark_xord_boundary", "catmark_hole_test2", "catmark_chaikin1",
             "catmark_smoothtris1"):
    m = read_obj_tagged(feat / f"{name}.obj")
    meshes.append((name + " refined twice", m.refine(operator=False)[0].refine(operator=False)[0]))
out = {}
for name, m in meshes:
    T = LimitSurface(m).patch_map.table  # the PatchTable (a NamedTuple: _fields is its public API)
    h = hashlib.sha256()
    for f in T._fields:
        a = getattr(T, f)
        h.update(f.encode())
        h.update(np.ascontiguousarray(a).tobytes() if isinstance(a, np.ndarray) else repr(a).encode())
    out[name] = h.hexdigest()
print(json.dumps(out))
"""


def _tables(a):
    for walk in ("compiled",):
        res = []
        for tree in (a.old, a.new):
            r = subprocess.run([sys.executable, "-c", TABLES, str(tree.resolve()), str(REPO / "tests" / "data")],
                               capture_output=True, text=True, env=dict(os.environ, PYTHONPATH=str(tree)), cwd="/")
            if r.returncode:
                sys.exit(f"{tree}: {r.stderr}")
            res.append(json.loads(r.stdout.strip().splitlines()[-1]))
        same = [k for k in res[0] if res[0][k] == res[1].get(k)]
        print(f"{walk} walk: {len(same)} of {len(res[0])} patch tables the same bits"
              + ("" if len(same) == len(res[0]) else f"; different: {sorted(set(res[0]) - set(same))}"))


def _run(tree, a):
    env = dict(os.environ, PYTHONPATH=str(tree))
    r = subprocess.run([sys.executable, "-c", WORKER, str(tree.resolve()), "-", str(REPO / "tests" / "data"),
                        str(a.reps), str(a.tri_levels)], capture_output=True, text=True, env=env, cwd="/")
    if r.returncode:
        sys.exit(f"{tree}: {r.stderr}")
    return json.loads(r.stdout.strip().splitlines()[-1])


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--old", type=Path)
    ap.add_argument("--new", type=Path)
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--tri-levels", type=int, default=4)
    ap.add_argument("--tables", action="store_true")
    ap.add_argument("--smoke", action="store_true",
                    help="this tree against itself, one round, one setup, icosphere level 1 (the test suite's run)")
    a = ap.parse_args(argv)
    if a.smoke:
        a.old = a.new = REPO
        a.rounds, a.reps, a.tri_levels = 1, 1, 1
    if a.old is None or a.new is None:
        ap.error("--old and --new are required (or --smoke)")
    if a.tables:
        return _tables(a)
    res = {"old": [], "new": []}
    loads = []
    for i in range(a.rounds):
        loads.append(os.getloadavg()[0])
        for side in (("old", "new") if i % 2 == 0 else ("new", "old")):
            res[side].append(_run(getattr(a, side), a))
        print(f"round {i + 1}/{a.rounds} done", file=sys.stderr, flush=True)
    print(f"{a.rounds} rounds, {a.reps} setups per process (median), load {min(loads):.1f}-{max(loads):.1f}; "
          f"{os.cpu_count()} cpus")
    for name in res["old"][0]:
        to = [r[name][0] for r in res["old"]]
        tn = [r[name][0] for r in res["new"]]
        po = min(r[name][1] for r in res["old"]) / 2**20
        pn = min(r[name][1] for r in res["new"]) / 2**20
        print(f"{name}: old {min(to) * 1e3:.1f} ms, new {min(tn) * 1e3:.1f} ms; tracemalloc peak old {po:.2f} MiB, "
              f"new {pn:.2f} MiB;  " + ratio_line("new/old", [n / o for o, n in zip(to, tn)], loads))


if __name__ == "__main__":
    main()
