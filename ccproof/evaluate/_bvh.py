"""Bounding-volume hierarchy over the cells of :mod:`ccproof.evaluate.closest` (axis-aligned boxes).

:func:`build` sorts the cells by recursive median splits of their centres (leaves of at most ``LEAF``
cells) and stores for every node the box of its cells' bounding spheres. :func:`candidates` lists,
for every query point, the cells whose cylinder lower bound is below the point's current upper bound
``d*``, visiting only the nodes whose box is closer than ``d*``. Compiled with numba when it is
installed (the same code runs as plain Python otherwise, slowly).
"""

from __future__ import annotations

import math

import numpy as np

try:
    import numba
except ImportError:  # pragma: no cover - optional dependency
    numba = None

#: cells per leaf at most
LEAF = 4


def build(centres, radii):
    """Hierarchy over spheres (centres (n, 3), radii (n,)).

    Returns
    -------
    order : ndarray of int64, shape (n,)
        Cells in leaf order.
    lo, hi : ndarray, shape (n_nodes, 3)
        Node boxes.
    child : ndarray of int64, shape (n_nodes, 2)
        Children (-1 at leaves).
    start, count : ndarray of int64, shape (n_nodes,)
        Leaf cells ``order[start : start + count]``.
    """
    n = centres.shape[0]
    order = np.arange(n)
    lo_l, hi_l, child_l, start_l, count_l = [], [], [], [], []
    smin = centres - radii[:, None]
    smax = centres + radii[:, None]

    def node(s, e):
        idx = order[s:e]
        i = len(lo_l)
        lo_l.append(smin[idx].min(axis=0))
        hi_l.append(smax[idx].max(axis=0))
        child_l.append([-1, -1])
        start_l.append(s)
        count_l.append(e - s)
        if e - s > LEAF:
            c = centres[idx]
            ax = int(np.argmax(c.max(axis=0) - c.min(axis=0)))
            mid = (e - s) // 2
            part = np.argpartition(c[:, ax], mid)
            order[s:e] = idx[part]
            a = node(s, s + mid)
            b = node(s + mid, e)
            child_l[i] = [a, b]
        return i

    if n:
        import sys

        old = sys.getrecursionlimit()
        sys.setrecursionlimit(max(old, 10000))
        try:
            node(0, n)
        finally:
            sys.setrecursionlimit(old)
    return (
        order,
        np.array(lo_l).reshape(-1, 3),
        np.array(hi_l).reshape(-1, 3),
        np.array(child_l, dtype=np.int64).reshape(-1, 2),
        np.array(start_l, dtype=np.int64),
        np.array(count_l, dtype=np.int64),
    )


def _traverse(X, dstar, order, lo, hi, child, start, count, c, nrm, r, h, out_p, out_c, out_lb, cap):
    """Write the pairs (point, cell, lower bound) with lower bound < d* (the first ``cap``); their number."""
    npts = X.shape[0]
    total = 0
    stack = np.empty(128, dtype=np.int64)
    for p in range(npts):
        x0, x1, x2 = X[p, 0], X[p, 1], X[p, 2]
        ds = dstar[p]
        top = 0
        stack[0] = 0
        top = 1
        while top > 0:
            top -= 1
            k = stack[top]
            d2 = 0.0
            for a in range(3):
                xa = X[p, a]
                if xa < lo[k, a]:
                    d2 += (lo[k, a] - xa) ** 2
                elif xa > hi[k, a]:
                    d2 += (xa - hi[k, a]) ** 2
            if d2 >= ds * ds:
                continue
            if child[k, 0] >= 0:
                stack[top] = child[k, 0]
                stack[top + 1] = child[k, 1]
                top += 2
                continue
            for q in range(start[k], start[k] + count[k]):
                j = order[q]
                w0, w1, w2 = x0 - c[j, 0], x1 - c[j, 1], x2 - c[j, 2]
                z = abs(w0 * nrm[j, 0] + w1 * nrm[j, 1] + w2 * nrm[j, 2])
                rho = math.sqrt(max(w0 * w0 + w1 * w1 + w2 * w2 - z * z, 0.0))
                a1 = max(rho - r[j], 0.0)
                a2 = max(z - h[j], 0.0)
                lb = math.sqrt(a1 * a1 + a2 * a2)
                if lb < ds:
                    if total < cap:
                        out_p[total] = p
                        out_c[total] = j
                        out_lb[total] = lb
                    total += 1
    return total


if numba is not None:  # pragma: no branch
    _traverse = numba.njit(cache=True, nogil=True)(_traverse)


def candidates(X, dstar, tree, c, nrm, r, h):
    """Pairs (point, cell) whose cylinder lower bound is below ``dstar[point]``.

    Parameters
    ----------
    X : ndarray, shape (n, 3)
    dstar : ndarray, shape (n,)
    tree : tuple
        Output of :func:`build`.
    c, nrm : ndarray, shape (n_cells, 3)
        Cylinder centres and unit axes.
    r, h : ndarray, shape (n_cells,)
        Lateral radii and half-heights.

    Returns
    -------
    pid, cid : ndarray of int64, shape (k,)
    lb : ndarray, shape (k,)
    """
    X = np.ascontiguousarray(X, dtype=np.float64)
    dstar = np.ascontiguousarray(dstar, dtype=np.float64)
    cap = 32 * X.shape[0] + 1024
    while True:  # one pass if the guessed capacity suffices, else count exactly and fill again
        pid = np.empty(cap, dtype=np.int64)
        cid = np.empty(cap, dtype=np.int64)
        lb = np.empty(cap)
        k = _traverse(X, dstar, *tree, c, nrm, r, h, pid, cid, lb, cap)
        if k <= cap:
            return pid[:k], cid[:k], lb[:k]
        cap = k
