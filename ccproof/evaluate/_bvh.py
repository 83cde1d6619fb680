"""Bounding-volume hierarchy over the faces of :mod:`ccproof.evaluate.closest` (axis-aligned boxes).

:func:`build` sorts bounding cylinders (one per face in the search structure) by recursive median splits of
their centres (leaves of at most ``LEAF``) and stores for every node the box of their bounding spheres.
:func:`candidates` lists, for every query point, the cylinders whose lower bound is below the point's
current upper bound ``d*``, visiting only the nodes whose box is closer than ``d*``; :func:`expand_cells`
turns candidate faces into candidate cells (the cylinders of :func:`cell_bounds`). Compiled with numba
when it is installed (the same code runs as plain Python otherwise, slowly).
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
    order, *nodes, nn = _build(centres, radii, LEAF)
    for i in range(len(nodes)):  # trimmed to the nodes used (about 2 n / 3 of n + 2), one array at a time
        nodes[i] = nodes[i][:nn].copy()
    return (order, *nodes)


def _build(centres, radii, leaf):
    """Depth-first construction (pre-order node numbering, left child first) with an explicit stack:
    a node's box holds its cells' spheres; a node of more than ``leaf`` cells is split at the median of
    its centres along their widest axis."""
    n = centres.shape[0]
    order = np.arange(n)
    # a node of more than ``leaf >= 2`` items is split into halves of at least 2 items: at most n / 2
    # leaves, hence at most n nodes (n + 2 for n <= leaf)
    cap = n + 2
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
                lo[i, a] = min(lo[i, a], centres[j, a] - radii[j])
                hi[i, a] = max(hi[i, a], centres[j, a] + radii[j])
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


def _traverse(X, dstar, tree, cells, out, cap):
    """Write the pairs (point, cell, lower bound) with lower bound < d* (the first ``cap``) into ``out`` =
    (points, cells, lower bounds); their number. ``tree``: :func:`build`'s; ``cells``: (c, nrm, r, h)."""
    order, lo, hi, child, start, count = tree
    c, nrm, r, h = cells
    out_p, out_c, out_lb = out
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


def _expand(X, dstar, pid, pos, slot, cells, mm, out):
    """Write the pairs (point, cell, lower bound) with lower bound < d* of candidate pairs (point, face) into
    ``out`` = (points, cells, lower bounds): face ``pos[i]`` has its ``mm`` cells at rows ``slot[i] * mm ...`` of
    ``cells`` = (c, nrm, r, h); cell ids are ``pos * mm + k``. Returns their number (``out`` holds
    ``pid.size * mm`` rows)."""
    c, nrm, r, h = cells
    out_p, out_c, out_lb = out
    total = 0
    for i in range(pid.size):
        p = pid[i]
        x0, x1, x2 = X[p, 0], X[p, 1], X[p, 2]
        ds = dstar[p]
        for k in range(mm):
            j = slot[i] * mm + k
            w0, w1, w2 = x0 - c[j, 0], x1 - c[j, 1], x2 - c[j, 2]
            z = abs(w0 * nrm[j, 0] + w1 * nrm[j, 1] + w2 * nrm[j, 2])
            rho = math.sqrt(max(w0 * w0 + w1 * w1 + w2 * w2 - z * z, 0.0))
            a1 = max(rho - r[j], 0.0)
            a2 = max(z - h[j], 0.0)
            lb = math.sqrt(a1 * a1 + a2 * a2)
            if lb < ds:
                out_p[total] = p
                out_c[total] = pos[i] * mm + k
                out_lb[total] = lb
                total += 1
    return total


if numba is not None:  # pragma: no branch
    _expand = numba.njit(cache=True, nogil=True)(_expand)


def expand_cells(X, dstar, pid, pos, slot, cells, mm):
    """Candidate cells of candidate faces: the pairs (point, cell) whose cylinder lower bound (the formula of
    :func:`candidates`) is below ``dstar[point]``.

    Parameters
    ----------
    X : ndarray, shape (n, 3)
    dstar : ndarray, shape (n,)
    pid, pos, slot : ndarray of int, shape (k,)
        Candidate pairs: point, face position (cell ids ``pos * mm + 0 .. mm - 1``), rows of the face's
        cells in ``cells`` (``slot * mm + 0 .. mm - 1``).
    cells : tuple of ndarray
        ``(c, nrm, r, h)`` as returned by :func:`cell_bounds`.
    mm : int
        Cells per face.

    Returns
    -------
    pid, cid : ndarray of int64
    lb : ndarray
    """
    m = pid.size * mm
    out_p, out_c, out_lb = np.empty(m, dtype=np.int64), np.empty(m, dtype=np.int64), np.empty(m)
    k = _expand(np.ascontiguousarray(X, dtype=np.float64), np.ascontiguousarray(dstar, dtype=np.float64),
                np.asarray(pid, dtype=np.int64), np.asarray(pos, dtype=np.int64), np.asarray(slot, dtype=np.int64),
                tuple(cells), int(mm), (out_p, out_c, out_lb))
    return out_p[:k].copy(), out_c[:k].copy(), out_lb[:k].copy()


