"""A/B of builds of the C evaluation kernel: the same meshes, the same points, rounds interleaved.

Each library (a build of ``ccproof/evaluate/_clib.c``) runs in a worker process of its own, which loads it
through the environment variable ``CCPROOF_CLIB`` (the file the evaluator loads instead of the installed
kernel) and evaluates with the public ``LimitSurface.evaluate(..., backend="c", threads=1)``; the workers
stay alive and the parent asks them in turn, round by round, the order rotating, every worker pinned to the
same CPU. The cases: each mesh of ``scripts/bench_evaluate.py`` with uniform points and points near
extraordinary vertices, P + Pu + Pv. Per case it prints the first library's median time and, for every other
library, the per-round ratio first / other (above 1: faster than the first; min, median, max) in CPU time of
the evaluating thread (less sensitive to the other processes of a shared machine than the wall clock), the
1-minute load, and whether its results have the first library's bits. Give the first library twice as a
control (each worker is a process of its own): its ratio is the floor of the A/B on that machine at that time.

A library built from another version of ``_clib.c`` (another ``ccp_abi``) is not loaded: the evaluator then
falls back, and the worker stops with an error naming the file.

Build a library with setup.py's flags, e.g.::

    gcc -shared -fPIC -std=c99 -O3 -ffp-contract=off -fno-math-errno -Wno-psabi ccproof/evaluate/_clib.c -o /tmp/new.so
    python scripts/bench_kernel_ab.py /tmp/old.so /tmp/old.so /tmp/new.so --rounds 61 --points 100000
    python scripts/bench_kernel_ab.py --smoke      the installed kernel against itself (the test suite's run)

A library may name the source tree its worker imports ccproof from and options of its table: ``LIB@TREE`` (the
tree put first on the worker's PYTHONPATH: compares two versions of the package, each with its own kernel),
``LIB@TREE@computed`` (no precomputed nets: the environment variables ``CCPROOF_NETS_BUDGET`` and
``CCPROOF_HOT_BUDGET`` set to 0, every net computed from the rings at evaluation time), ``LIB@TREE@unsorted``
(points never batched by face: ``SORT_MIN`` out of reach) or both (``@computed,unsorted``), e.g. the table
of the main branch against this one on the icospheres of
``scripts/bench_memory.py`` (``--mesh`` adds meshes; ``--shapes none`` leaves out the default ones)::

    python scripts/bench_kernel_ab.py /tmp/old.so@/tmp/oldtree /tmp/new.so /tmp/new.so@.@computed \
        --shapes none --mesh /tmp/icosphere5.obj --dists uniform --rounds 11 --points 200000
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from _bench import load, missing, ratio_line  # noqa: E402
from bench_evaluate import SHAPES, near_ev_points, uniform_points  # noqa: E402

from ccproof.evaluate import natural_limit_surface  # noqa: E402
from ccproof.evaluate.backend import available_backends  # noqa: E402
from ccproof.mesh.io import read_mesh  # noqa: E402

#: the worker: reads "case path npz" lines, prints "thread-seconds digest" per line
WORKER = r"""
import hashlib, os, sys, time
import numpy as np
if os.environ.get("CCPROOF_AB_UNSORTED"):
    from ccproof.evaluate import surface
    surface.SORT_MIN = 1 << 62
from ccproof.evaluate import natural_limit_surface
from ccproof.evaluate.backend import available_backends
from ccproof.mesh.io import read_mesh
if "c" not in available_backends():
    sys.exit(f"{os.environ.get('CCPROOF_CLIB')}: not loaded (not a build of this _clib.c?)")
if hasattr(os, "sched_setaffinity"):
    os.sched_setaffinity(0, {int(sys.argv[1])})
surfaces, points = {}, {}
for line in sys.stdin:
    path, pts = line.split()
    if path not in surfaces:
        surfaces[path] = natural_limit_surface(read_mesh(path), progress=False)
    if pts not in points:
        d = np.load(pts)
        points[pts] = (d["f"], d["u"], d["v"])
    S, (f, u, v) = surfaces[path], points[pts]
    t0 = time.thread_time()
    r = S.evaluate(f, u, v, 1, backend="c", threads=1)
    dt = time.thread_time() - t0
    h = hashlib.sha256(b"".join(np.ascontiguousarray(r[k]).tobytes() for k in ("P", "Pu", "Pv"))).hexdigest()
    print(dt, h, flush=True)
