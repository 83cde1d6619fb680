"""Uniform cubic B-spline basis, its exact 1D Gram matrices and the normal-element matrices (qmv98).

One knot span of the uniform cubic B-spline (qmv98 eq. 1, docs/qmv98.md B2)::

    B0 = (1-u)^3/6,  B1 = (3u^3 - 6u^2 + 4)/6,  B2 = (-3u^3 + 3u^2 + 3u + 1)/6,  B3 = u^3/6.

A bicubic patch on the unit square is ``s(u, v) = sum_{i,j} d_ij B_i(u) B_j(v)``; its 16 control
points are numbered ``k = 4 i + j`` with ``i`` along ``u`` (qmv98 eq. 2). The paper's 3 x 48 matrix
``J_p`` interleaves x, y, z (entries ``3k, 3k+1, 3k+2``); since every coordinate uses the same
weights, ccproof works with the *scalar* 1 x 16 row ``N(u, v)`` (``J_p = N (x) I_3``, see
:func:`paper_patch_jacobian`) and with control points as ``(n, 3)`` arrays.

With constant densities the normal-element matrices are Kronecker products of the span Grams
``G_r[a, b] = int_0^1 B_a^(r) B_b^(r) du`` (docs/qmv98.md B5; computed here exactly in rational arithmetic):

* mass ``M = mu G0 (x) G0``;
* stiffness ``K = a11 G1(x)G0 + a22 G0(x)G1 + b11 G2(x)G0 + b12 G1(x)G1 + b22 G0(x)G2`` (qmv98 eq. 20,
  "thin plate under tension"; ``b12`` multiplies ``J_uv^T J_uv`` once).

>>> G0, G1, G2 = (gram(r) for r in range(3))
>>> str(G0[1][1]), str(G1[0][1]), str(G2[0][3])
('33/140', '7/120', '1/6')
>>> import numpy as np
>>> round(float(np.kron(gram_float(0), gram_float(0)).sum()), 12)      # 1^T M 1 = mu for mu = 1
1.0
"""

from __future__ import annotations

import functools
from fractions import Fraction

import numpy as np

__all__ = [
    "BASIS_COEFFS",
    "basis_1d",
    "gram",
    "gram_float",
    "TERMS",
    "term_matrix",
    "patch_rows",
    "paper_patch_jacobian",
]

#: coefficients (of 1, u, u^2, u^3) of 6 B_a(u), a = 0..3
BASIS_COEFFS = ((1, -3, 3, -1), (4, 0, -6, 3), (1, 3, 3, -3), (0, 0, 0, 1))

#: the six per-patch integrands, as (r_u, r_v) derivative orders in the Kronecker form
#: (first factor: the u (or s) direction, index i of k = 4 i + j)
TERMS = {
    "mass": (0, 0),  # J^T J
    "uu1": (1, 0),  # J_u^T J_u   (tension a11)
    "vv1": (0, 1),  # J_v^T J_v   (tension a22)
    "uu2": (2, 0),  # J_uu^T J_uu (rigidity b11)
    "uv2": (1, 1),  # J_uv^T J_uv (rigidity b12)
    "vv2": (0, 2),  # J_vv^T J_vv (rigidity b22)
}


def _poly_deriv(c, r):
    c = list(c)
    for _ in range(r):
        c = [i * c[i] for i in range(1, len(c))] or [0]
    return c


@functools.cache
def gram(r):
    """Exact span Gram matrix ``G_r[a][b] = int_0^1 B_a^(r)(u) B_b^(r)(u) du`` (list of Fractions).

    Parameters
    ----------
    r : int
        Derivative order of both factors (0, 1 or 2).

    Returns
    -------
    list of list of Fraction, shape (4, 4)

    Examples
    --------
    >>> [str(x) for x in gram(2)[0]]
    ['1/3', '-1/2', '0', '1/6']
    """
    if r not in (0, 1, 2):
        raise ValueError(f"derivative order must be 0, 1 or 2, got {r!r}")
    polys = [[Fraction(x, 6) for x in _poly_deriv(c, r)] for c in BASIS_COEFFS]
    G = []
    for a in range(4):
        row = []
        for b in range(4):
            s = Fraction(0)
            for p, x in enumerate(polys[a]):
                for q, y in enumerate(polys[b]):
                    s += x * y / (p + q + 1)
            row.append(s)
        G.append(tuple(row))
    return tuple(G)