def _nearest(X, pid, slot, c, mm, out_k, out_d):
    for i in range(pid.size):
        p = pid[i]
        best, kb = math.inf, 0
        for k in range(mm):
            j = slot[i] * mm + k
            d = (X[p, 0] - c[j, 0]) ** 2 + (X[p, 1] - c[j, 1]) ** 2 + (X[p, 2] - c[j, 2]) ** 2
            if d < best:
                best, kb = d, k
        out_k[i] = kb
        out_d[i] = best


if numba is not None:  # pragma: no branch
    _nearest = numba.njit(cache=True, nogil=True)(_nearest)


def nearest_centres(X, pid, slot, c, mm):
    """For pairs (point ``pid[i]``, face whose ``mm`` cells are rows ``slot[i] * mm ...`` of the centres
    ``c``): the face's cell whose centre is nearest to the point (the first of equals) and the squared
    distance (``inf`` where none is finite).

    >>> c = np.array([[0.0, 0, 0], [1.0, 0, 0], [5.0, 0, 0], [2.0, 0, 0]])
    >>> k, d = nearest_centres(np.array([[1.8, 0, 0]]), np.array([0, 0]), np.array([0, 1]), c, 2)
    >>> k.tolist(), d.round(12).tolist()
    ([1, 1], [0.64, 0.04])
    """
    k, d = np.empty(pid.size, dtype=np.int64), np.empty(pid.size)
    _nearest(np.ascontiguousarray(X, dtype=np.float64), np.asarray(pid, dtype=np.int64),
             np.asarray(slot, dtype=np.int64), c, int(mm), k, d)
    return k, d


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
        k = _traverse(X, dstar, tuple(tree), (c, nrm, r, h), (pid, cid, lb), cap)
        if k <= cap:
            return pid[:k], cid[:k], lb[:k]
        cap = k


def cell_bounds(P, Pu, Pv, m, safety, eps):
    """Bounding cylinders of the ``m x m`` cells of every face (:mod:`ccproof.evaluate.closest`, step 1).

    Parameters
    ----------
    P, Pu, Pv : ndarray, shape (nf, 2 m + 1, 2 m + 1, 3)
        The surface and its first derivatives on the sample grid of each face (index i along u).
    m : int
    safety : float
        Enlargement in units of the largest second difference of a cell's samples.
    eps : float
        Added to every margin (round-off of the samples).

    Returns
    -------
    c, n : ndarray, shape (nf m^2, 3)
        Centre sample and unit normal there (from ``Pu x Pv``; where that is not finite, from the
        cross product of the cell's diagonals, zero where that vanishes too).
    r, h : ndarray, shape (nf m^2,)
        Lateral radius and half-height.

    Notes
    -----
    Cell ``(f, ci, cj)`` is row ``(f m + ci) m + cj`` and holds the 3 x 3 samples
    ``P[f, 2 ci + a, 2 cj + b]``. Compiled with numba; without numba the numpy version
    :func:`cell_bounds_numpy` (the same bounds, tests/evaluate/test_closest.py) runs instead.
    """
    if numba is None:  # pragma: no cover - the loop below would run in plain Python
        return cell_bounds_numpy(P, Pu, Pv, m, safety, eps)
    P = np.ascontiguousarray(P, dtype=np.float64)
    Pu = np.ascontiguousarray(Pu, dtype=np.float64)
    Pv = np.ascontiguousarray(Pv, dtype=np.float64)
    nc = P.shape[0] * m * m
    c, n, r, h = np.empty((nc, 3)), np.empty((nc, 3)), np.empty(nc), np.empty(nc)
    _cell_bounds(P, Pu, Pv, int(m), float(safety), float(eps), c, n, r, h)
    return c, n, r, h


def _cross(a0, a1, a2, b0, b1, b2):
    return a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0


