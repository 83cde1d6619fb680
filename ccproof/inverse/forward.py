"""The characteristic map Phi of valence k on the quadrant, vectorized (bmz04 section 4.3).

Phi is evaluated through its layer structure (docs/readings.md R4): for y = (r, s) in [0, inf)^2 with
max(r, s) = m 2^e (m in [1/2, 1)), y0 = 2^-e y lies in layer 0 = [0,1]^2 minus [0,1/2)^2, and

    Phi(y) = lam^-e Phi(y0),

the extension of bmz04 (Phi(u, v) = lam^-m Phi(u/2^m, v/2^m)) for points outside the face. By the
symmetry Phi(s, r) = swap(Phi(r, s)) only P1 and P2 are evaluated (for r >= s), in the power
basis (one 4 x 4 matrix product per block, then Horner). Scaling by 2^-e is exact; lam^n is a
tabulated correctly-rounded mantissa times an exact power of two, so there is no overflow or
underflow before the true result over- or underflows.
"""

from __future__ import annotations

from typing import Literal, overload

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ccproof.errors import check_valence
from ccproof.inverse.data import NMAX, valence_data
from ccproof.inverse.kernels import SAFE_HI, SAFE_LO, as_points, chunks, patch_eval, patch_eval_jac


@overload
def characteristic_map(k: int, r: ArrayLike, s: ArrayLike, jacobian: Literal[False] = False
                       ) -> tuple[NDArray[np.float64], NDArray[np.float64]]: ...
@overload
def characteristic_map(k: int, r: ArrayLike, s: ArrayLike, jacobian: Literal[True]
                       ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]: ...
def characteristic_map(k: int, r: ArrayLike, s: ArrayLike, jacobian: bool = False
                       ) -> tuple[NDArray[np.float64], ...]:
    """Phi(r, s) for valence k, vectorized over arrays r, s >= 0 (broadcast together).

    Parameters
    ----------
    k : int
        Valence >= 3.
    r, s : array_like
        Face parameters (u, v) of the quadrant [0, inf)^2; the face is [0, 1]^2.
    jacobian : bool
        Also return the Jacobian matrix d(x, y)/d(r, s), shape ``r.shape + (2, 2)``.

    Returns
    -------
    x, y : ndarray
        Phi(r, s), shape of the broadcast inputs; ``(x, y, J)`` when ``jacobian``.

    >>> x, y = characteristic_map(4, [0.3, 2.0], [0.7, 0.25])     # k = 4: the identity
    >>> np.round(x, 12).tolist(), np.round(y, 12).tolist()
    ([0.3, 2.0], [0.7, 0.25])
    >>> x, y = characteristic_map(5, [1.0, 0.5, 0.0], [0.0, 0.0, 0.0])
    >>> np.round(x, 12).tolist(), (np.round(y, 12) + 0.0).tolist()   # Phi(1,0) = (1,0), Phi(1/2,0) = (lam,0)
    ([1.0, 0.549988354518, 0.0], [0.0, 0.0, 0.0])
    """
    k = check_valence(k)
    ra, sa, shape = as_points(r, s, "parameter")
    D = valence_data(k)
    n = ra.shape[0]
    X = np.empty(n)
    Y = np.empty(n)
    J = np.empty((n, 2, 2)) if jacobian else None
    for sl in chunks(n):
        _forward_chunk(D, ra[sl], sa[sl], X[sl], Y[sl], None if J is None else J[sl])
    if J is not None:
        return X.reshape(shape), Y.reshape(shape), J.reshape(shape + (2, 2))
    return X.reshape(shape), Y.reshape(shape)


def _forward_chunk(D, r, s, X, Y, J):
    sw = s > r
    a = np.where(sw, s, r)
    b = np.where(sw, r, s)
    m, e = np.frexp(a)
    idx = NMAX - e
    fast = a.size == 0 or (a.min() >= SAFE_LO and a.max() <= SAFE_HI)
    b0 = b * D.pow2[idx] if fast else np.ldexp(b, -e)   # exact either way
    p2 = b0 >= 0.5
    sl = 2.0 * m - 1.0
    tl = 2.0 * b0 - p2
    px = np.empty_like(a)
    py = np.empty_like(a)
    if J is not None:
        jac = np.empty((4, a.shape[0]))
    for p, sel in ((0, np.flatnonzero(~p2)), (1, np.flatnonzero(p2))):
        if sel.size == 0:
            continue
        if J is None:
            out = patch_eval(D.W[p], sl[sel], tl[sel])
        else:
            out = patch_eval_jac(D.C6[p], sl[sel], tl[sel])
        px[sel] = out[0]
        py[sel] = out[1]
        if J is not None:
            for i in range(4):
                jac[i, sel] = out[2 + i]
    zero = a == 0
    if fast:
        f = D.pow_lam[idx]
        px *= f
        py *= f
    else:
        mant = D.pow_mant[idx]
        expo = D.pow_exp[idx]
        with np.errstate(over="ignore", under="ignore"):
            px = np.ldexp(px * mant, expo)
            py = np.ldexp(py * mant, expo)
    px[zero] = 0.0
    py[zero] = 0.0
    X[:] = np.where(sw, py, px)
    Y[:] = np.where(sw, px, py)
    if J is not None:
        # d/dy = lam^-e * 2 * 2^-e * d/d(local) = 2 (2 lam)^-e d/d(local)
        with np.errstate(over="ignore", under="ignore", invalid="ignore"):
            jac *= 2.0 * D.pow_2lam[idx]
        jac[:, zero] = np.nan  # Phi is not differentiable at the extraordinary vertex
        xs, xt, ys, yt = jac
        # for swapped points Phi = swap o Phi_0 o swap: J = [[yt, ys], [xt, xs]]
        J[:, 0, 0] = np.where(sw, yt, xs)
        J[:, 0, 1] = np.where(sw, ys, xt)
        J[:, 1, 0] = np.where(sw, xt, ys)
        J[:, 1, 1] = np.where(sw, xs, yt)
