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
   refines once with ``refine(operator="csr")``), the former refine patched in as "old" (its CSR arrays
   built from the same stencils: the same bits).

Usage: python scripts/bench_refine.py [--rounds 5] [--tri-levels 6] [--setup-levels 5] [--smoke]

``--before REV`` (e.g. ``main``) instead compares this tree's ``refine(operator=False)`` against the one of
the git revision REV (exported with ``git archive``, the compiled kernel copied over): each round runs one
fresh worker process per tree, alternating which goes first, on the icosphere of ``--tri-levels``,
catmark_cubes_infsharp at levels 0 and 2, and ``subdivision_matrix`` of the QuadMesh of the icosphere of
``--tri-levels`` - 1 refined once; a worker times ``--reps`` calls of each and keeps the fastest, and in
the first round measures the tracemalloc peak of one more call. Printed per mesh: the times of both trees
(min / median over the rounds), new / old per round (min, median, max), the peaks; the children (and
matrices) of the two trees are compared bit for bit first (it stops otherwise). The workers get glibc's
``MALLOC_*`` environment variables (e.g. ``MALLOC_MMAP_THRESHOLD_=1073741824``: the cases run in one process, and
by default the large arrays a case frees raise glibc's mmap threshold for the next one, whose time then
depends on what ran before it).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _trees import export_revision  # noqa: E402
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


def _stencil_csr(stencils):
    """The CSR arrays ``(indptr, indices, data)`` of the stencils' rounded weights (increasing columns, no
    zero; an unused vertex's row empty): the operator the former code had for ``operator="csr"``."""
    rows = [[] if st is None else sorted((c, to_float(w)) for c, w in st.items() if w != 0) for st in stencils]
    indptr = np.r_[0, np.cumsum([len(r) for r in rows])].astype(np.int64)
    indices = np.array([c for r in rows for c, _ in r], dtype=np.int64)
    data = np.array([w for r in rows for _, w in r], dtype=np.float64)
    return indptr, indices, data


def old_refine(self, operator=False):
    """The former ``PolyMesh.refine`` of a manifold mesh, ``operator=False`` or ``"csr"`` (the evaluator's
    tagged setup asks for the step's CSR arrays: built from the same stencils)."""
    assert self.manifold is self and operator in (False, "csr")
    cx = self.complex()
    stencils, children, ces, cvs = refine_complex(cx)
    V1 = _apply_stencils(stencils, np.asarray(self.vertices, dtype=np.float64))
    holes = np.repeat(self.is_hole, self.sizes)
    m = PolyMesh(V1, children, creases=(list(ces.keys()), list(ces.values())) if ces else None,
                 corners=cvs or None, holes=np.flatnonzero(holes), options=self.options)
    m.level = self.level + 1
    return m, (_stencil_csr(stencils) if operator == "csr" else None)


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


# ------------------------------------------------------------------ --before: this tree against a revision
ROOT = Path(__file__).resolve().parents[1]

WORKER = r"""
import hashlib, json, sys, time, tracemalloc
import numpy as np
sys.path.insert(0, __SCRIPTS__)
from bench_step import _icosphere
from ccproof.mesh import PolyMesh, QuadMesh, subdivision_matrix
from ccproof.mesh.io import read_mesh

def digest(*arrays):
    h = hashlib.sha256()
    for a in arrays:
        h.update(np.ascontiguousarray(a).tobytes())
    return h.hexdigest()

def child(pm):
    m, _ = pm.refine(operator=False)
    tags = repr((list(m.edge_sharpness.items()), list(m.vertex_sharpness.items()), m.options, m.level))
    return digest(m.vertices, m.indices, m.sizes, m.is_hole, np.frombuffer(tags.encode(), dtype=np.uint8))

def matrix(qm):
    S = subdivision_matrix(qm)
    return digest(S.indptr, S.indices, S.data)

cases = []
V, F = _icosphere(__TRI__)
sphere = PolyMesh(V, F)
cases.append((f"refine icosphere ({F.shape[0]:,} triangles)", child, sphere))
for lv in (0, 2):
    pm = read_mesh(__DATA__ + "/catmark_cubes_infsharp.obj").manifold
    for _ in range(lv):
        pm, _ = pm.refine(operator=False)
    cases.append((f"refine catmark_cubes_infsharp level {lv} ({pm.n_faces:,} faces)", child, pm))
V, F = _icosphere(__TRI__ - 1)
q, _ = PolyMesh(V, F).refine(operator=False)
qm = QuadMesh(q.vertices, q.indices.reshape(-1, 4))
cases.append((f"subdivision_matrix icosphere quads ({qm.n_faces:,} quads)", matrix, qm))
out = {}
for name, f, x in cases:
    key = f(x)  # warm-up (imports) and the result's digest
    ts = []
    for _ in range(__REPS__):
        t = time.perf_counter(); f(x); ts.append(time.perf_counter() - t)
    r = {"t": min(ts), "digest": key}
    if __MEMORY__:
        tracemalloc.start()
        a = tracemalloc.get_traced_memory()[0]
        f(x)
        r["peak"] = tracemalloc.get_traced_memory()[1] - a
        tracemalloc.stop()
    out[name] = r
print(json.dumps(out))
"""


