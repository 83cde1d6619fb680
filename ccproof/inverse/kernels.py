"""The vectorized float kernels of the forward and inverse characteristic map: points in blocks
(:data:`CHUNK`, :func:`chunks`), polynomial rows by nested Horner (a point's bits depend on that point only),
the patch evaluation with and without its Jacobian, the safe range of the scaled tables. The data they read
come from :func:`ccproof.inverse.data.valence_data`.
"""

from __future__ import annotations

import numpy as np

from ccproof.inverse.data import monomial_exponents

__all__ = ["CHUNK", "chunks", "polynomial_rows", "patch_eval", "patch_eval_jac", "approx_log", "as_points",
           "SAFE_LO", "SAFE_HI"]


#: points per block in the vectorized kernels (keeps the temporaries in cache)
CHUNK = 16384


def polynomial_rows(C, x, y, degree):
    """Rows of bivariate polynomials at points (x, y), point by point: nested Horner, no BLAS.

    Row r is ``sum C[r, i] x^a y^b`` over the monomials x^a y^b of :func:`monomials` (order of
    :func:`monomial_exponents`), evaluated as ``(...(h_d(y) x + h_{d-1}(y)) x + ...) + h_0(y)`` with
    ``h_a(y) = sum_b C[r, (a, b)] y^b`` by Horner's rule in y. Every product and sum is numpy's
    elementwise one (no BLAS, no fused multiply-add), so a point's bits depend on that point only:
    not on the size of the batch nor on the point's place in it. (A BLAS product ``C @ monomials``
    does not promise that: OpenBLAS takes another kernel for a single column and edge kernels for the
    last columns of a block, which made the inverse of a point depend on the points inverted with it.)

    Parameters
    ----------
    C : ndarray, shape (m, M) float64
        Coefficients, M = (degree + 1)(degree + 2)/2.
    x, y : ndarray, shape (n,) float64
    degree : int
        Total degree.

    Returns
    -------
    ndarray, shape (m, n) float64

    Examples
    --------
    1 + 2x + 3y + 4x^2 + 5xy + 6y^2 at (2, 3) is 1 + 4 + 9 + 16 + 30 + 54 = 114:

    >>> C = np.arange(1.0, 7.0)[None, :]
    >>> polynomial_rows(C, np.array([2.0]), np.array([3.0]), 2).tolist()
    [[114.0]]
    >>> bool(np.array_equal(polynomial_rows(C, np.array([2.0, 0.5]), np.array([3.0, 0.25]), 2)[:, 1:],
    ...                     polynomial_rows(C, np.array([0.5]), np.array([0.25]), 2)))
    True
    """
    col = {e: i for i, e in enumerate(monomial_exponents(degree))}
    out = np.repeat(C[:, col[(degree, 0)], None], x.shape[0], axis=1)
    for a in range(degree - 1, -1, -1):
        h = C[:, col[(a, degree - a)], None] * y  # h_a(y), degree - a >= 1
        for b in range(degree - a - 1, -1, -1):
            h += C[:, col[(a, b)], None]
            if b:
                h *= y
        out *= x
        out += h
    return out


#: blocks whose points all have max(u, v) in [SAFE_LO, SAFE_HI] scale with the double tables
#: (plain products); others with mantissa/exponent tables and ldexp (exact range, 30x slower)
SAFE_LO = 2.0**-900
SAFE_HI = 2.0**900

_LN2 = float(np.log(2.0))
#: quadratic approximation of log(m) on [1/2, 1) (error < 1e-2), used by :func:`approx_log`
_LOG_Q = np.polyfit(np.linspace(0.5, 1.0, 200), np.log(np.linspace(0.5, 1.0, 200)), 2)


def approx_log(a):
    """log(a) to within 1e-2 (a > 0): frexp plus a quadratic; 3x cheaper than np.log."""
    m, e = np.frexp(a)
    c2, c1, c0 = _LOG_Q
    return (c2 * m + c1) * m + (c0 + _LN2 * e)


def patch_eval(Wp, s, t, jacobian=False):
    """P(s, t) of one piece (``Wp`` = ``ValenceData.W[p]``) at arrays s, t (local coordinates).

    Returns (x, y) or (x, y, x_s, x_t, y_s, y_t). The t-polynomials q_i(t) of both components
    (and their t- and s-derivative coefficients) by Horner's rule in t, all rows at once, then
    Horner in s: point by point, so a point's bits do not depend on the other points of the batch.
    """
    W = Wp[:8] if not jacobian else Wp
    Q = _horner_rows(W, t)
    if not jacobian:
        return _horner3(Q, 0, s), _horner3(Q, 4, s)
    return (_horner3(Q, 0, s), _horner3(Q, 4, s), _horner2(Q, 16, s), _horner3(Q, 8, s),
            _horner2(Q, 19, s), _horner3(Q, 12, s))


