"""Triangulation of quad charts and least-squares conformal maps (Levy et al. 2002), numpy/scipy only.

hsh10 initializes by "triangulating the control mesh and applying a polygon parameterization method
such as LSCM" (docs/hsh10.md A6). :func:`lscm` minimizes the conformal energy
``sum_t A_t |grad u - rot90(grad v)|^2`` (piecewise linear on triangles, local orthonormal frames;
the Cauchy-Riemann form keeps the orientation) with two pinned vertices, by one sparse solve of the
normal equations. :func:`lscm_extend` solves the same energy for free vertices around fixed ones
(used for the extension ring of extended charts, docs/hsh10.md A11.6).

Quads are split along their shorter 3D diagonal (:func:`triangulate_quads`), the choice used for
every polygon method here (init, baselines (a) and (d), control-level flip counts).

>>> import numpy as np
>>> V = np.array([[0, 0, 0], [2, 0, 0], [2, 1, 0], [0, 1, 0.0]])
>>> T = triangulate_quads(V, [[0, 1, 2, 3]])
>>> UV = lscm(V, T)
>>> bool(np.allclose(np.linalg.norm(UV[1] - UV[0]), 2) and np.allclose(np.linalg.norm(UV[3] - UV[0]), 1))
True
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

__all__ = ["triangulate_quads", "lscm", "lscm_extend", "signed_areas", "fit_area"]


def triangulate_quads(V, F):
    """Two triangles per quad, split along the shorter diagonal; triangle 2f, 2f+1 from quad f.

    Parameters
    ----------
    V : ndarray, shape (n, 3) float64
    F : array_like, shape (m, 4) int

    Returns
    -------
    ndarray, shape (2m, 3) int64

    Examples
    --------
    A kite whose diagonal 1-3 is the shorter one is split along it:

    >>> import numpy as np
    >>> V = np.array([[0, 0, 0], [2, -0.5, 0], [4, 0, 0], [2, 0.5, 0.0]])
    >>> triangulate_quads(V, [[0, 1, 2, 3]]).tolist()
    [[0, 1, 3], [1, 2, 3]]
    """
    V = np.asarray(V, dtype=np.float64)
    F = np.asarray(F, dtype=np.int64).reshape(-1, 4)
    d02 = np.linalg.norm(V[F[:, 2]] - V[F[:, 0]], axis=1)
    d13 = np.linalg.norm(V[F[:, 3]] - V[F[:, 1]], axis=1)
    use02 = d02 <= d13
    T = np.empty((2 * F.shape[0], 3), dtype=np.int64)
    T[0::2] = np.where(use02[:, None], F[:, [0, 1, 2]], F[:, [0, 1, 3]])
    T[1::2] = np.where(use02[:, None], F[:, [0, 2, 3]], F[:, [1, 2, 3]])
    return T


def signed_areas(UV, T):
    """Signed areas of the 2D triangles (positive = counter-clockwise).

    Parameters
    ----------
    UV : ndarray, shape (n, 2) float64
    T : ndarray, shape (t, 3) int

    Returns
    -------
    ndarray, shape (t,) float64

    Examples
    --------
    >>> import numpy as np
    >>> UV = np.array([[0, 0], [2, 0], [0, 1.0]])
    >>> signed_areas(UV, np.array([[0, 1, 2], [0, 2, 1]])).tolist()
    [1.0, -1.0]
    """
    a = UV[T[:, 1]] - UV[T[:, 0]]
    b = UV[T[:, 2]] - UV[T[:, 0]]
    return 0.5 * (a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0])


def _conformal_operator(V, T, n):
    """Sparse K (2t, 2n) with K [u; v] = sqrt(A_t) (grad u - rot90 grad v) per triangle."""
    V = np.asarray(V, dtype=np.float64)
    e1 = V[T[:, 1]] - V[T[:, 0]]
    e2 = V[T[:, 2]] - V[T[:, 0]]
    l1 = np.linalg.norm(e1, axis=1)
    cr = np.linalg.norm(np.cross(e1, e2), axis=1)
    x1 = l1
    x2 = np.einsum("ij,ij->i", e1, e2) / l1
    y2 = cr / l1
    area = 0.5 * cr
    # gradient of the linear interpolant: grad f = [[1/x1, 0], [-x2/(x1 y2), 1/y2]] (f1 - f0, f2 - f0)
    g = np.zeros((T.shape[0], 2, 3))  # grad = g @ (f0, f1, f2)
    g[:, 0, 1] = 1 / x1
    g[:, 0, 0] = -1 / x1
    g[:, 1, 1] = -x2 / (x1 * y2)
    g[:, 1, 2] = 1 / y2
    g[:, 1, 0] = -(g[:, 1, 1] + g[:, 1, 2])
    s = np.sqrt(area)[:, None]
    t = T.shape[0]
    r0 = np.repeat(2 * np.arange(t), 3)
    r1 = r0 + 1
    cols = T.ravel()
    # residual 1: u_x - v_y ; residual 2: u_y + v_x
    rows = np.r_[r0, r0, r1, r1]
    cc = np.r_[cols, cols + n, cols, cols + n]
    vals = np.r_[(g[:, 0] * s).ravel(), -(g[:, 1] * s).ravel(), (g[:, 1] * s).ravel(), (g[:, 0] * s).ravel()]
    return sp.csr_matrix((vals, (rows, cc)), shape=(2 * t, 2 * n))


def _solve_pinned(K, n, fixed, fixed_uv, reg=0.0):
    fixed = np.asarray(fixed, dtype=np.int64)
    fz = np.r_[fixed, fixed + n]
    zf = np.r_[fixed_uv[:, 0], fixed_uv[:, 1]]
    free = np.setdiff1d(np.arange(2 * n), fz)
    Kf = K[:, free]
    M = (Kf.T @ Kf).tocsc()
    if reg:
        M = M + reg * float(M.diagonal().mean()) * sp.identity(M.shape[0], format="csc")
    rhs = -(Kf.T @ (K[:, fz] @ zf))
    z = np.empty(2 * n)
    z[fz] = zf
    z[free] = spla.spsolve(M, rhs)
    return np.stack([z[:n], z[n:]], axis=1)


def _far_pair(V, cand):
    p = cand[0]
    for _ in range(2):
        q = cand[np.argmax(np.linalg.norm(V[cand] - V[p], axis=1))]
        p, q = q, p
    return q, p


def lscm(V, T, pins=None):
    """Least-squares conformal map of a triangulated disk; two pinned vertices.

    Parameters
    ----------
    V : (n, 3), T : (t, 3) int
    pins : (2,) int, optional
        Default: two far-apart boundary vertices (two sweeps of farthest points). They are pinned
        at (0, 0) and (|V[p1] - V[p0]|, 0).

    Returns
    -------
    (n, 2) texture coordinates (orientation preserving: positive signed areas for a valid map).

    Examples
    --------
    A planar square is mapped to a congruent square:

    >>> import numpy as np
    >>> V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0.0]])
    >>> T = triangulate_quads(V, [[0, 1, 2, 3]])
    >>> UV = lscm(V, T)
    >>> np.round(signed_areas(UV, T), 9).tolist(), round(float(np.linalg.norm(UV[1] - UV[0])), 9)
    ([0.5, 0.5], 1.0)
    """
    V = np.asarray(V, dtype=np.float64)
    T = np.asarray(T, dtype=np.int64)
    n = V.shape[0]
    if pins is None:
        e = np.sort(np.r_[T[:, [0, 1]], T[:, [1, 2]], T[:, [2, 0]]], axis=1)
        ue, cnt = np.unique(e, axis=0, return_counts=True)
        bnd = np.unique(ue[cnt == 1])
        cand = bnd if bnd.size >= 2 else np.unique(T)
        pins = _far_pair(V, cand)
    p0, p1 = int(pins[0]), int(pins[1])
    K = _conformal_operator(V, T, n)
    uv = np.array([[0.0, 0.0], [np.linalg.norm(V[p1] - V[p0]), 0.0]])
    return _solve_pinned(K, n, [p0, p1], uv)


def lscm_extend(V, T, fixed, fixed_uv, reg=1e-9):
    """Minimize the conformal energy of ``T`` over the vertices not in ``fixed``.

    A tiny Tikhonov term keeps vertices that the energy leaves undetermined at a finite place; the
    conformal extension of the initialization of extended charts (docs/hsh10.md).

    Parameters
    ----------
    V : ndarray, shape (n, 3) float64
    T : ndarray, shape (t, 3) int
    fixed : ndarray of int
        Vertices held at ``fixed_uv``.
    fixed_uv : ndarray, shape (len(fixed), 2) float64
    reg : float, optional

    Returns
    -------
    ndarray, shape (n, 2) float64

    Examples
    --------
    A planar square with one edge fixed at its true place is reproduced:

    >>> import numpy as np
    >>> V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0.0]])
    >>> UV = lscm_extend(V, triangulate_quads(V, [[0, 1, 2, 3]]), np.array([0, 1]), np.array([[0, 0], [1, 0.0]]))
    >>> np.round(UV, 6).tolist()
    [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]
    """
    V = np.asarray(V, dtype=np.float64)
    K = _conformal_operator(V, np.asarray(T, dtype=np.int64), V.shape[0])
    return _solve_pinned(K, V.shape[0], fixed, np.asarray(fixed_uv, dtype=np.float64), reg=reg)


def fit_area(UV, V, T):
    """Scale (about the centroid) and, if needed, mirror ``UV`` to the surface area of ``T``.

    Its signed area is then positive and equals the surface area of the triangles ``T``.

    Parameters
    ----------
    UV : ndarray, shape (n, 2) float64
    V : ndarray, shape (n, 3) float64
    T : ndarray, shape (t, 3) int

    Returns
    -------
    ndarray, shape (n, 2) float64

    Examples
    --------
    >>> import numpy as np
    >>> V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0.0]])
    >>> T = triangulate_quads(V, [[0, 1, 2, 3]])
    >>> float(signed_areas(fit_area(-3 * V[:, :2], V, T), T).sum())
    1.0
    """
    UV = np.array(UV, dtype=np.float64, copy=True)
    sa = signed_areas(UV, T).sum()
    if sa < 0:
        UV[:, 0] = -UV[:, 0]
        sa = -sa
    e1 = V[T[:, 1]] - V[T[:, 0]]
    e2 = V[T[:, 2]] - V[T[:, 0]]
    A = 0.5 * np.linalg.norm(np.cross(e1, e2), axis=1).sum()
    c = UV[np.unique(T)].mean(axis=0)
    return c + (UV - c) * np.sqrt(A / sa)
