#!/usr/bin/env python
"""Benchmark of LimitSurface.basis against LimitSurface.evaluate on the same points (interleaved rounds).

The cube subdivided ``--levels`` times (1,536 faces at 4: eight valence-3 vertices, corner faces in their
layers) and ``--points`` uniformly random points (face, u, v), a tenth of them within 10^-1 .. 10^-12 of
a face corner. Per round and derivative order d = 0, 1: ``evaluate(f, u, v, d)`` (the compiled kernel) and
``basis(f, u, v, d)`` (the CSR rows of the file's control vertices), in turn; the ratio basis / evaluate
per round is printed as min, median, max, with the 1-minute load before the rounds. Both on ``--threads``
threads (default: the evaluator's default, all cores for large batches). Rows hold 16 weights and
indices per point (regular patch), so the output is about 8x that of ``evaluate`` per derivative.

The floor: in the same rounds, writing arrays of the size of W's (its data per key and its index arrays:
one, shared by the keys, where the rows are canonical; numpy ``fill``) without computing anything,
``write W's arrays / evaluate``. Arrays this large are fresh pages
from the system in every call (glibc maps allocations over 32 MB anew), whose first touch costs what
the machine's memory does: in a virtual machine that hands freed memory back to its host, this is most
of the time of ``basis``, and the noise of the ratio. ``evaluate``'s outputs (under 32 MB each at 10^6
points) are served again from the process's heap. ``--keep-memory`` puts both on the same footing: glibc
keeps every freed allocation in the heap (``mallopt`` M_MMAP_THRESHOLD 1 GiB, M_TRIM_THRESHOLD 2 GiB, as
``MALLOC_MMAP_THRESHOLD_`` would; a setting of this benchmark's process, not of the package).

``--cpu``: one thread, and each call timed by the CPU time of the calling thread (``time.thread_time``: user
and system time, page faults included) instead of the wall clock: on a machine shared with other jobs the
wall clock also counts the time the thread waits for a core, which the CPU time does not.

Usage: python scripts/bench_basis.py [--points 1000000] [--rounds 5] [--threads N] [--keep-memory] [--cpu] [--smoke]
(``--smoke``: 10^4 points, 2 rounds: checks that it runs).
"""

from __future__ import annotations

import argparse
import os
import statistics
import time

import numpy as np


def _points(S, n, seed=0):
    rng = np.random.default_rng(seed)
    f = rng.integers(0, S.n_faces, n)
    u, v = rng.random(n), rng.random(n)
    k = n // 10
    u[:k], v[:k] = 10.0 ** -rng.uniform(1, 12, k), 10.0 ** -rng.uniform(1, 12, k)
    return f, u, v


def _keep_freed_memory():
    """glibc's ``mallopt``: allocations up to 1 GiB from the heap, the heap never trimmed below 2 GiB."""
    import ctypes

    libc = ctypes.CDLL("libc.so.6")
    m_trim_threshold, m_mmap_threshold = -1, -3
    if not (libc.mallopt(m_mmap_threshold, 1 << 30) and libc.mallopt(m_trim_threshold, (1 << 31) - 1)):
        raise SystemExit("--keep-memory: glibc's mallopt refused the thresholds")


def _write_arrays(nnz, keys, index_arrays):
    """Arrays of the size of W's (``keys`` data arrays, ``index_arrays`` of indices), written once (the
    cost of their memory alone)."""
    out = [np.empty(nnz) for _ in range(keys)] + [np.empty(nnz, dtype=np.int32) for _ in range(index_arrays)]
    for x in out:
        x.fill(1)
    return out


def _stats(r):
    return f"min {min(r):.2f}  median {statistics.median(r):.2f}  max {max(r):.2f}"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--points", type=int, default=10**6)
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--levels", type=int, default=4)
    ap.add_argument("--threads", type=int, default=None)
    ap.add_argument("--smoke", action="store_true")
    ap.add_argument("--keep-memory", action="store_true", help="glibc keeps freed memory in the heap")
    ap.add_argument("--cpu", action="store_true", help="one thread, timed by its CPU time (not the wall clock)")
    a = ap.parse_args(argv)
    if a.keep_memory:
        _keep_freed_memory()
    clock = time.perf_counter
    if a.cpu:
        a.threads, clock = 1, time.thread_time
    if a.smoke:
        a.points, a.rounds, a.levels = 10**4, 2, 2
    from ccproof.evaluate import natural_limit_surface
    from ccproof.mesh import subdivide
    from ccproof.mesh.examples import cube

    mesh = cube()
    for _ in range(a.levels):
        mesh = subdivide(mesh)
    S = natural_limit_surface(mesh, progress=False)
    f, u, v = _points(S, a.points)
    print(f"cube subdivided {a.levels} times: {S.n_faces:,} faces; {a.points:,} points; {os.cpu_count()} cpus; "
          f"threads {a.threads or 'default'}; rounds {a.rounds}{'; freed memory kept' if a.keep_memory else ''}"
          f"{'; CPU time of the thread' if a.cpu else ''}",
          flush=True)
    for d in (0, 1):
        S.evaluate(f, u, v, d, threads=a.threads)  # warm-up: kernels loaded, operators built
        W = S.basis(f, u, v, d, threads=a.threads)
        nnz, keys = W["P"].nnz, len(W)
        index_arrays = len({w.indices.__array_interface__["data"][0] for w in W.values()})  # shared or not
        t_ev, t_b, ratios, floor = [], [], [], []
        load = os.getloadavg()[0]
        for i in range(a.rounds):
            t_w = []
            order = [("e", t_ev), ("b", t_b), ("w", t_w)]
            for what, acc in (order if i % 2 == 0 else order[::-1]):
                t0 = clock()
                if what == "e":
                    S.evaluate(f, u, v, d, threads=a.threads)
                elif what == "b":
                    W = S.basis(f, u, v, d, threads=a.threads)
                else:
                    _write_arrays(nnz, keys, index_arrays)
                acc.append(clock() - t0)
            ratios.append(t_b[-1] / t_ev[-1])
            floor.append(t_w[-1] / t_ev[-1])
        print(f"derivatives {d}: evaluate {min(t_ev) * 1e3:7.1f} ms  basis {min(t_b) * 1e3:7.1f} ms "
              f"({nnz / a.points:.1f} weights per point)  basis/evaluate {_stats(ratios)}  (load {load:.1f})",
              flush=True)
        print(f"    write W's arrays ({keys} data, {index_arrays} index) / evaluate (the floor) {_stats(floor)}",
              flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