def _horner_rows(W, t):
    """Row r: the cubic ``W[r, 0] + W[r, 1] t + W[r, 2] t^2 + W[r, 3] t^3`` by Horner's rule, shape (rows, n)."""
    Q = W[:, 3, None] * t
    for j in (2, 1, 0):
        Q += W[:, j, None]
        if j:
            Q *= t
    return Q


def patch_eval_jac(Cp, s, t):
    """(x, y, x_s, x_t, y_s, y_t) of one piece (``Cp`` = ``ValenceData.C6[p]``), shape (6, n).

    The t-polynomials of x, y (cubics) and of x_t, y_t (quadratics) for each power of s by Horner's
    rule in t, then Horner in s, with the s-derivative carried along (x_s, y_s). Point by point (no
    BLAS), so a point's bits do not depend on the other points of the batch.
    """
    C = Cp.reshape(6, 4, 4)  # [output, power of s, power of t]; outputs x, y, x_s, x_t, y_s, y_t
    q = C[0:2, :, 3, None] * t  # (2, 4, n): q_i(t) of x and y
    q += C[0:2, :, 2, None]
    q *= t
    q += C[0:2, :, 1, None]
    q *= t
    q += C[0:2, :, 0, None]
    qt = C[3::2, :, 2, None] * t  # (2, 4, n): the t-derivatives
    qt += C[3::2, :, 1, None]
    qt *= t
    qt += C[3::2, :, 0, None]
    out = np.empty((6, s.shape[0]))
    P, Ps, Pt = out[0:2], out[2::2], out[3::2]
    np.multiply(q[:, 3], s, out=P)
    P += q[:, 2]  # q3 s + q2
    np.multiply(q[:, 3], s, out=Ps)
    Ps += P  # 2 q3 s + q2
    P *= s
    P += q[:, 1]
    Ps *= s
    Ps += P  # 3 q3 s^2 + 2 q2 s + q1
    P *= s
    P += q[:, 0]
    np.multiply(qt[:, 3], s, out=Pt)
    Pt += qt[:, 2]
    Pt *= s
    Pt += qt[:, 1]
    Pt *= s
    Pt += qt[:, 0]
    return out


def _horner3(Q, i, s):
    acc = Q[i + 3] * s
    acc += Q[i + 2]
    acc *= s
    acc += Q[i + 1]
    acc *= s
    acc += Q[i]
    return acc


def _horner2(Q, i, s):
    acc = Q[i + 2] * s
    acc += Q[i + 1]
    acc *= s
    acc += Q[i]
    return acc


def chunks(n, size=CHUNK):
    """Slices covering range(n) in blocks of ``size``.

    Parameters
    ----------
    n : int
    size : int, optional
        Default ``CHUNK``.

    Yields
    ------
    slice

    Examples
    --------
    >>> list(chunks(5, 2))
    [slice(0, 2, None), slice(2, 4, None), slice(4, 5, None)]
    """
    for i in range(0, n, size):
        yield slice(i, min(i + size, n))


def as_points(u, v, what="point"):
    """Broadcast two coordinate arrays to flat float64 arrays; reject NaN, inf and negatives.

    Returns (u, v, shape). Raises :class:`~ccproof.errors.CCProofError`.
    """
    from ccproof.errors import CCProofError

    try:
        u = np.asarray(u, dtype=np.float64)
        v = np.asarray(v, dtype=np.float64)
        u, v = np.broadcast_arrays(u, v)
    except (TypeError, ValueError) as exc:
        raise CCProofError(f"{what} coordinates must be real numbers or arrays of them: {exc}") from None
    shape = u.shape
    u = np.ascontiguousarray(u).ravel()
    v = np.ascontiguousarray(v).ravel()
    for name, a in (("first", u), ("second", v)):
        bad = ~np.isfinite(a)
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise CCProofError(f"{what} {name} coordinate is not finite (NaN or inf) at index {i}: {float(a[i])!r}")
        neg = a < 0
        if neg.any():
            i = int(np.flatnonzero(neg)[0])
            raise CCProofError(
                f"{what} {name} coordinate is negative at index {i}: {float(a[i])!r}; the characteristic map "
                "and its inverse are defined on the quadrant [0, inf)^2")
    return u, v, shape
