"""Inverse of the characteristic map: bmz04 Algorithm 1, vectorized, with a guaranteed fallback.

For t = (x, y) in the quadrant (by the symmetry Phi(v, u) = swap(Phi(u, v)) we work with
x >= y and swap back at the end):

1. **Layer, first guess** (R11): n0 = floor(log_lam(max(x, y) / A)), so that t0 = lam^-n0 t has
   max(t0) in (lam A, A]. A is the geometric middle of [xmax, xmin / lam^2] where x ranges over
   the inner boundary Gamma of layer 0; since xmax / xmin < 1/lam^2 for every k (checked), the
   layer of t0 is then -1, 0 or +1.
2. **Layer and piece by the implicit cubics** (:mod:`ccproof.inverse.implicit`): with g_Gamma the
   implicit polynomial of Gamma = Phi(u = 1/2, 0 <= v <= 1/2) (edge s = 0 of P1), t0 is inside
   layer 1 when g_Gamma(t0) is on the origin side, and outside layer 0 when g_Gamma(lam t0) is on
   the outer side: the *scaling relation* Phi(y/2) = lam Phi(y) turns the outer boundary test into
   the inner one, so a single cubic (and its sign convention) serves every layer. The piece (P1
   or P2) is the side of the separator C = Phi(1/2 <= u <= 1, v = 1/2) (edge t = 1 of P1). All
   five values (Gamma at t0 and lam t0, C at t0 scaled by 1/lam, 1, lam) are cubics in t0,
   evaluated together by nested Horner, point by point (no BLAS: a point's bits do not depend on
   its batch).
3. **Newton** on P_j(s, t) = lam^-n t from a first guess: a least-squares polynomial of total
   degree 5 in (x, y) fitted to the local coordinates of P_j (error 1e-5 .. 2e-4), instead of the
   paper's (u, v) (which needs 4 to 6 steps). Two Newton steps, then more only for the points
   whose last step exceeds 1e-8 (at most 6).
4. **Acceptance**: the last Newton step is below 1e-8 (quadratic convergence then puts the error
   near 1e-16), the solution is finite and lies in the piece's closed domain up to 1e-7 in local
   coordinates. The last tolerance is safe: the pieces join C^2 (the characteristic map is a
   bicubic spline away from the extraordinary vertex, across layers too), so the polynomial
   extension of a piece differs from Phi by O(d^3) at distance d outside its domain.
5. **Fallback** for every point not accepted: :mod:`ccproof.inverse.fallback` (Bezier-hull
   subdivision, then Newton; always terminates, answer verified by residual).

The result is (r, s) in the face's parameter: [0,1]^2 for t in Phi([0,1]^2) and the quadrant
extension (bmz04: Phi(u, v) = lam^-m Phi(u/2^m, v/2^m)) elsewhere; y = 2^-n y0 with y0 the
layer-0 preimage, an exact scaling.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal, overload

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ccproof.errors import CCProofError, check_valence
from ccproof.inverse.data import FIT_DEGREE, NMAX, valence_data
from ccproof.inverse.kernels import CHUNK, SAFE_HI, SAFE_LO, approx_log, as_points, patch_eval_jac, polynomial_rows

#: Newton steps done for every point before the first convergence check
NEWTON_STEPS = 2
#: further steps (only for the points not yet converged)
EXTRA_STEPS = 6
#: a point is accepted when its last Newton step is below this (local coordinates)
STEP_TOL = 1e-8
#: ... and its solution lies within this of the piece's domain [0,1]^2 (local coordinates)
DOMAIN_TOL = 1e-7

PATCH_NAMES = ("P1", "P2", "P3")


@dataclass
class InverseResult:
    """Preimages and diagnostics of :func:`inverse_characteristic_map` (bmz04 Algorithm 1; docs/inverse.md).

    Parameters
    ----------
    r, s : ndarray, shape of the input points, float64
        The preimage (face parameter).
    layer : ndarray of int64
        n with y = 2^-n y0, y0 in layer 0 (n < 0 outside the face; docs/readings.md R4).
    patch : ndarray of int64
        0, 1, 2 for P1, P2, P3 (-1 at the origin).
    fallback : ndarray of bool
        True where the subdivision fallback produced the answer.
    verified : ndarray of bool
        False only where even the fallback's acceptance test failed (never observed; counted as a
        failure by the benchmark).
    stats : dict
        Counts of ``points``, ``fallback`` and ``failures`` (and ``uncertified`` with ``rigorous=True``).
    boxes : list of CertifiedPreimage or None
        With ``rigorous=True``, one :class:`~ccproof.inverse.certified.CertifiedPreimage` per point
        (flattened order).

    Examples
    --------
    For k = 4 Phi is the identity: (0.75, 0.25) lies in P1 of layer 0, (0.3, 0.1) = (0.6, 0.2)/2 in
    P1 of layer 1 and (0.75, 0.75) in P2:

    >>> res = inverse_characteristic_map(4, [0.75, 0.3, 0.75], [0.25, 0.1, 0.75], full_output=True)
    >>> res.layer.tolist(), res.patch.tolist(), res.stats["fallback"]
    ([0, 1, 0], [0, 0, 1], 0)
    """

    r: np.ndarray
    s: np.ndarray
    layer: np.ndarray
    patch: np.ndarray
    fallback: np.ndarray
    verified: np.ndarray
    stats: dict = field(default_factory=dict)
    boxes: list | None = None


@overload
def inverse_characteristic_map(k: int, u: ArrayLike, v: ArrayLike, *, domain: Literal["quadrant", "face"] = ...,
                               full_output: Literal[False] = False, rigorous: Literal[False] = False, prec: int = ...
                               ) -> tuple[NDArray[np.float64], NDArray[np.float64]]: ...
@overload
def inverse_characteristic_map(k: int, u: ArrayLike, v: ArrayLike, *, domain: Literal["quadrant", "face"] = ...,
                               full_output: bool = ..., rigorous: bool = ..., prec: int = ...
                               ) -> tuple[NDArray[np.float64], NDArray[np.float64]] | InverseResult: ...
def inverse_characteristic_map(k: int, u: ArrayLike, v: ArrayLike, *, domain: Literal["quadrant", "face"] = "quadrant",
                               full_output: bool = False, rigorous: bool = False, prec: int = 128
                               ) -> tuple[NDArray[np.float64], NDArray[np.float64]] | InverseResult:
    """Phi^-1(u, v) for valence k, vectorized: bmz04 Algorithm 1 with a guaranteed fallback.

    Parameters
    ----------
    k : int
        Valence >= 3.
    u, v : array_like
        Points of the quadrant [0, inf)^2 in the image of the characteristic map (broadcast).
    domain : {"quadrant", "face"}
        ``"quadrant"``: Phi extended to [0, inf)^2 by the scaling relation (bmz04 section 4.3), onto
        the quadrant. ``"face"``: only Phi([0,1]^2) is allowed; points outside it raise
        :class:`~ccproof.errors.CCProofError`.
    full_output : bool
        Return an :class:`InverseResult` (layer, patch, fallback flags, statistics).
    rigorous : bool
        Also certify every preimage with an interval Newton (Krawczyk) test in arb at ``prec``
        bits (slow: about 10 ms per point); see :func:`ccproof.inverse.certified.certify_preimage`.
        Implies ``full_output``; the boxes are in ``result.boxes`` and
        ``result.stats["uncertified"]`` counts the points whose test failed (0 in all our runs).

    Returns
    -------
    r, s : ndarray
        Face parameters with Phi(r, s) = (u, v) (or an :class:`InverseResult`).

    >>> r, s = inverse_characteristic_map(5, [1.0, 0.0, 0.3], [0.0, 0.0, 0.3])
    >>> np.round(r, 12).tolist(), np.round(s, 12).tolist()   # Phi(1,0) = (1,0); 0 is fixed
    ([1.0, 0.0, 0.306134955665], [0.0, 0.0, 0.306134955665])
    >>> [round(float(x), 12) for x in inverse_characteristic_map(4, 0.25, 0.75)]      # k = 4: the identity
    [0.25, 0.75]
    """
    k = check_valence(k)
    if domain not in ("quadrant", "face"):
        raise CCProofError(f"unknown domain {domain!r}; use 'quadrant' or 'face'")
    x, y, shape = as_points(u, v, "image")
    D = valence_data(k)
    npts = x.shape[0]
    R = np.empty(npts)
    S = np.empty(npts)
    layer = np.empty(npts, dtype=np.int64)
    patch = np.empty(npts, dtype=np.int64)
    fb = np.zeros(npts, dtype=bool)
    ver = np.ones(npts, dtype=bool)
    pending = []
    for i in range(0, npts, CHUNK):
        sl = slice(i, min(i + CHUNK, npts))
        bad = _inverse_chunk(D, x[sl], y[sl], R[sl], S[sl], layer[sl], patch[sl])
        if bad is not None:
            pending.append(bad + i)
    if pending:
        idx = np.concatenate(pending)
        _run_fallback(D, x, y, idx, R, S, layer, patch, ver)
        fb[idx] = True
    if domain == "face":
        _check_face(x, y, R, S)
    stats = {"points": npts, "fallback": int(fb.sum()), "failures": int((~ver).sum())}
    boxes = None
    if rigorous:
        from ccproof.inverse.certified import certify_preimage

        boxes = [certify_preimage(k, x[i], y[i], R[i], S[i], prec) for i in range(npts)]
        stats["uncertified"] = sum(not b.certified for b in boxes)
    if full_output or rigorous:
        return InverseResult(R.reshape(shape), S.reshape(shape), layer.reshape(shape),
                             patch.reshape(shape), fb.reshape(shape), ver.reshape(shape), stats, boxes)
    return R.reshape(shape), S.reshape(shape)


def _check_face(x, y, R, S):
    eps = 4 * np.finfo(float).eps
    out = (R > 1 + eps) | (S > 1 + eps)
    if out.any():
        i = int(np.flatnonzero(out)[0])
        raise CCProofError(
            f"point ({float(x[i])!r}, {float(y[i])!r}) is outside the image Phi([0,1]^2) of the face (its "
            f"preimage in the quadrant is ({float(R[i])!r}, {float(S[i])!r})); the quadrant domain (the "
            "default; ccproof invert --domain quadrant) gives the extension")
    np.minimum(R, 1.0, out=R)
    np.minimum(S, 1.0, out=S)


def _first_layer(D, a, fast=False):
    """Step 1: n0 = floor(log_lam(a / A)) (an approximate log is enough: the band has room)."""
    n0 = np.floor((approx_log(a) - D.log_a) * D.inv_log_lam)
    if not fast:
        np.clip(n0, -NMAX + 4, NMAX - 4, out=n0)
    return n0.astype(np.int64)


def _scale_lam(D, n, a, b, fast):
    """(a, b) * lam^n for integer arrays n (tables; ldexp on the slow path)."""
    idx = NMAX + n
    if fast:
        f = D.pow_lam[idx]
        return a * f, b * f
    mant = D.pow_mant[idx]
    expo = D.pow_exp[idx]
    return np.ldexp(a * mant, expo), np.ldexp(b * mant, expo)


def locate(D, a, b, fast=True):
    """Steps 1-2 of bmz04 Algorithm 1 for points a >= b >= 0 with a > 0: the layer and the piece.

    docs/readings.md R11; the layer and piece tests use the implicit boundaries of docs/inverse.md.

    Parameters
    ----------
    D : ValenceData
        :func:`ccproof.inverse.data.valence_data` of the valence.
    a, b : ndarray, shape (n,) float64
        Points of the half-sector a >= b >= 0, a > 0.
    fast : bool, optional
        The fast path: powers of lam as doubles, no clipping of the first-guess layer to the exact
        range of the power tables (the caller keeps the points in range).

    Returns
    -------
    n : ndarray, shape (n,) int64
        The layer.
    p : ndarray, shape (n,) int64
        The piece (0: P1, 1: P2).
    a1, b1 : ndarray, shape (n,) float64
        lam^-n (a, b), the point scaled into layer 0.
    n0 : ndarray, shape (n,) int64
        The first-guess layer.

    Examples
    --------
    For k = 4 (Phi the identity, lam = 1/2):

    >>> import numpy as np
    >>> from ccproof.inverse.data import valence_data
    >>> n, p, a1, b1, n0 = locate(valence_data(4), np.array([0.75, 0.3]), np.array([0.25, 0.1]))
    >>> n.tolist(), p.tolist(), a1.tolist(), b1.tolist()
    ([0, 1], [0, 0], [0.75, 0.6], [0.25, 0.2])
    """
    n0 = _first_layer(D, a, fast)
    a0, b0 = _scale_lam(D, -n0, a, b, fast)
    V = polynomial_rows(D.G, a0, b0, 3)
    inner = V[0] * D.gamma_sign < 0          # t0 inside Gamma: one layer deeper
    outer = (V[1] * D.gamma_sign > 0) & ~inner  # lam t0 outside Gamma: one layer out
    sep = np.where(inner, V[2], np.where(outer, V[4], V[3])) * D.sep_sign
    p = (sep < 0).astype(np.int64)
    f = np.where(inner, 1.0 / D.lam, np.where(outer, D.lam, 1.0))
    return n0 + inner - outer, p, a0 * f, b0 * f, n0


def _inverse_chunk(D, x, y, R, S, layer, patch):
    sw = y > x
    a = np.where(sw, y, x)
    b = np.where(sw, x, y)
    zero = a == 0
    if zero.any():
        a = np.where(zero, 1.0, a)
    fast = a.size == 0 or (a.min() >= SAFE_LO and a.max() <= SAFE_HI)
    n, p, a1, b1, _ = locate(D, a, b, fast)
    s_loc = np.empty_like(a)
    t_loc = np.empty_like(a)
    ok = np.zeros(a.shape[0], dtype=bool)
    for q in (0, 1):
        sel = np.flatnonzero(p == q)
        if sel.size == 0:
            continue
        X, Y = a1[sel], b1[sel]
        s0, t0 = polynomial_rows(D.fit[q], X, Y, FIT_DEGREE)
        s, t, good = newton(D.C6[q], s0, t0, X, Y)
        s_loc[sel] = s
        t_loc[sel] = t
        ok[sel] = good
    # on the axis the preimage is on the axis (Phi maps each axis onto itself, injectively)
    t_loc[b == 0] = 0.0
    # local -> layer-0 face coordinates -> face coordinates (exact scaling by 2^-n)
    u0 = (s_loc + 1.0) * 0.5
    v0 = (t_loc + p) * 0.5
    if fast:
        f = D.pow2[NMAX - n]
        r = u0 * f
        s = v0 * f
    else:
        r = np.ldexp(u0, -n)
        s = np.ldexp(v0, -n)
    np.maximum(s, 0.0, out=s)  # (r >= 0 always: u0 >= 1/2 - DOMAIN_TOL / 2)
    ok |= zero
    r[zero] = 0.0
    s[zero] = 0.0
    R[:] = np.where(sw, s, r)
    S[:] = np.where(sw, r, s)
    layer[:] = np.where(zero, 0, n)
    patch[:] = np.where(zero, -1, np.where(sw & (p == 0), 2, p))
    if ok.all():
        return None
    return np.flatnonzero(~ok)


def newton(Cp, s, t, X, Y):
    """Newton for P(s, t) = (X, Y) on one piece; returns (s, t, accepted).

    Step 3 of bmz04 Algorithm 1 (docs/readings.md R11): Newton's method on the bicubic piece from the
    fitted first guess.

    Parameters
    ----------
    Cp : ndarray, shape (6, 16) float64
        ``ValenceData.C6[p]``: power-basis coefficients of x, y and their derivatives on piece p.
    s, t : ndarray, shape (n,) float64
        Starting local coordinates.
    X, Y : ndarray, shape (n,) float64
        Target points in layer 0.

    Returns
    -------
    s, t : ndarray, shape (n,) float64
    accepted : ndarray, shape (n,) bool
        Whether the iteration converged (else the caller falls back to subdivision).

    Examples
    --------
    For k = 4, P1 is u = (1 + s)/2, v = t/2, so (0.75, 0.25) has local coordinates (0.5, 0.5):

    >>> import numpy as np
    >>> from ccproof.inverse.data import valence_data
    >>> s, t, ok = newton(valence_data(4).C6[0], np.array([0.3]), np.array([0.7]), np.array([0.75]),
    ...                   np.array([0.25]))
    >>> np.round(s, 12).tolist(), np.round(t, 12).tolist(), ok.tolist()
    ([0.5], [0.5], [True])
    """
    step = np.full(s.shape, np.inf)
    for i in range(NEWTON_STEPS):
        s, t, step = _newton_step(Cp, s, t, X, Y, i == NEWTON_STEPS - 1)
    todo = np.flatnonzero(~(step <= STEP_TOL))
    if todo.size:
        s, t = s.copy(), t.copy()
    for _ in range(EXTRA_STEPS):
        if todo.size == 0:
            break
        s2, t2, st2 = _newton_step(Cp, s[todo], t[todo], X[todo], Y[todo])
        s[todo] = s2
        t[todo] = t2
        step[todo] = st2
        todo = todo[~(st2 <= STEP_TOL)]
    good = ((step <= STEP_TOL) & (s >= -DOMAIN_TOL) & (s <= 1 + DOMAIN_TOL)
            & (t >= -DOMAIN_TOL) & (t <= 1 + DOMAIN_TOL))
    return s, t, good


def _newton_step(Cp, s, t, X, Y, want_step=True):
    x, y, xs, xt, ys, yt = patch_eval_jac(Cp, s, t)
    x -= X
    y -= Y
    with np.errstate(all="ignore"):
        det = xs * yt
        det -= xt * ys
        ds = yt * x
        ds -= xt * y
        ds /= det
        dt = xs * y
        dt -= ys * x
        dt /= det
    s = s - ds
    t = t - dt
    if not want_step:
        return s, t, None
    np.abs(ds, out=ds)
    np.abs(dt, out=dt)
    return s, t, np.maximum(ds, dt, out=ds)


def _run_fallback(D, x, y, idx, R, S, layer, patch, ver):
    from ccproof.inverse.fallback import subdivision_inverse

    xs, ys = x[idx], y[idx]
    sw = ys > xs
    a = np.where(sw, ys, xs)
    b = np.where(sw, xs, ys)
    n0 = _first_layer(D, a)
    n, p, s_loc, t_loc, verified = subdivision_inverse(D, a, b, n0)
    t_loc[(b == 0) & (p == 0)] = 0.0
    r = np.maximum(np.ldexp((s_loc + 1.0) * 0.5, -n), 0.0)
    s = np.maximum(np.ldexp((t_loc + p) * 0.5, -n), 0.0)
    R[idx] = np.where(sw, s, r)
    S[idx] = np.where(sw, r, s)
    layer[idx] = n
    patch[idx] = np.where(sw & (p == 0), 2, p)
    ver[idx] = verified
