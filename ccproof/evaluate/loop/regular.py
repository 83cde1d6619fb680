"""The regular triangles of a whole mesh at once (numpy): which they are and their 12 control points.

A triangle is taken here when its three corners are interior vertices of valence 6 with no tagged edge
or corner tag at them (the box spline's case without ghosts); every other triangle goes through the
exact per-configuration path (:mod:`ccproof.evaluate.loop.plan`), which finds the same nets for these
(tests/evaluate/test_loop.py compares the two).

Half-edge ``h = 3 f + i`` runs from corner i of triangle f to corner i + 1; counter-clockwise around
its origin the next half-edge is ``twin(prev(h))``.
"""

from __future__ import annotations

import functools

import numpy as np

from ccproof.evaluate.loop.box_spline import DIRS, NET

__all__ = ["regular_triangles"]


@functools.lru_cache(maxsize=1)
def _net_sources():
    """Per NET position: (corner i, step j) whose j-th counter-clockwise neighbour (from corner i + 1) it is;
    corners themselves as (i, -1)."""
    where = {(0, 0): (0, -1), (1, 0): (1, -1), (0, 1): (2, -1)}
    for i, base in enumerate(((0, 0), (1, 0), (0, 1))):
        for j in range(6):
            d = DIRS[(2 * i + j) % 6]
            where.setdefault((base[0] + d[0], base[1] + d[1]), (i, j))
    return [where[p] for p in NET]


def regular_triangles(F, n_vertices, tagged_vertices=(), twin=None):
    """(mask (m,) of the regular triangles, their control points' vertex labels (R, 12) in NET order, per
    vertex whether it is simple (interior, valence 6, untagged), per vertex whether it is on the boundary).

    Parameters
    ----------
    F : ndarray of int, shape (m, 3)
    n_vertices : int
    tagged_vertices : iterable of int
        Vertices with a tagged edge or a corner tag (never regular here).
    twin : ndarray of int, shape (3 m,), optional
        The opposite of every half-edge ``3 f + i`` (-1 on the boundary), when known (a manifold mesh's
        :attr:`HalfEdges.twin <ccproof.mesh.halfedges.HalfEdges.twin>`); else paired here.

    Examples
    --------
    >>> F = np.array([[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]])
    >>> regular_triangles(F, 6)[0].any()        # the octahedron: valence 4 everywhere
    np.False_
    """
    F = np.asarray(F, dtype=np.int64)
    src = F.reshape(-1)
    dst = np.roll(F, -1, axis=1).reshape(-1)
    if twin is None:
        key = src * n_vertices + dst
        order = np.argsort(key, kind="stable")
        rev = dst * n_vertices + src
        pos = np.minimum(np.searchsorted(key, rev, sorter=order), key.size - 1)
        twin = np.where(key[order[pos]] == rev, order[pos], -1)
    valence = np.bincount(src, minlength=n_vertices)
    boundary = np.zeros(n_vertices, dtype=bool)
    boundary[src[twin < 0]] = True
    boundary[dst[twin < 0]] = True
    simple = (valence == 6) & ~boundary
    simple[np.asarray(list(tagged_vertices), dtype=np.int64)] = False
    reg = simple[F].all(axis=1)
    faces = np.flatnonzero(reg)
    fans = np.empty((faces.size, 3, 6), dtype=np.int64)
    prev = np.arange(src.size, dtype=np.int64).reshape(-1, 3)[:, [2, 0, 1]].reshape(-1)
    rot = twin[prev]  # the next half-edge counter-clockwise around the origin
    h = 3 * faces[:, None] + np.arange(3)  # (R, 3)
    for j in range(6):
        fans[:, :, j] = dst[h]
        h = rot[h]
    labels = np.empty((faces.size, 12), dtype=np.int64)
    for k, (i, j) in enumerate(_net_sources()):
        labels[:, k] = F[faces, i] if j < 0 else fans[:, i, j]
    return reg, labels, simple, boundary
