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
    centres = np.ascontiguousarray(centres, dtype=np.float64).reshape(-1, 3)
    radii = np.ascontiguousarray(radii, dtype=np.float64).reshape(-1)
    smin = centres - radii[:, None]
    smax = centres + radii[:, None]
    order, lo, hi, child, start, count, nn = _build(centres, smin, smax, LEAF)
    return order, lo[:nn].copy(), hi[:nn].copy(), child[:nn].copy(), start[:nn].copy(), count[:nn].copy()


def _build(centres, smin, smax, leaf):
    """Depth-first construction (pre-order node numbering, left child first) with an explicit stack:
    a node's box holds its cells' spheres; a node of more than ``leaf`` cells is split at the median of
    its centres along their widest axis."""
    n = centres.shape[0]
    order = np.arange(n)
    cap = 2 * n + 2
    lo = np.empty((cap, 3))
    hi = np.empty((cap, 3))
    child = np.full((cap, 2), -1, dtype=np.int64)
    start = np.zeros(cap, dtype=np.int64)
    count = np.zeros(cap, dtype=np.int64)
    stack = np.empty((256, 4), dtype=np.int64)  # (s, e, parent, side); depth is about log2(n / leaf)
    nn = 0
    top = 0
    if n > 0:
        stack[0, 0], stack[0, 1], stack[0, 2], stack[0, 3] = 0, n, -1, 0
        top = 1
    while top > 0:
        top -= 1
        s, e, parent, side = stack[top, 0], stack[top, 1], stack[top, 2], stack[top, 3]
        i = nn
        nn += 1
        if parent >= 0:
            child[parent, side] = i
        start[i] = s
        count[i] = e - s
        cmin = np.full(3, np.inf)
        cmax = np.full(3, -np.inf)
        for a in range(3):
            lo[i, a] = np.inf
            hi[i, a] = -np.inf
        for q in range(s, e):
            j = order[q]
            for a in range(3):
                lo[i, a] = min(lo[i, a], smin[j, a])
                hi[i, a] = max(hi[i, a], smax[j, a])
                cmin[a] = min(cmin[a], centres[j, a])
                cmax[a] = max(cmax[a], centres[j, a])
        if e - s > leaf:
            ax = 0
            for a in range(1, 3):
                if cmax[a] - cmin[a] > cmax[ax] - cmin[ax]:
                    ax = a
            idx = order[s:e].copy()
            keys = np.empty(e - s)
            for q in range(e - s):
                keys[q] = centres[idx[q], ax]
            perm = np.argsort(keys)
            for q in range(e - s):
                order[s + q] = idx[perm[q]]
            mid = s + (e - s) // 2
            stack[top, 0], stack[top, 1], stack[top, 2], stack[top, 3] = mid, e, i, 1
            stack[top + 1, 0], stack[top + 1, 1], stack[top + 1, 2], stack[top + 1, 3] = s, mid, i, 0
            top += 2
    return order, lo, hi, child, start, count, nn


if numba is not None:  # pragma: no branch
    _build = numba.njit(cache=True, nogil=True)(_build)


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