def _cell_bounds(P, Pu, Pv, m, safety, eps, c, n, r, h):
    nf = P.shape[0]
    for f in range(nf):
        for ci in range(m):
            for cj in range(m):
                k = (f * m + ci) * m + cj
                i0, j0 = 2 * ci, 2 * cj
                x0, x1, x2 = P[f, i0 + 1, j0 + 1, 0], P[f, i0 + 1, j0 + 1, 1], P[f, i0 + 1, j0 + 1, 2]
                n0, n1, n2 = _cross(Pu[f, i0 + 1, j0 + 1, 0], Pu[f, i0 + 1, j0 + 1, 1], Pu[f, i0 + 1, j0 + 1, 2],
                                    Pv[f, i0 + 1, j0 + 1, 0], Pv[f, i0 + 1, j0 + 1, 1], Pv[f, i0 + 1, j0 + 1, 2])
                nn = math.sqrt(n0 * n0 + n1 * n1 + n2 * n2)
                if nn > 0.0 and math.isfinite(nn):
                    n0, n1, n2 = n0 / nn, n1 / nn, n2 / nn
                else:  # a degenerate normal at the centre: the cell's diagonals
                    d1 = [P[f, i0 + 2, j0 + 2, q] - P[f, i0, j0, q] for q in range(3)]
                    d2 = [P[f, i0 + 2, j0, q] - P[f, i0, j0 + 2, q] for q in range(3)]
                    n0, n1, n2 = _cross(d1[0], d1[1], d1[2], d2[0], d2[1], d2[2])
                    nn = max(math.sqrt(n0 * n0 + n1 * n1 + n2 * n2), 1e-300)
                    n0, n1, n2 = n0 / nn, n1 / nn, n2 / nn
                zmax = 0.0
                rmax = 0.0
                for a in range(3):
                    for b in range(3):
                        w0 = P[f, i0 + a, j0 + b, 0] - x0
                        w1 = P[f, i0 + a, j0 + b, 1] - x1
                        w2 = P[f, i0 + a, j0 + b, 2] - x2
                        z = w0 * n0 + w1 * n1 + w2 * n2
                        rho = math.sqrt(max(w0 * w0 + w1 * w1 + w2 * w2 - z * z, 0.0))
                        zmax = max(zmax, abs(z))
                        rmax = max(rmax, rho)
                d2 = 0.0  # largest second difference: along u, along v, mixed
                for b in range(3):
                    s = 0.0
                    for q in range(3):
                        e = P[f, i0, j0 + b, q] - 2 * P[f, i0 + 1, j0 + b, q] + P[f, i0 + 2, j0 + b, q]
                        s += e * e
                    d2 = max(d2, math.sqrt(s))
                for a in range(3):
                    s = 0.0
                    for q in range(3):
                        e = P[f, i0 + a, j0, q] - 2 * P[f, i0 + a, j0 + 1, q] + P[f, i0 + a, j0 + 2, q]
                        s += e * e
                    d2 = max(d2, math.sqrt(s))
                s = 0.0
                for q in range(3):
                    e = P[f, i0, j0, q] - P[f, i0, j0 + 2, q] - P[f, i0 + 2, j0, q] + P[f, i0 + 2, j0 + 2, q]
                    s += e * e
                d2 = max(d2, math.sqrt(s))
                margin = safety * d2 + eps
                c[k, 0], c[k, 1], c[k, 2] = x0, x1, x2
                n[k, 0], n[k, 1], n[k, 2] = n0, n1, n2
                r[k] = rmax + margin
                h[k] = zmax + margin


def cell_bounds_numpy(P, Pu, Pv, m, safety, eps):
    """The numpy reference of :func:`cell_bounds` (same arguments and results)."""
    nf = P.shape[0]
    N = np.cross(Pu[:, 1::2, 1::2], Pv[:, 1::2, 1::2])
    nn = np.linalg.norm(N, axis=-1, keepdims=True)
    blocks = np.stack(
        [P[:, i0 : i0 + 2 * m - 1 : 2, j0 : j0 + 2 * m - 1 : 2] for i0 in range(3) for j0 in range(3)], axis=3,
    )  # (nf, m, m, 9, 3), sample (a, b) -> 3 a + b
    C = blocks[:, :, :, 4]
    good = (nn[..., 0] > 0) & np.isfinite(nn[..., 0])
    with np.errstate(invalid="ignore", divide="ignore"):
        Nc = np.where(good[..., None], N / np.where(good[..., None], nn, 1.0), 0.0)
    if not good.all():
        d1 = blocks[:, :, :, 8] - blocks[:, :, :, 0]
        d2 = blocks[:, :, :, 6] - blocks[:, :, :, 2]
        alt = np.cross(d1, d2)
        alt /= np.maximum(np.linalg.norm(alt, axis=-1, keepdims=True), 1e-300)
        Nc = np.where(good[..., None], Nc, alt)
    W = blocks - C[:, :, :, None]
    z = np.einsum("fijsc,fijc->fijs", W, Nc)
    rho = np.sqrt(np.maximum(np.einsum("fijsc,fijsc->fijs", W, W) - z * z, 0.0))
    b = blocks.reshape(nf, m, m, 3, 3, 3)
    d2u = np.linalg.norm(b[:, :, :, 0] - 2 * b[:, :, :, 1] + b[:, :, :, 2], axis=-1).max(axis=-1)
    d2v = np.linalg.norm(b[:, :, :, :, 0] - 2 * b[:, :, :, :, 1] + b[:, :, :, :, 2], axis=-1).max(axis=-1)
    d2x = np.linalg.norm(b[:, :, :, 0, 0] - b[:, :, :, 0, 2] - b[:, :, :, 2, 0] + b[:, :, :, 2, 2], axis=-1)
    margin = safety * np.maximum(np.maximum(d2u, d2v), d2x) + eps
    return (C.reshape(-1, 3), Nc.reshape(-1, 3), (rho.max(axis=-1) + margin).reshape(-1),
            (np.abs(z).max(axis=-1) + margin).reshape(-1))


if numba is not None:  # pragma: no branch
    _cross = numba.njit(cache=True, nogil=True, inline="always")(_cross)
    _cell_bounds = numba.njit(cache=True, nogil=True)(_cell_bounds)
