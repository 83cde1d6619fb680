"""The one-rings of many triangles at once (numba), read as :func:`~ccproof.evaluate.loop.complex.canonical_triangle_ring`
reads them, with an encoding of their keys: triangles with equal encodings have equal ring keys.

Half-edge ``h = 3 f + i`` runs from corner i of triangle f to corner i + 1; ``twin[h]`` is its opposite
(-1 where the complex of the rings has none). The encoding of a ring is one row of integers: the ring's size,
its triangles (in ring labels, each listed from its lowest label, sorted), its tagged edges (the key's
selection: from the lower label, or on the boundary; with the bits of their sharpness) and its tagged
vertices (with the bits of their sharpness), each list with its length, padded with -1.
"""

from __future__ import annotations

import numba
import numpy as np

__all__ = ["triangle_rings"]


@numba.njit(cache=True)
def _fan(F, twin, h0, out):
    """Neighbours of the origin of half-edge h0 as ``TriComplex.fan`` lists them from h0's end: written to
    ``out`` with their faces (``out[1]``: the face between out[0][k] and out[0][k + 1]); (count, closed)."""
    start = F[h0 // 3, (h0 % 3 + 1) % 3]
    n, h = 1, h0
    ccw = np.empty((2, out.shape[1]), dtype=np.int64)
    ccw[0, 0] = start
    while True:  # counter-clockwise: the third vertex of h's face, then the half-edge to it
        f = h // 3
        w = F[f, (h % 3 + 2) % 3]
        ccw[1, n - 1] = f
        if w == start:
            out[:, :n] = ccw[:, :n]
            return n, True
        ccw[0, n] = w
        n += 1
        h = twin[3 * f + (h % 3 + 2) % 3]
        if h < 0:
            break
    m, h = 0, h0
    cw = np.empty((2, out.shape[1]), dtype=np.int64)
    while twin[h] >= 0:  # clockwise from start
        t = twin[h]
        f = t // 3
        h = 3 * f + (t % 3 + 1) % 3
        cw[0, m] = F[f, (h % 3 + 1) % 3]
        cw[1, m] = f
        m += 1
    for k in range(m):
        out[0, k] = cw[0, m - 1 - k]
        out[1, k] = cw[1, m - 1 - k]
    out[0, m:m + n] = ccw[0, :n]
    out[1, m:m + n - 1] = ccw[1, :n - 1]
    return m + n, False


@numba.njit(cache=True)
def _label(ring, n, x):
    for i in range(n):
        if ring[i] == x:
            return i, n
    ring[n] = x
    return n, n + 1


@numba.njit(cache=True)
def _one(F, twin, hsharp, vcorner, f, rot, ring, row, cap_t):
    n = 3
    for i in range(3):
        ring[i] = F[f, (rot + i) % 3]
    fan = np.empty((2, ring.size), dtype=np.int64)
    faces = np.full(cap_t, -1, dtype=np.int64)
    nf = 0
    for i in range(3):
        k, closed = _fan(F, twin, 3 * f + (rot + i) % 3, fan)
        for j in range(k):
            _, n = _label(ring, n, fan[0, j])
        for j in range(k if closed else k - 1):
            g = fan[1, j]
            new = True
            for q in range(nf):
                new = new and faces[q] != g
            if new:
                faces[nf] = g
                nf += 1
    size = ring.size
    codes = np.empty(nf, dtype=np.int64)
    lab = np.empty((nf, 3), dtype=np.int64)
    for q in range(nf):
        for j in range(3):
            lab[q, j] = _label(ring, n, F[faces[q], j])[0]
        s = 0
        for j in range(3):
            if lab[q, j] < lab[q, s]:
                s = j
        codes[q] = (lab[q, s] * size + lab[q, (s + 1) % 3]) * size + lab[q, (s + 2) % 3]
    row[:] = -1
    row[0], row[1] = n, nf
    row[2:2 + nf] = np.sort(codes)
    p = 2 + cap_t
    sharp = np.empty((3 * nf, 2), dtype=np.int64)
    ns = 0
    for q in range(nf):
        for j in range(3):
            h = 3 * faces[q] + j
            a, b = lab[q, j], lab[q, (j + 1) % 3]
            if hsharp[h] > 0 and (a < b or twin[h] < 0):
                sharp[ns, 0] = min(a, b) * size + max(a, b)
                sharp[ns, 1] = np.array([hsharp[h]]).view(np.int64)[0]
                ns += 1
    order = np.argsort(sharp[:ns, 0], kind="mergesort")
    row[p] = ns
    for q in range(ns):  # sorted and unique (an edge seen from its two triangles once)
        row[p + 1 + 2 * q] = sharp[order[q], 0]
        row[p + 2 + 2 * q] = sharp[order[q], 1]
    p += 1 + 6 * cap_t
    nc = 0
    for i in range(n):
        if vcorner[ring[i]] > 0:
            row[p + 1 + 2 * nc] = i
            row[p + 2 + 2 * nc] = np.array([vcorner[ring[i]]]).view(np.int64)[0]
            nc += 1
    row[p] = nc


@numba.njit(cache=True)
def _all(F, twin, hsharp, vcorner, faces, rot, rings, rows, cap_t):
    for r in range(faces.size):
        _one(F, twin, hsharp, vcorner, faces[r], rot[r], rings[r], rows[r], cap_t)


def triangle_rings(F, twin, hsharp, vcorner, faces, max_fan, rot=None):
    """(rings (R, cap) padded with -1, key encodings (R, W)) of the triangles ``faces`` read from their corner
    ``rot`` (0 where not given), as :func:`~ccproof.evaluate.loop.plan.oriented_ring` lists a triangle from its corner r.

    Parameters
    ----------
    F : ndarray (m, 3) of int
    twin : ndarray (3 m,) of int
        Each half-edge's opposite in the complex the rings are read from (-1: none).
    hsharp : ndarray (3 m,) of float
        The sharpness of each half-edge's edge (0 untagged).
    vcorner : ndarray (n,) of float
        The sharpness of each vertex's corner tag (0 untagged).
    faces : ndarray (R,) of int
    max_fan : int
        At least the number of neighbours of any corner of these triangles.
    rot : ndarray (R,) of int, optional

    Examples
    --------
    Two triangles of a square: the ring of triangle 0 is the four vertices, its triangles both, coded as
    ``(a cap + b) cap + c`` with ``cap = 3 + 3 max_fan`` (12 here):

    >>> F = np.array([[0, 1, 2], [1, 3, 2]])
    >>> twin = np.array([-1, 5, -1, -1, -1, 1])
    >>> rings, rows = triangle_rings(F, twin, np.zeros(6), np.zeros(4), np.array([0]), 3)
    >>> rings[0, :4].tolist(), rows[0, :4].tolist()
    ([0, 1, 2, 3], [4, 2, 14, 182])
    """
    cap = 3 + 3 * max_fan
    cap_t = 3 * max_fan
    rings = np.full((faces.size, cap), -1, dtype=np.int64)
    rows = np.empty((faces.size, 3 + 7 * cap_t + 1 + 2 * cap), dtype=np.int64)
    if faces.size:
        _all(np.ascontiguousarray(F, dtype=np.int64), np.ascontiguousarray(twin, dtype=np.int64),
             np.ascontiguousarray(hsharp, dtype=np.float64), np.ascontiguousarray(vcorner, dtype=np.float64),
             np.ascontiguousarray(faces, dtype=np.int64),
             np.zeros(faces.size, dtype=np.int64) if rot is None else np.ascontiguousarray(rot, dtype=np.int64),
             rings, rows, cap_t)
    return rings, rows
