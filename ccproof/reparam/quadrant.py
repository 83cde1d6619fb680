"""Quadrant maps F_i of bmz04 eq. (4): the vanishing-derivative map F^alpha (section 4.2) and the
inverse characteristic map Phi^-1 in the normalized frame (section 4.3, docs/readings.md R3, R6).

Both map the quadrant [0, inf)^2 onto itself, fix the origin, map each axis onto itself and commute
with the swap (s, t) -> (t, s). Each function returns the map, its Jacobian and (on request) its
second derivatives, all analytic (no finite differences).

Choice of the default exponent (section 4.2 leaves it open): near an extraordinary vertex of
valence k the natural parameterization behaves like |y|^beta with beta = log2(1/lam) (its
derivatives scale by 2 lam per halving, eq. (3)); after F^alpha the surface behaves like
|t|^(alpha beta). The paper's bound alpha > -log 2 / log lam is alpha beta > 1. We take
``alpha = 2 / beta = -2 log 2 / log lam`` (twice the bound) for every valence: the reparameterized
surface then behaves like |t|^2 at every extraordinary vertex, so its first derivatives vanish
linearly (the same rate for all valences) and its second derivatives stay bounded. This alpha is
>= 1.555 (k = 3) > 1, so the radial blend b(rho) rho^alpha + (1 - b(rho)) rho is increasing
(section 4.2's one-to-one argument needs alpha >= 1 or a check, see :func:`check_alpha`).
"""

from __future__ import annotations

import math

import numpy as np

from ccproof.errors import CCProofError, check_valence
from ccproof.valence import lam_from_c

__all__ = [
    "subdominant_lambda",
    "alpha_bound",
    "default_alpha",
    "check_alpha",
    "vanishing_map",
    "inverse_characteristic_map_derivatives",
]


def subdominant_lambda(k):
    """lam(k) = (5 + c + sqrt((1 + c)(9 + c))) / 16, c = cos(2 pi / k) (docs/readings.md R2), as a float
    (:func:`ccproof.valence.lam_from_c`; exactly 0.5 for k = 4).

    Parameters
    ----------
    k : int
        Valence, k >= 3.

    Returns
    -------
    float

    Examples
    --------
    >>> subdominant_lambda(4)
    0.5
    >>> import math
    >>> subdominant_lambda(6) == (5.5 + math.sqrt(1.5 * 9.5)) / 16        # c = 1/2
    True
    """
    k = check_valence(k)
    if k == 4:
        return 0.5
    return lam_from_c(math.cos(2 * math.pi / k))


def alpha_bound(k):
    """The lower bound -log 2 / log lam(k) of bmz04 section 4.2 (alpha must exceed it).

    Parameters
    ----------
    k : int
        Valence, k >= 3.

    Returns
    -------
    float

    Examples
    --------
    >>> round(alpha_bound(5), 6), alpha_bound(4)
    (1.159384, 1.0)
    """
    return -math.log(2.0) / math.log(subdominant_lambda(k))


def default_alpha(k):
    """Default exponent of F^alpha for valence k: twice the bound (module docstring).

    Parameters
    ----------
    k : int
        Valence, k >= 3.

    Returns
    -------
    float
        ``2 * alpha_bound(k)``.

    Examples
    --------
    >>> round(default_alpha(3), 4), round(default_alpha(13), 4)
    (1.5553, 3.0811)
    """
    return 2.0 * alpha_bound(k)


def _radial_increasing(alpha):
    """Whether g(rho) = b(rho) rho^alpha + (1 - b(rho)) rho is increasing on (0, 1/2] (dense check)."""
    from ccproof.reparam.weights import bump

    rho = np.linspace(0.0, 0.5, 20001)[1:]
    b, db = bump(rho, 1)
    dg = db * (rho**alpha - rho) + b * alpha * rho ** (alpha - 1.0) + (1.0 - b)
    return bool((dg > 0).all())


