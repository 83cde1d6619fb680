"""The cells of the closest-point search (:mod:`ccproof.evaluate.closest`): one cylinder per face enclosing its
cells' cylinders (:func:`enclosing_cylinders`), the cache of the cells of recently refined faces
(:class:`CellCache`), and the order of the query points that keeps nearby points together (:func:`morton_order`).
"""

from __future__ import annotations

import numpy as np

__all__ = ["enclosing_cylinders", "morton_order", "CellCache"]


def enclosing_cylinders(centre, c, n, r, h, mm):
    """Per face, a cylinder around ``centre`` (k, 3) holding the cylinders (c, n, r, h) of its ``mm`` cells.

    The axis ``a`` is the mean of the cells' axes ``n`` (``(0, 0, 1)`` where it vanishes). A cell's cylinder
    reaches ``h |<n, a>| + r sin`` along ``a`` and ``r + h sin`` across it (``sin`` the sine of the angle
    between n and a), so the face's half-height and radius are the largest of ``|z| + h |<n, a>| + r sin``
    and ``rho + r + h sin`` (z, rho: axial and lateral offsets of the cell centres). Bounds that are not
    finite become infinite (the face is then always a candidate).

    >>> c = np.array([[1.0, 0, 0], [-1.0, 0, 0]]); n = np.array([[0, 0, 1.0], [0, 0, 1.0]])
    >>> bounds = enclosing_cylinders(np.zeros((1, 3)), c, n, np.array([0.5, 0.25]), np.array([0.1, 0.2]), 2)
    >>> [a.tolist() for a in bounds]
    [[[0.0, 0.0, 0.0]], [[0.0, 0.0, 1.0]], [1.5], [0.2]]
    """
    k = centre.shape[0]
    C, N, r, h = c.reshape(k, mm, 3), n.reshape(k, mm, 3), r.reshape(k, mm), h.reshape(k, mm)
    axis = N.sum(axis=1)
    nn = np.linalg.norm(axis, axis=1, keepdims=True)
    good = np.isfinite(nn) & (nn > 0)
    axis = np.where(good, axis / np.where(good, nn, 1.0), np.array([0.0, 0.0, 1.0]))
    W = C - centre[:, None, :]
    z = np.einsum("kmc,kc->km", W, axis)
    rho = np.sqrt(np.maximum(np.einsum("kmc,kmc->km", W, W) - z * z, 0.0))
    cos = np.minimum(np.abs(np.einsum("kmc,kc->km", N, axis)), 1.0)
    sin = np.sqrt(np.maximum(1.0 - cos * cos, 0.0))
    with np.errstate(invalid="ignore"):
        fr = (rho + r + h * sin).max(axis=1)
        fh = (np.abs(z) + h * cos + r * sin).max(axis=1)
    bad = ~(np.isfinite(fr) & np.isfinite(fh))
    return centre, axis, np.where(bad, np.inf, fr), np.where(bad, np.inf, fh)


def morton_order(X, bits=10):
    """Order of the points ``X`` (n, 3) along a Z-order (Morton) curve of their bounding box (``bits`` per axis).

    >>> morton_order(np.array([[1.0, 1, 1], [0, 0, 0], [1, 0, 0], [0, 0.1, 0]])).tolist()
    [1, 3, 2, 0]
    """
    if X.shape[0] == 0:
        return np.zeros(0, dtype=np.int64)
    lo, ext = X.min(axis=0), np.ptp(X, axis=0)
    q = ((X - lo) / np.where(ext > 0, ext, 1.0) * ((1 << bits) - 1)).astype(np.int64)
    code = np.zeros(X.shape[0], dtype=np.int64)
    for b in range(bits):
        for a in range(3):
            code |= ((q[:, a] >> b) & 1) << (3 * b + a)
    return np.argsort(code, kind="stable")


def _grown(a, n):
    """``a`` in a new array of ``n`` rows (its rows first; np.resize would keep a larger base alive)."""
    out = np.empty((n,) + a.shape[1:], dtype=a.dtype)
    out[: a.shape[0]] = a
    return out


class CellCache:
    """Cell cylinders of recently refined faces, ``capacity`` faces at most (emptied when full; the arrays
    grow as faces are added). ``refine(pos)`` yields ``(block, (c, n, r, h))``: the faces of ``pos`` in blocks
    with their ``mm`` cells each."""

    def __init__(self, n_faces, mm, capacity, refine):
        self.mm, self.capacity, self.refine = mm, capacity, refine
        self.slot = np.full(n_faces, -1, dtype=np.int32)
        self.pos = np.empty(0, dtype=np.int64)
        self.c, self.n, self.r, self.h = np.empty((0, 3)), np.empty((0, 3)), np.empty(0), np.empty(0)
        self.size = 0

    def nbytes(self):
        return sum(a.nbytes for a in (self.slot, self.pos, self.c, self.n, self.r, self.h))

    def cells(self):
        return self.c, self.n, self.r, self.h

    def _reserve(self, faces):
        """Room for ``faces`` faces (at most ``capacity``; doubling)."""
        if faces <= self.pos.size:
            return
        cap = min(self.capacity, max(faces, 2 * self.pos.size))
        rows = cap * self.mm
        self.pos, self.c, self.n, self.r, self.h = (_grown(a, n) for a, n in zip(
            (self.pos, self.c, self.n, self.r, self.h), (cap, rows, rows, rows, rows)))

    def ensure(self, pos):
        """Slots of the faces at ``pos`` (at most ``capacity`` distinct), refining those not cached."""
        new = np.unique(pos[self.slot[pos] < 0])
        if self.size + new.size > self.capacity:
            self.slot[self.pos[: self.size]] = -1
            self.size = 0
            new = np.unique(pos)
        for pos_blk, cells in self.refine(new):
            self.store(pos_blk, *cells)
        return self.slot[pos].astype(np.int64)

    def store(self, pos, c, n, r, h):
        """Add the cells (c, n, r, h) of the faces at ``pos`` (not cached, room left)."""
        mm = self.mm
        self._reserve(self.size + pos.size)
        a, b = self.size * mm, (self.size + pos.size) * mm
        self.c[a:b], self.n[a:b], self.r[a:b], self.h[a:b] = c, n, r, h
        self.pos[self.size: self.size + pos.size] = pos
        self.slot[pos] = np.arange(self.size, self.size + pos.size)
        self.size += pos.size
