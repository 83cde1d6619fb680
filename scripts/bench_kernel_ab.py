"""A/B of builds of the C evaluation kernel in one process: the same table, the same points, rounds interleaved.

Each library (a build of ``ccproof/evaluate/_clib.c`` with the same ``ccp_abi``) is loaded with ctypes and its
``ccp_evaluate`` called on one :class:`ccproof.evaluate._ckernel.CTable` of each mesh of
``scripts/bench_evaluate.py`` (uniform points and points near extraordinary vertices, P + Pu + Pv), in rounds
whose order rotates, the process pinned to one CPU. Per case it prints the 1-minute load before and after, the
first library's median time, and for every other library the median (min-max) over the rounds of the per-round
ratio first / other (above 1: faster than the first) in CPU time of the calling thread (less sensitive to the
other processes of a shared machine than the wall clock), and whether its results have the first library's
bits. Load a second copy of the first library (another file) as a control: its ratio is the floor of the
A/B on that machine at that time.

Build a library with setup.py's flags, e.g.::

    gcc -shared -fPIC -std=c99 -O3 -ffp-contract=off -fno-math-errno -Wno-psabi ccproof/evaluate/_clib.c -o /tmp/new.so
    python scripts/bench_kernel_ab.py /tmp/old.so /tmp/old_copy.so /tmp/new.so --rounds 61 --points 100000
"""

from __future__ import annotations

import argparse
import ctypes
import os
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(Path(__file__).resolve().parent))

import bench_evaluate as be  # noqa: E402

from ccproof.evaluate import _ckernel, natural_limit_surface  # noqa: E402
from ccproof.mesh.io import read_mesh  # noqa: E402


def _load(path):
    lib = ctypes.CDLL(os.path.abspath(path))
    lib.ccp_abi.restype = ctypes.c_int64
    if lib.ccp_abi() != 1000 * ctypes.sizeof(_ckernel._Table) + _ckernel._ABI:
        raise SystemExit(f"{path}: built from another version of _clib.c (ccp_abi differs)")
    lib.ccp_evaluate.restype = ctypes.c_int64
    lib.ccp_evaluate.argtypes = ([ctypes.POINTER(_ckernel._Table), ctypes.c_int64] + [ctypes.c_void_p] * 3
                                 + [ctypes.c_int64] + [ctypes.c_void_p] * 7)
    return lib


def _call(lib, ct, f, u, v, o, cache):
    """P, Pu, Pv of the points (f, u, v) into o by ``lib``'s kernel, with its own corner-net cache."""
    return lib.ccp_evaluate(ct.ref, f.size, f.ctypes.data, u.ctypes.data, v.ctypes.data, 1, o[0].ctypes.data,
                            o[1].ctypes.data, o[2].ctypes.data, None, None, None, cache.ctypes.data)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("libs", nargs="+", help="shared libraries; the first is the baseline")
    ap.add_argument("--rounds", type=int, default=41)
    ap.add_argument("--points", type=int, default=100_000)
    ap.add_argument("--shapes", default=",".join(label for label, _ in be.SHAPES))
    ap.add_argument("--dists", default="uniform,near")
    a = ap.parse_args(argv)
    if _ckernel.load() is None:
        raise SystemExit("the C kernel was not built (python setup.py build_ext --inplace): CTable needs it")
    libs = [_load(p) for p in a.libs]
    names = [os.path.basename(p) for p in a.libs]
    if hasattr(os, "sched_setaffinity"):
        os.sched_setaffinity(0, {min(os.sched_getaffinity(0))})
    rng = np.random.default_rng(1)
    n = a.points
    for label, path in be.SHAPES:
        if label not in a.shapes.split(","):
            continue
        mesh = read_mesh(path)
        ct = _ckernel.CTable(natural_limit_surface(mesh)._table)
        for dist in a.dists.split(","):
            f, u, v = (be.uniform_points(mesh, n, rng) if dist == "uniform" else be.near_ev_points(mesh, n, rng)[:3])
            f, u, v = (np.ascontiguousarray(x, dtype=t) for x, t in ((f, np.int64), (u, np.float64), (v, np.float64)))
            outs = [[np.empty((n, 3)) for _ in range(3)] for _ in libs]
            caches = [np.zeros(_ckernel.load().ccp_cache_words()) for _ in libs]

            for i in range(len(libs)):
                if _call(libs[i], ct, f, u, v, outs[i], caches[i]) != -1:
                    raise SystemExit(f"{names[i]} refused a point")
            same = [all(np.array_equal(x.view(np.int64), y.view(np.int64)) for x, y in zip(outs[0], o)) for o in outs]
            times = [[] for _ in libs]
            load0 = os.getloadavg()[0]
            for r in range(a.rounds):
                for i in [(r + j) % len(libs) for j in range(len(libs))]:
                    t0 = time.thread_time()
                    _call(libs[i], ct, f, u, v, outs[i], caches[i])
                    times[i].append(time.thread_time() - t0)
            base = np.array(times[0])
            line = (f"{label:15s} {dist:8s} load {load0:.2f}-{os.getloadavg()[0]:.2f}  {names[0]} "
                    f"{np.median(base) * 1e3:.1f} ms")
            for i in range(1, len(libs)):
                r_ = base / np.array(times[i])
                line += (f" | {names[i]} {np.median(r_):.3f} ({r_.min():.2f}-{r_.max():.2f})"
                         f"{'' if same[i] else ' OTHER BITS'}")
            print(line, flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