def _worker(tree, tri, reps, memory):
    code = WORKER
    for key, value in (("SCRIPTS", str(ROOT / "scripts")), ("DATA", str(DATA / "osd_features" / "meshes")),
                       ("TRI", tri), ("REPS", reps), ("MEMORY", memory)):
        code = code.replace(f"__{key}__", repr(value))
    env = {"PYTHONPATH": str(tree), "PATH": "/usr/bin:/bin", "HOME": str(Path.home())}
    # glibc's allocator settings passed on (e.g. MALLOC_MMAP_THRESHOLD_: a fixed threshold, so that what a case
    # frees does not change how the next one's large arrays are allocated)
    env.update({k: v for k, v in os.environ.items() if k.startswith("MALLOC_")})
    p = subprocess.run([sys.executable, "-c", code], cwd=tree, env=env, capture_output=True, text=True)
    if p.returncode:
        raise SystemExit(f"the worker in {tree} failed:\n{p.stderr}")
    return json.loads(p.stdout.strip().splitlines()[-1])


def before_main(a):
    """``--before``: this tree's refine against the revision's, one fresh worker per tree and round."""
    print(f"{os.cpu_count()} cpus; rounds {a.rounds}, {a.reps} calls per worker (the fastest kept)", flush=True)
    with tempfile.TemporaryDirectory() as tmp:
        old = Path(tmp)
        rev = export_revision(a.before, old)
        trees = {"old": old, "new": ROOT}
        res: dict = {k: [] for k in trees}
        loads = []
        for i in range(a.rounds):
            loads.append(os.getloadavg()[0])
            for name in (list(trees) if i % 2 == 0 else list(trees)[::-1]):
                res[name].append(_worker(trees[name], a.tri_levels, a.reps, i == 0))
    print(f"old: {a.before} = {rev}, new: this tree (load {min(loads):.1f}-{max(loads):.1f})")
    for case in res["new"][0]:
        if {r[case]["digest"] for k in trees for r in res[k]} != {res["new"][0][case]["digest"]}:
            raise SystemExit(f"{case}: the two trees' results differ")
        t = {k: [r[case]["t"] for r in res[k]] for k in trees}
        ratios = [x / y for x, y in zip(t["new"], t["old"])]
        print(f"{case:55s} old {min(t['old']) * 1e3:7.1f} / {statistics.median(t['old']) * 1e3:7.1f} ms  "
              f"new {min(t['new']) * 1e3:7.1f} / {statistics.median(t['new']) * 1e3:7.1f} ms (min / median)  "
              f"new/old {_stats(ratios)}  tracemalloc peak old {res['old'][0][case]['peak'] / 2**20:.1f} MiB, "
              f"new {res['new'][0][case]['peak'] / 2**20:.1f} MiB", flush=True)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--tri-levels", type=int, default=6)
    ap.add_argument("--setup-levels", type=int, default=5)
    ap.add_argument("--before", default=None, help="a git revision: compare against its refine (see above)")
    ap.add_argument("--reps", type=int, default=3, help="with --before: calls per worker and mesh")
    ap.add_argument("--smoke", action="store_true", help="one round on the smallest inputs (the test suite's run)")
    a = ap.parse_args(argv)
    if a.smoke:
        a.rounds, a.tri_levels, a.setup_levels, a.reps = 1, 1, 1, 1
    if a.before is not None:
        return before_main(a)
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