@functools.cache
def gram_float(r):
    """:func:`gram` as a read-only float64 (4, 4) array.

    Parameters
    ----------
    r : int
        Derivative order (0, 1 or 2).

    Returns
    -------
    ndarray, shape (4, 4) float64, read-only

    Examples
    --------
    The cubic B-splines sum to 1 on [0, 1], so all entries of the r = 0 Gram matrix sum to 1:

    >>> round(float(gram_float(0).sum()), 15), gram_float(0).flags.writeable
    (1.0, False)
    """
    G = np.array([[float(x) for x in row] for row in gram(r)])
    G.setflags(write=False)
    return G


@functools.cache
def term_matrix(term):
    """The 16 x 16 patch matrix of one integrand of :data:`TERMS` on the unit square, unit density.

    Parameters
    ----------
    term : str
        A key of :data:`TERMS` (``"mass"``, ``"uu1"``, ... : the integrands of the mass and of the
    stiffness of qmv98 eq. 20: ``J^T J``, ``J_u^T J_u``, ...).

    Returns
    -------
    ndarray, shape (16, 16) float64

    Examples
    --------
    >>> K = term_matrix("uu2")
    >>> K.shape, bool(abs(K.sum(axis=1)).max() < 1e-15)       # annihilates translations
    ((16, 16), True)
    """
    ru, rv = TERMS[term]
    K = np.kron(gram_float(ru), gram_float(rv))
    K.setflags(write=False)
    return K


def basis_1d(x, derivatives=0):
    """Values (and derivatives up to ``derivatives``) of B0..B3 at ``x``: list of arrays (..., 4).

    Parameters
    ----------
    x : array_like, float64
        Parameters in [0, 1].
    derivatives : int, optional

    Returns
    -------
    list of ndarray, shape x.shape + (4,) float64
        Values, then derivatives 1 .. ``derivatives``.

    Examples
    --------
    >>> [row.tolist() for row in np.round(basis_1d([0.0], 0)[0] * 6, 12)]
    [[1.0, 4.0, 1.0, 0.0]]
    """
    x = np.asarray(x, dtype=np.float64)
    out = []
    powers = np.stack([np.ones_like(x), x, x * x, x * x * x], axis=-1)
    for r in range(derivatives + 1):
        C = np.array([_poly_deriv(c, r) + [0] * r for c in BASIS_COEFFS], dtype=np.float64).T / 6.0
        out.append(powers @ C)
    return out


def patch_rows(u, v, derivatives=0):
    """Scalar shape-function rows of a bicubic patch at points ``(u, v)``.

    Parameters
    ----------
    u, v : array_like, shape (m,)
    derivatives : 0, 1 or 2

    Returns
    -------
    dict of ndarray, shape (m, 16)
        ``"P"`` and, as requested, ``"Pu", "Pv"`` and ``"Puu", "Puv", "Pvv"``; column ``4 i + j``.

    >>> r = patch_rows([0.5], [0.5])["P"]
    >>> r.shape, round(float(r.sum()), 12)
    ((1, 16), 1.0)
    """
    bu = basis_1d(u, derivatives)
    bv = basis_1d(v, derivatives)

    def tp(a, b):
        return (a[:, :, None] * b[:, None, :]).reshape(a.shape[0], 16)

    out = {"P": tp(bu[0], bv[0])}
    if derivatives >= 1:
        out["Pu"] = tp(bu[1], bv[0])
        out["Pv"] = tp(bu[0], bv[1])
    if derivatives >= 2:
        out["Puu"] = tp(bu[2], bv[0])
        out["Puv"] = tp(bu[1], bv[1])
        out["Pvv"] = tp(bu[0], bv[2])
    return out


def paper_patch_jacobian(u, v):
    """The paper's 3 x 48 matrix ``J_p(u, v)`` of eq. (2) (x, y, z interleaved, k = 4 i + j).

    Parameters
    ----------
    u, v : float
        Patch parameters in [0, 1].

    Returns
    -------
    ndarray, shape (3, 48) float64

    Examples
    --------
    >>> J = paper_patch_jacobian(0.25, 0.75)
    >>> J.shape, bool(np.allclose(J[1, 1::3].sum(), 1.0)), float(J[0, 1])
    ((3, 48), True, 0.0)
    """
    row = patch_rows(np.atleast_1d(float(u)), np.atleast_1d(float(v)))["P"][0]
    return np.kron(row[None, :], np.eye(3))
