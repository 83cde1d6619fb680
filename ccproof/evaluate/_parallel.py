"""Blocks of points on threads: the compiled kernels release the GIL (evaluation, Newton descents).

Below both :mod:`ccproof.evaluate.surface` and :mod:`ccproof.evaluate.closest` (neither imports
the other's internals through it).

>>> in_blocks(lambda lo, hi: hi - lo, 10, 1, 4)
[10]
>>> sum(int(hi - lo) for hi, lo in in_blocks(lambda lo, hi: (hi, lo), 100000, 2, 1000))
100000
"""

from __future__ import annotations

import numpy as np

from ccproof.errors import CCProofError

__all__ = ["in_blocks", "threads_for"]


def in_blocks(fn, n, nt, size, per_thread=16):
    """``fn(lo, hi)`` over contiguous blocks of ``range(n)`` on ``nt`` threads; the results in block order.

    More blocks than threads (about ``size`` points each, at most ``per_thread`` per thread), taken in
    turn: the cost per point varies (points near irregular vertices go down the layers), so equal
    shares would finish unequally. One thread: a single call on everything.
    """
    if nt <= 1:
        return [fn(0, n)]
    from concurrent.futures import ThreadPoolExecutor

    nb = max(nt, min(per_thread * nt, n // size))
    bounds = np.linspace(0, n, nb + 1).astype(np.int64)
    with ThreadPoolExecutor(nt) as ex:
        return list(ex.map(lambda i: fn(bounds[i], bounds[i + 1]), range(nb)))


def threads_for(threads, n):
    """Number of threads for n points (see :meth:`ccproof.evaluate.surface.LimitSurface.evaluate`)."""
    import os

    if threads is None:
        if n < 1 << 17:
            return 1
        threads = int(os.environ.get("CCPROOF_THREADS", os.cpu_count() or 1))
    threads = int(threads)
    if threads < 1:
        raise CCProofError(f"threads must be >= 1, got {threads}")
    return max(1, min(threads, n // 1024 or 1))
