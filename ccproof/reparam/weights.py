"""The blending weights of bmz04 section 4.2-4.3 (docs/readings.md R5).

``b(x) = B(6x + 1) + B(6x) + B(6x - 1)`` with ``B`` the centred uniform cubic B-spline (support
[-2, 2]); the paper's "c = 1/6" must be 6 (R5). ``b`` is even, piecewise cubic with breakpoints
1/6, 1/3, 1/2 (in |x|), C2, equal to ``1 - 36 x^3`` on [0, 1/6] and to 0 for |x| >= 1/2.
With ``z = 6|x|``:

=============  =====================================
 z in [0, 1]    1 - z^3 / 6
 z in [1, 2]    (5 - 3 d - 3 d^2 + 2 d^3) / 6,  d = z - 1
 z in [2, 3]    (1 - d)^3 / 6,                  d = z - 2
 z >= 3         0
=============  =====================================

Two weights on a corner quarter (local coordinates (s, t) >= 0, corner at the origin):
:func:`weight_radial` ``w = b(|t|)`` (section 4.2, vanishing derivatives) and
:func:`weight_tensor` ``w = b(s) b(t)`` (section 4.3, characteristic map). Both are 1 at the
corner, C2, and vanish outside [0, 1/2)^2, so the supports of the four corners of a face are
disjoint.
"""

from __future__ import annotations

import numpy as np

__all__ = ["bump", "bump_complement", "weight_radial", "weight_tensor", "weight_complement"]


def bump(x, derivatives=0):
    """The weight b(x) of bmz04 section 4.2 (R5) and its derivatives, vectorized.

    Parameters
    ----------
    x : array_like, shape (n,)
    derivatives : int, 0, 1 or 2

    Returns
    -------
    tuple of ndarray, shape (n,)
        ``(b,)``, ``(b, b')`` or ``(b, b', b'')``.

    Examples
    --------
    >>> np.round(bump([0.0, 1 / 6, 1 / 3, 0.5, 0.7])[0], 12).tolist()
    [1.0, 0.833333333333, 0.166666666667, 0.0, 0.0]
    """
    x = np.asarray(x, dtype=np.float64)
    z = 6.0 * np.abs(x)
    zc = np.minimum(z, 3.0)
    i = np.where(zc >= 0, zc, 3.0).astype(np.int64)  # piece: z in [i, i + 1); 3 for z >= 3 (b = 0) and NaN
    d = z - i
    c0, c1, c2, c3 = (np.take(col, i) for col in _COEF_T)  # coefficients of the piece in d
    out = [((c3 * d + c2) * d + c1) * d + c0]
    if derivatives >= 1:
        bz = (3.0 * c3 * d + 2.0 * c2) * d + c1
        out.append(np.copysign(6.0, x) * bz)
    if derivatives >= 2:
        out.append(36.0 * (6.0 * c3 * d + 2.0 * c2))
    return tuple(out)


def bump_complement(x):
    """1 - b(x) with full relative precision near 0 (36 |x|^3 on [0, 1/6]), shape of x.

    Parameters
    ----------
    x : array_like, float64

    Returns
    -------
    ndarray, shape of ``x`` float64

    Examples
    --------
    1 - b(x) = 36 x^3 at x = 1e-10 is 3.6e-29, to a relative error below 1e-14, while 1 - b(x) in
    floating point is 0:

    >>> bool(abs(float(bump_complement(np.array([1e-10]))[0]) / 3.6e-29 - 1.0) < 1e-14)
    True
    >>> float(1.0 - bump(np.array([1e-10]))[0][0])
    0.0
    """
    x = np.asarray(x, dtype=np.float64)
    z = 6.0 * np.abs(x)
    out = 1.0 - bump(x)[0]
    near = z < 1.0
    out[near] = z[near] ** 3 / 6.0
    return out