"""


def _installed_kernel():
    """The C kernel this install built (the file the evaluator loads by default), or None."""
    import ccproof.evaluate as ev

    here = Path(ev.__file__).parent
    found = sorted(here.glob("_clib*.so")) + sorted(here.glob("_clib*.pyd"))
    return found[0] if found else None


class Worker:
    """A process evaluating with one library (``CCPROOF_CLIB``), pinned to ``cpu``."""

    def __init__(self, spec, cpu):
        lib, tree, opt = (spec.split("@") + ["", ""])[:3]
        env = dict(os.environ, CCPROOF_CLIB=str(Path(lib).resolve()))
        env.pop("CCPROOF_BACKEND", None)
        if tree:
            env["PYTHONPATH"] = str(Path(tree).resolve()) + os.pathsep + env.get("PYTHONPATH", "")
        for o in filter(None, opt.split(",")):
            if o not in ("computed", "unsorted"):
                raise SystemExit(f"{spec}: unknown option {o!r} (computed, unsorted)")
            if o == "computed":
                env["CCPROOF_NETS_BUDGET"] = env["CCPROOF_HOT_BUDGET"] = "0"
            else:
                env["CCPROOF_AB_UNSORTED"] = "1"
        self.p = subprocess.Popen([sys.executable, "-c", WORKER, str(cpu)], stdin=subprocess.PIPE,
                                  stdout=subprocess.PIPE, text=True, env=env, cwd=tree or None)  # ("" first)

    def run(self, path, pts):
        self.p.stdin.write(f"{path} {pts}\n")
        self.p.stdin.flush()
        line = self.p.stdout.readline()
        if not line:
            raise SystemExit(f"a worker stopped (exit {self.p.wait()})")
        dt, digest = line.split()
        return float(dt), digest

    def close(self):
        self.p.stdin.close()
        self.p.wait()


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("libs", nargs="*", help="shared libraries; the first is the baseline")
    ap.add_argument("--rounds", type=int, default=41)
    ap.add_argument("--points", type=int, default=100_000)
    ap.add_argument("--shapes", default=",".join(label for label, _ in SHAPES))
    ap.add_argument("--dists", default="uniform,near")
    ap.add_argument("--mesh", action="append", default=[], help="another mesh file (label: its name)")
    ap.add_argument("--smoke", action="store_true",
                    help="the installed kernel against itself, 2 rounds, 2,000 points, one mesh")
    a = ap.parse_args(argv)
    if a.smoke:
        a.rounds, a.points, a.shapes, a.dists = 2, 2000, SHAPES[2][0], "uniform,near"
        lib = _installed_kernel()
        if lib is None or "c" not in available_backends():
            missing("the C kernel", "not built: python setup.py build_ext --inplace")
            S = natural_limit_surface(read_mesh(SHAPES[2][1]), progress=False)
            print(f"our side (numpy): {S.evaluate([0], [0.5], [0.5])['P'].shape[0]} point evaluated")
            return 0
        a.libs = [str(lib), str(lib)]
    if len(a.libs) < 2:
        ap.error("give at least two libraries (the first is the baseline), or --smoke")
    names = ["@".join(os.path.basename(x) for x in p.split("@")) for p in a.libs]
    cpu = min(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else 0
    workers = [Worker(p, cpu) for p in a.libs]
    rng = np.random.default_rng(1)
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        for label, path in SHAPES + [(Path(m).stem, Path(m)) for m in a.mesh]:
            if label not in a.shapes.split(",") and str(path) not in a.mesh:
                continue
            mesh = read_mesh(path)
            for dist in a.dists.split(","):
                pick = uniform_points if dist == "uniform" else (lambda m, n, r: near_ev_points(m, n, r)[:3])
                f, u, v = pick(mesh, a.points, rng)
                pts = os.path.join(tmp, f"{label}_{dist}.npz")
                np.savez(pts, f=np.asarray(f, np.int64), u=np.asarray(u, np.float64), v=np.asarray(v, np.float64))
                first = [w.run(path, pts) for w in workers]  # warm-up: the surface built, the bits compared
                same = [d == first[0][1] for _, d in first]
                times, loads = [[] for _ in workers], []
                for r in range(a.rounds):
                    loads.append(load())
                    for i in [(r + j) % len(workers) for j in range(len(workers))]:
                        times[i].append(workers[i].run(path, pts)[0])
                base = np.array(times[0])
                print(f"{label:15s} {dist:8s} {names[0]} {np.median(base) * 1e3:.1f} ms", flush=True)
                for i in range(1, len(workers)):
                    line = ratio_line(f"   {names[0]}/{names[i]}:", base / np.array(times[i]), loads)
                    print(line + ("" if same[i] else "  OTHER BITS"), flush=True)
    for w in workers:
        w.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