def check_alpha(alpha, k):
    """Return ``float(alpha)`` after checking alpha > -log 2 / log lam(k) (bmz04 section 4.2).

    For alpha < 1 (possible only for k = 3, whose bound is 0.778) the radial blend is also checked
    to be increasing on a dense grid (the one-to-one argument of section 4.2).

    Raises
    ------
    CCProofError
        alpha not a finite real, not above the bound, or (alpha < 1) a blend that is not one-to-one.

    Parameters
    ----------
    alpha : float
    k : int
        Valence, k >= 3.

    Returns
    -------
    float

    Examples
    --------
    >>> check_alpha(1.1, 5)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ccproof.errors.CCProofError: alpha = 1.1 is not above the bound -log 2 / log lam = 1.15938 of valence 5 ...
    """
    try:
        a = float(alpha)
    except (TypeError, ValueError):
        raise CCProofError(f"alpha must be a real number, got {alpha!r}") from None
    if not math.isfinite(a):
        raise CCProofError(f"alpha must be finite, got {alpha!r}")
    bound = alpha_bound(k)
    if not a > bound:
        raise CCProofError(
            f"alpha = {a!r} is not above the bound -log 2 / log lam = {bound:.6g} of valence {k} (bmz04 section "
            "4.2): the derivatives would not vanish at the extraordinary vertex")
    if a < 1.0 and not _radial_increasing(a):
        raise CCProofError(f"alpha = {a!r}: the radial blend of bmz04 section 4.2 is not one-to-one for this alpha")
    return a


def vanishing_map(s, t, alpha, derivatives=1):
    """F^alpha(t) = |t|^(alpha - 1) t (bmz04 section 4.2) with its derivatives.

    Parameters
    ----------
    s, t : ndarray, shape (n,)
        Points of the quadrant.
    alpha : float
    derivatives : int, 0, 1 or 2

    Returns
    -------
    F : ndarray, shape (n, 2)
    J : ndarray, shape (n, 2, 2)
        ``J[:, a, i] = dF_a / dt_i`` (with ``derivatives >= 1``; 0 at the origin for alpha > 1).
    H : ndarray, shape (n, 2, 2, 2)
        ``H[:, a, i, j] = d^2 F_a / dt_i dt_j`` (with 2; NaN at the origin when alpha < 2).

    >>> F, J = vanishing_map(np.array([3.0]), np.array([4.0]), 2.0)
    >>> np.round(F, 12).tolist(), np.round(J[0], 12).tolist()
    ([[15.0, 20.0]], [[6.8, 2.4], [2.4, 8.2]])
    """
    s = np.asarray(s, dtype=np.float64)
    t = np.asarray(t, dtype=np.float64)
    rho = np.hypot(s, t)
    pos = rho > 0
    safe = np.where(pos, rho, 1.0)
    p = np.where(pos, safe ** (alpha - 1.0), 0.0)
    F = np.stack([p * s, p * t], axis=1)
    out = [F]
    if derivatives >= 1:
        n = np.stack([np.where(pos, s / safe, 0.0), np.where(pos, t / safe, 0.0)], axis=1)
        eye = np.eye(2)
        J = p[:, None, None] * (eye + (alpha - 1.0) * n[:, :, None] * n[:, None, :])
        if alpha <= 1:
            J[~pos] = np.nan  # not differentiable at the origin
        out.append(J)
    if derivatives >= 2:
        q = (alpha - 1.0) * np.where(pos, safe ** (alpha - 2.0), 0.0 if alpha > 2 else np.nan)
        # H[a, i, j] = (alpha - 1) rho^(alpha - 2) (d_ai n_j + d_ij n_a + d_ja n_i + (alpha - 3) n_a n_i n_j)
        H = (np.einsum("ai,nj->naij", eye, n) + np.einsum("ij,na->naij", eye, n)
             + np.einsum("ja,ni->naij", eye, n)
             + (alpha - 3.0) * np.einsum("na,ni,nj->naij", n, n, n))
        H *= q[:, None, None, None]
        out.append(H)
    return tuple(out)


