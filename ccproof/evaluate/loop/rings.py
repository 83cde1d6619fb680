"""The one-rings of many triangles at once (numba), read as
:func:`~ccproof.evaluate.loop.complex.canonical_triangle_ring` reads them, with an encoding of their keys: triangles
with equal encodings have equal ring keys (the key computed once per encoding, at setup).

Half-edge ``h = 3 f + i`` runs from corner i of triangle f to corner i + 1; ``twin[h]`` is its opposite
(-1 where the complex of the rings has none). The encoding of a ring is a row of integers: the ring's size,
its triangles (in ring labels of 20 bits, each triangle listed from its lowest label, sorted), its tagged edges
(the key's selection: from the lower label, or on the boundary; with the bits of their sharpness) and its tagged
vertices (with the bits of their sharpness), each list after its length.
"""

from __future__ import annotations

import functools

import numba
import numpy as np

__all__ = ["triangle_rings", "equal_rows", "halfedge_sharpness", "vertex_sharpness_array"]


@numba.njit(cache=True)
def _fan(F, twin, h0, out, ccw, cw):
    """Neighbours of the origin of half-edge h0 as ``TriComplex.fan`` lists them from h0's end: written to
    ``out`` with their faces (``out[1]``: the face between out[0][k] and out[0][k + 1]); (count, closed)."""
    start = F[h0 // 3, (h0 % 3 + 1) % 3]
    n, h = 1, h0
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
def _label(ring, n, x, seen, at):
    """The label of vertex x in the ring (added where new): (label, size); ``seen[x] == at[0]`` where x has
    one in the ring of triangle ``at[0]``, ``at[1] + x``."""
    if seen[x] == at[0]:
        return at[1 + x], n
    seen[x] = at[0]
    at[1 + x] = n
    ring[n] = x
    return n, n + 1


@numba.njit(cache=True)
def _ring(F, twin, f, rot, ring, scratch, faces, seen, at, fseen):
    """The ring of triangle f from its corner rot into ``ring``, its triangles into ``faces``: (size, count)."""
    n, nf = 0, 0
    for i in range(3):
        _, n = _label(ring, n, F[f, (rot + i) % 3], seen, at)
    fan, ccw, cw = scratch[0:2], scratch[2:4], scratch[4:6]
    for i in range(3):
        k, closed = _fan(F, twin, 3 * f + (rot + i) % 3, fan, ccw, cw)
        for j in range(k):
            _, n = _label(ring, n, fan[0, j], seen, at)
        for j in range(k if closed else k - 1):
            g = fan[1, j]
            if fseen[g] != at[0]:
                fseen[g] = at[0]
                faces[nf] = g
                nf += 1
    return n, nf


@numba.njit(cache=True)
def _one(F, twin, hsharp, hbits, vbits, f, rot, ring, row, scratch, faces, lab, pairs, seen, at, fseen):
    """Ring and key encoding of one triangle: [size, count, triangles..., count, (edge, bits)..., count,
    (label, bits)...], labels packed 20 bits each; returns the encoding's length."""
    n, nf = _ring(F, twin, f, rot, ring, scratch, faces, seen, at, fseen)
    codes = pairs[:nf, 0]
    for q in range(nf):
        for j in range(3):
            lab[q, j] = _label(ring, n, F[faces[q], j], seen, at)[0]
        s = 0
        for j in range(3):
            if lab[q, j] < lab[q, s]:
                s = j
        codes[q] = (lab[q, s] << 40) | (lab[q, (s + 1) % 3] << 20) | lab[q, (s + 2) % 3]
    row[0], row[1] = n, nf
    row[2:2 + nf] = np.sort(codes)
    p, ns = 2 + nf, 0
    for q in range(nf):
        for j in range(3):
            h = 3 * faces[q] + j
            a, b = lab[q, j], lab[q, (j + 1) % 3]
            if hsharp[h] > 0 and (a < b or twin[h] < 0):
                pairs[ns, 0] = (min(a, b) << 20) | max(a, b)
                pairs[ns, 1] = hbits[h]
                ns += 1
    order = np.argsort(pairs[:ns, 0])
    row[p] = ns
    for q in range(ns):  # an edge once (the key's selection): sorted by its labels
        row[p + 1 + 2 * q] = pairs[order[q], 0]
        row[p + 2 + 2 * q] = pairs[order[q], 1]
    p += 1 + 2 * ns
    nc = 0
    for i in range(n):
        if vbits[ring[i]] != 0:
            row[p + 1 + 2 * nc] = i
            row[p + 2 + 2 * nc] = vbits[ring[i]]
            nc += 1
    row[p] = nc
    return p + 1 + 2 * nc


@numba.njit(cache=True)
def _all(F, twin, hsharp, vcorner, faces, rot, rings, rows, lengths, cap_t):
    hbits, vbits = hsharp.view(np.int64), vcorner.view(np.int64)
    scratch = np.empty((6, rings.shape[1]), dtype=np.int64)
    tri = np.empty(cap_t, dtype=np.int64)
    lab = np.empty((cap_t, 3), dtype=np.int64)
    pairs = np.empty((3 * cap_t, 2), dtype=np.int64)
    seen = np.full(vbits.size, -1, dtype=np.int64)  # per vertex and face: the last triangle whose ring holds it
    at = np.empty(1 + vbits.size, dtype=np.int64)
    fseen = np.full(F.shape[0], -1, dtype=np.int64)
    for r in range(faces.size):
        at[0] = r
        lengths[r] = _one(F, twin, hsharp, hbits, vbits, faces[r], rot[r], rings[r], rows[r], scratch, tri, lab, pairs,
                          seen, at, fseen)


def triangle_rings(F, twin, hsharp, vcorner, faces, max_fan, rot=None):
    """(rings (R, cap) padded with -1, key encodings (R, W) padded with -1, their lengths (R,)) of the triangles
    ``faces`` read from their corner ``rot`` (0 where not given), as :func:`~ccproof.evaluate.loop.plan.oriented_ring`
    lists a triangle from its corner r. Equal encodings (``rows[i, :lengths[i]]``, of any mesh) are equal keys.

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
    Two triangles of a square: the ring of triangle 0 is the four vertices, its triangles both, as labels of
    20 bits each (``(a << 40) | (b << 20) | c``), no tagged edge, no tagged vertex:

    >>> F = np.array([[0, 1, 2], [1, 3, 2]])
    >>> twin = np.array([-1, 5, -1, -1, -1, 1])
    >>> rings, rows, lengths = triangle_rings(F, twin, np.zeros(6), np.zeros(4), np.array([0]), 3)
    >>> rings[0, :4].tolist(), rows[0].tolist() == [4, 2, 2**20 + 2, 2**40 + 3 * 2**20 + 2, 0, 0]
    ([0, 1, 2, 3], True)
    """
    cap = 3 + 3 * max_fan
    cap_t = 3 * max_fan
    rings = np.full((faces.size, cap), -1, dtype=np.int64)
    rows = np.full((faces.size, 4 + 7 * cap_t + 2 * cap), -1, dtype=np.int64)
    lengths = np.zeros(faces.size, dtype=np.int64)
    if faces.size:
        _all(np.ascontiguousarray(F, dtype=np.int64), np.ascontiguousarray(twin, dtype=np.int64),
             np.ascontiguousarray(hsharp, dtype=np.float64), np.ascontiguousarray(vcorner, dtype=np.float64),
             np.ascontiguousarray(faces, dtype=np.int64),
             np.zeros(faces.size, dtype=np.int64) if rot is None else np.ascontiguousarray(rot, dtype=np.int64),
             rings, rows, lengths, cap_t)
    return rings, rows[:, :int(lengths.max(initial=0))], lengths


@functools.lru_cache(maxsize=8)
def _hash_weights(n):
    return np.random.default_rng(12345).integers(1, 2**62, n) | 1


def equal_rows(rows):
    """(first row, rows) of the groups of equal rows of ``rows`` (a hash of each, then each row compared with its
    group's first: rows of a colliding hash are left out)."""
    _, first, group = np.unique(rows @ _hash_weights(rows.shape[1]), return_index=True, return_inverse=True)
    group = group.reshape(-1)
    group[~(rows == rows[first[group]]).all(axis=1)] = -1
    order = np.argsort(group, kind="stable")
    bounds = np.searchsorted(group[order], np.arange(first.size + 1))
    return [(int(first[g]), order[bounds[g]:bounds[g + 1]]) for g in range(first.size)]


def halfedge_sharpness(F, edge_sharpness):
    """Per half-edge ``3 f + i`` of triangles ``F`` the sharpness of its edge (0 untagged)."""
    out = np.zeros(F.size)
    if edge_sharpness:
        n = int(F.max()) + 1
        E = np.array(list(edge_sharpness), dtype=np.int64).reshape(-1, 2)
        code = np.minimum(E[:, 0], E[:, 1]) * n + np.maximum(E[:, 0], E[:, 1])
        order = np.argsort(code)
        a, b = F.reshape(-1), np.roll(F, -1, axis=1).reshape(-1)
        h = np.minimum(a, b) * n + np.maximum(a, b)
        pos = np.minimum(np.searchsorted(code, h, sorter=order), code.size - 1)
        hit = code[order[pos]] == h
        out[hit] = np.array(list(edge_sharpness.values()), dtype=np.float64)[order[pos[hit]]]
    return out


def vertex_sharpness_array(n, vertex_sharpness):
    out = np.zeros(n)
    if vertex_sharpness:
        out[np.array(list(vertex_sharpness), dtype=np.int64)] = np.maximum(list(vertex_sharpness.values()), 0.0)
    return out