def weight_complement(s, t, radial):
    """1 - w(s, t) with full relative precision near the corner (w radial or tensor product).

    Parameters
    ----------
    s, t : ndarray, shape (n,) float64
        Local corner coordinates.
    radial : bool
        The radial weight of "vanishing" (:func:`weight_radial`) or the tensor-product weight of
        "characteristic" (:func:`weight_tensor`).

    Returns
    -------
    ndarray, shape (n,) float64

    Examples
    --------
    At (1e-10, 0), 1 - w = 36 (1e-10)^3 = 3.6e-29 to a relative error below 1e-14:

    >>> bool(abs(float(weight_complement(np.array([1e-10]), np.array([0.0]), radial=False)[0]) / 3.6e-29 - 1) < 1e-14)
    True
    """
    if radial:
        return bump_complement(np.hypot(s, t))
    cs, ct = bump_complement(s), bump_complement(t)
    return cs + ct - cs * ct


#: b on z = 6|x| in [i, i + 1): sum_j _COEF[i, j] (z - i)^j (module docstring)
_COEF = np.array([
    [1.0, 0.0, 0.0, -1.0 / 6.0],
    [5.0 / 6.0, -0.5, -0.5, 1.0 / 3.0],
    [1.0 / 6.0, -0.5, 0.5, -1.0 / 6.0],
    [0.0, 0.0, 0.0, 0.0],
])
_COEF_T = np.ascontiguousarray(_COEF.T)


def weight_tensor(s, t, derivatives=0):
    """w(s, t) = b(s) b(t) (bmz04 section 4.3) and its derivatives.

    Parameters
    ----------
    s, t : ndarray, shape (n,)
        Corner-local coordinates (corner at the origin).
    derivatives : int, 0, 1 or 2

    Returns
    -------
    tuple of ndarray, shape (n,)
        ``(w,)``; with 1 also ``w_s, w_t``; with 2 also ``w_ss, w_st, w_tt``.

    >>> [round(float(v[0]), 12) for v in weight_tensor(np.array([0.0]), np.array([1 / 6]))]     # b(0) b(1/6) = 5/6
    [0.833333333333]
    """
    bs = bump(s, derivatives)
    bt = bump(t, derivatives)
    out = [bs[0] * bt[0]]
    if derivatives >= 1:
        out += [bs[1] * bt[0], bs[0] * bt[1]]
    if derivatives >= 2:
        out += [bs[2] * bt[0], bs[1] * bt[1], bs[0] * bt[2]]
    return tuple(out)


def weight_radial(s, t, derivatives=0):
    """w(s, t) = b(sqrt(s^2 + t^2)) (bmz04 section 4.2) and its derivatives.

    Same conventions as :func:`weight_tensor`. At the origin the gradient and the Hessian are 0
    (b = 1 - 36 rho^3 there, so b'(rho)/rho = -108 rho -> 0 and b''(0) = 0).

    Parameters
    ----------
    s, t : ndarray, shape (n,) float64
    derivatives : int, optional
        0, 1 or 2.

    Returns
    -------
    tuple of ndarray, shape (n,)
        ``(w,)``; with 1 also ``w_s, w_t``; with 2 also ``w_ss, w_st, w_tt``.

    Examples
    --------
    >>> [float(v[0]) for v in weight_radial(np.array([0.3]), np.array([0.4]))]
    [0.0]
    """
    s = np.asarray(s, dtype=np.float64)
    t = np.asarray(t, dtype=np.float64)
    rho = np.hypot(s, t)
    bb = bump(rho, derivatives)
    out = [bb[0]]
    if derivatives >= 1:
        pos = rho > 0
        safe = np.where(pos, rho, 1.0)
        ns, nt = np.where(pos, s / safe, 0.0), np.where(pos, t / safe, 0.0)
        out += [bb[1] * ns, bb[1] * nt]
        if derivatives >= 2:
            q = np.where(pos, bb[1] / safe, 0.0)  # b'(rho)/rho, -> 0 at the origin
            out += [bb[2] * ns * ns + q * (1.0 - ns * ns), (bb[2] - q) * ns * nt, bb[2] * nt * nt + q * (1.0 - nt * nt)]
    return tuple(out)