def _phi_hessian(k, r, s):
    """Second derivatives of Phi (normalized frame) at points (r, s) != 0 of the quadrant.

    Returns H of shape (n, 2, 2, 2): ``H[:, c, i, j] = d^2 Phi_c / dy_i dy_j``, from the power
    basis of the layer-0 pieces P1, P2 and the scaling Phi(2^e y0) = lam^-e Phi(y0), as in
    :mod:`ccproof.inverse.forward` (swap symmetry for s > r).
    """
    from ccproof.inverse.data import NMAX, valence_data

    D = valence_data(k)
    sw = s > r
    a = np.where(sw, s, r)
    b = np.where(sw, r, s)
    m, e = np.frexp(a)
    b0 = np.ldexp(b, -e)
    p2 = b0 >= 0.5
    sl = 2.0 * m - 1.0
    tl = 2.0 * b0 - p2
    C = D.power[p2.astype(np.int64)]  # (n, 2, 4, 4): [comp, s power, t power]
    one = np.ones_like(sl)
    zero = np.zeros_like(sl)
    S0 = np.stack([one, sl, sl * sl, sl**3], axis=1)
    S1 = np.stack([zero, one, 2 * sl, 3 * sl * sl], axis=1)
    S2 = np.stack([zero, zero, 2 * one, 6 * sl], axis=1)
    T0 = np.stack([one, tl, tl * tl, tl**3], axis=1)
    T1 = np.stack([zero, one, 2 * tl, 3 * tl * tl], axis=1)
    T2 = np.stack([zero, zero, 2 * one, 6 * tl], axis=1)
    pss = np.einsum("ncij,ni,nj->nc", C, S2, T0)
    pst = np.einsum("ncij,ni,nj->nc", C, S1, T1)
    ptt = np.einsum("ncij,ni,nj->nc", C, S0, T2)
    # d/dy = 2 * 2^-e d/dlocal, Phi = lam^-e P: d^2/dy^2 = 4 lam^-e 4^-e d^2/dlocal^2
    idx = np.clip(NMAX - e, 0, 2 * NMAX)
    with np.errstate(over="ignore", under="ignore", invalid="ignore"):
        f = 4.0 * D.pow_2lam[idx] * np.ldexp(1.0, -e)
    H0 = np.empty((a.shape[0], 2, 2, 2))
    H0[:, :, 0, 0] = pss * f[:, None]
    H0[:, :, 0, 1] = H0[:, :, 1, 0] = pst * f[:, None]
    H0[:, :, 1, 1] = ptt * f[:, None]
    Hs = H0[:, ::-1, ::-1, ::-1]
    return np.where(sw[:, None, None, None], Hs, H0)


def inverse_characteristic_map_derivatives(k, s, t, derivatives=1):
    """F(t) = Phi^-1(t) for valence k in the normalized frame (bmz04 section 4.3) with derivatives.

    Phi^-1 comes from :func:`ccproof.inverse.inverse_characteristic_map` (Algorithm 1 with a
    guaranteed fallback); its Jacobian is ``(D Phi(y))^-1`` at ``y = Phi^-1(t)`` with the Jacobian of
    the bicubic pieces (:func:`ccproof.inverse.characteristic_map`), and its second derivatives
    ``-J^-1 D^2 Phi[J^-1 ., J^-1 .]``.

    Parameters
    ----------
    k : int
    s, t : ndarray, shape (n,)
        Points of the quadrant.
    derivatives : int, 0, 1 or 2

    Returns
    -------
    F : ndarray, shape (n, 2)
    J : ndarray, shape (n, 2, 2)
        ``J[:, a, i] = dF_a / dt_i`` (NaN at the origin, where Phi^-1 is not differentiable).
    H : ndarray, shape (n, 2, 2, 2)
        With ``derivatives == 2`` (NaN at the origin).

    >>> F, J = inverse_characteristic_map_derivatives(4, np.array([0.3]), np.array([0.2]))   # k = 4: identity
    >>> np.round(F, 14).tolist(), (np.round(J[0], 14) + 0.0).tolist()
    ([[0.3, 0.2]], [[1.0, 0.0], [0.0, 1.0]])
    """
    from ccproof.inverse import characteristic_map, inverse_characteristic_map

    k = check_valence(k)
    s = np.asarray(s, dtype=np.float64)
    t = np.asarray(t, dtype=np.float64)
    r, q = inverse_characteristic_map(k, s, t)
    F = np.stack([r, q], axis=1)
    out = [F]
    if derivatives >= 1:
        _, _, JP = characteristic_map(k, r, q, jacobian=True)
        det = JP[:, 0, 0] * JP[:, 1, 1] - JP[:, 0, 1] * JP[:, 1, 0]
        J = np.empty_like(JP)
        J[:, 0, 0] = JP[:, 1, 1] / det
        J[:, 1, 1] = JP[:, 0, 0] / det
        J[:, 0, 1] = -JP[:, 0, 1] / det
        J[:, 1, 0] = -JP[:, 1, 0] / det
        out.append(J)
    if derivatives >= 2:
        zero = (r == 0) & (q == 0)
        H = np.full((s.shape[0], 2, 2, 2), np.nan)
        ok = ~zero
        if ok.any():
            HP = _phi_hessian(k, r[ok], q[ok])
            Ji = J[ok]
            H[ok] = -np.einsum("nak,nkbc,nbi,ncj->naij", Ji, HP, Ji, Ji)
        out.append(H)
    return tuple(out)
