"""The local step of the closest points (:mod:`ccproof.evaluate.closest`): a projected, backtracked Newton
descent of ``E(u, v) = |P(u, v) - X|^2 / 2`` in ``[0, 1]^2`` from a start parameter, point by point.

Gradient ``(<P_u, R>, <P_v, R>)``, Hessian ``J^T J + <P_ww, R>`` (``R = P - X``); variables at a bound
with the gradient pushing outwards are frozen; an indefinite Hessian is replaced by ``J^T J`` plus a
Levenberg term; every step is backtracked (Armijo) so ``E`` never increases; at most :data:`MAX_ITER`
steps of at most :data:`MAX_HALVINGS` halvings. On the evaluator's own surfaces the descent runs
compiled with the same formulas in the same order (bit-identical, tests/evaluate/test_newton_compiled.py).

Near an extraordinary vertex the natural parameterization is singular at the corner (derivatives tend to 0
for valence 3 and to infinity for valence >= 5); there the clipping at the face's corner and the backtracking
still give a monotone descent, and the evaluator's self-similar layers keep the derivatives exact down to
``2^-60`` of the corner, so the descent converges (linearly in the last layers at worst) to the corner or to
the nearby minimum.
"""

from __future__ import annotations

import numpy as np

from ccproof.errors import CCProofError
from ccproof.evaluate._parallel import in_blocks, threads_for

__all__ = ["newton_descent", "row_dot", "unit_normal", "MAX_ITER", "MAX_HALVINGS"]

#: Newton steps at most per descent
MAX_ITER = 60
#: step halvings at most per Newton step (then the descent stops: no decrease at that scale)
MAX_HALVINGS = 20


def row_dot(a, b):
    """Row-wise dot products of (n, 3) arrays, summed left to right (the compiled descent's order)."""
    return a[:, 0] * b[:, 0] + a[:, 1] * b[:, 1] + a[:, 2] * b[:, 2]


def unit_normal(Pu, Pv):
    N = np.cross(Pu, Pv)
    nn = np.linalg.norm(N, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        N = N / nn[:, None]
    return N


def newton_descent(surface, X, face, u, v, max_iter=MAX_ITER, *, backend=None, threads=None):
    """Projected, backtracked Newton descent of ``|P(face, u, v) - X|^2 / 2`` in ``[0, 1]^2``.

    Parameters
    ----------
    surface : LimitSurface
    X : ndarray, shape (n, 3)
    face : ndarray of int, shape (n,)
    u, v : ndarray, shape (n,)
        Starting parameters (clipped to [0, 1]).
    max_iter : int
        Newton steps at most per point.
    backend : {None, "numpy", "numba"}
        As in :meth:`~ccproof.evaluate.LimitSurface.evaluate`: ``None`` runs the compiled descent
        (the same formulas point by point, in numba) where the surface is evaluated by the compiled
        kernel in its natural parameterization, else this numpy descent over the whole batch.
    threads : int, optional
        Threads of the compiled descent (contiguous blocks, identical results); default all cores
        for at least 2^13 points.

    Returns
    -------
    u, v : ndarray, shape (n,)
    E : ndarray, shape (n,)
        ``|P - X|^2 / 2`` at the result (never larger than at the start).

    Notes
    -----
    docs/closest.md "Float path: method" (the local descent of every candidate cell).

    Examples
    --------
    Above the centre of the cube's top face (face 1) the descent ends at (1/2, 1/2), where the limit
    point is (0, 0, 68/81), at distance 94/81 from (0, 0, 2):

    >>> from ccproof.evaluate import limit_surface
    >>> from ccproof.mesh.examples import cube
    >>> u, v, E = newton_descent(limit_surface(cube()), [[0.0, 0.0, 2.0]], [1], [0.3], [0.3])
    >>> u.round(12).tolist(), v.round(12).tolist(), round(float(2 * E[0] * 81**2), 9)
    ([0.5], [0.5], 8836.0)
    """
    X = np.asarray(X, dtype=np.float64)
    face = np.asarray(face, dtype=np.int64)
    u = np.clip(np.asarray(u, dtype=np.float64), 0.0, 1.0).copy()
    v = np.clip(np.asarray(v, dtype=np.float64), 0.0, 1.0).copy()
    n = u.size
    kernel = surface._newton_kernel(backend) if hasattr(surface, "_newton_kernel") else None
    if kernel is not None:
        return _newton_compiled(surface, kernel, X, face, u, v, max_iter, threads)
    r = surface.evaluate(face, u, v, 2)
    R = r["P"] - X
    E = 0.5 * row_dot(R, R)
    alpha = np.ones(n)
    active = np.arange(n)
    # round-off of E = |P - X|^2 / 2: P is accurate to about eps |P|, so E to about eps |P| |R|
    xs = np.abs(X).max(axis=1) if n else np.zeros(0)
    slack = 1e-13 * E + 4e-16 * np.sqrt(2.0 * E) * (xs + np.sqrt(2.0 * E))
    cur = {k: r[k] for k in ("Pu", "Pv", "Puu", "Puv", "Pvv")}
    for _ in range(max_iter):
        if active.size == 0:
            break
        a = active
        ua, va = u[a], v[a]
        gu, gv, guu, gvv, du, dv, pg = _descent_direction(cur, a, R[a], ua, va)
        al = alpha[a]
        _line_search(surface, X, face, a, (ua, va, gu, gv, pg), (du, dv, al), (u, v, E, R, cur), slack)
        step = np.maximum(np.abs(u[a] - ua), np.abs(v[a] - va))
        # converged: no move, or a full step smaller than round-off of the parameter
        # or a step below 1e-12 of the distance to the nearest face corner (converged to round-off:
        # E is quadratic there), or a projected gradient at the round-off level of <P_w, R>
        ucorner = np.maximum(np.minimum(u[a], 1.0 - u[a]), np.minimum(v[a], 1.0 - v[a]))
        nR = np.sqrt(2.0 * E[a])
        keep = (step > 0) & ~((al >= 1.0) & (step <= 4e-16)) & ~(step <= 1e-12 * ucorner)
        keep &= ~(pg <= 1e-15 * nR * np.sqrt(guu + gvv))
        alpha[a] = np.minimum(1.0, al * 2.0)
        active = a[keep]
    return u, v, E


def _descent_direction(cur, a, Ra, ua, va):
    """:func:`newton_descent`'s step at the active points ``a`` (residuals ``Ra``, parameters ``ua``, ``va``):
    (gu, gv, guu, gvv, du, dv, projected gradient norm)."""
    Pu, Pv = cur["Pu"][a], cur["Pv"][a]
    gu, gv = row_dot(Pu, Ra), row_dot(Pv, Ra)
    guu, guv, gvv = row_dot(Pu, Pu), row_dot(Pu, Pv), row_dot(Pv, Pv)
    huu = guu + row_dot(cur["Puu"][a], Ra)
    huv = guv + row_dot(cur["Puv"][a], Ra)
    hvv = gvv + row_dot(cur["Pvv"][a], Ra)
    fu = ~(((ua <= 0.0) & (gu > 0)) | ((ua >= 1.0) & (gu < 0)))
    fv = ~(((va <= 0.0) & (gv > 0)) | ((va >= 1.0) & (gv < 0)))
    # Newton where the (free part of the) Hessian is positive definite, else Gauss-Newton + LM
    tr = np.abs(guu) + np.abs(gvv) + 1e-300
    pd = (huu > 0) & (hvv > 0) & (huu * hvv - huv * huv > 1e-14 * tr * tr)
    pd1u, pd1v = huu > 1e-14 * tr, hvv > 1e-14 * tr
    lm = 1e-6 * tr
    Auu = np.where(pd | (fu & ~fv & pd1u), huu, guu + lm)
    Avv = np.where(pd | (fv & ~fu & pd1v), hvv, gvv + lm)
    Auv = np.where(pd, huv, guv)
    both = fu & fv
    det = Auu * Avv - Auv * Auv
    with np.errstate(invalid="ignore", divide="ignore"):
        du = np.where(both, -(Avv * gu - Auv * gv) / det, np.where(fu, -gu / Auu, 0.0))
        dv = np.where(both, -(Auu * gv - Auv * gu) / det, np.where(fv, -gv / Avv, 0.0))
    bad = ~(np.isfinite(du) & np.isfinite(dv))
    du[bad], dv[bad] = -gu[bad] / tr[bad], -gv[bad] / tr[bad]
    pg = np.hypot(np.where(fu, gu, 0.0), np.where(fv, gv, 0.0))
    return gu, gv, guu, gvv, du, dv, pg


def _line_search(surface, X, face, a, start, step, state, slack):
    """:func:`newton_descent`'s backtracking at the active points ``a``: accept the first step with an Armijo decrease;
    give up below 2^-MAX_HALVINGS. ``start`` = (ua, va, gu, gv, pg) at the start, ``step`` = (du, dv, al)
    (``al`` halved in place), ``state`` = (u, v, E, R, cur) updated in place where a step is accepted."""
    ua, va, gu, gv, pg = start
    du, dv, al = step
    u, v, E, R, cur = state
    done = np.zeros(a.size, dtype=bool)
    for _ls in range(MAX_HALVINGS + 1):
        idx = np.flatnonzero(~done)
        if idx.size == 0:
            break
        ai = a[idx]
        nu = np.clip(ua[idx] + al[idx] * du[idx], 0.0, 1.0)
        nv = np.clip(va[idx] + al[idx] * dv[idx], 0.0, 1.0)
        moved = (nu != ua[idx]) | (nv != va[idx])
        rt = surface.evaluate(face[ai], nu, nv, 2)
        Rt = rt["P"] - X[ai]
        Et = 0.5 * row_dot(Rt, Rt)
        pred = gu[idx] * (nu - ua[idx]) + gv[idx] * (nv - va[idx])
        # Armijo decrease; or, where E is flat to round-off (next to the minimum), a smaller
        # projected gradient at no larger E beyond its round-off (slack, fixed at the start)
        gtu, gtv = row_dot(rt["Pu"], Rt), row_dot(rt["Pv"], Rt)
        ftu = ~(((nu <= 0.0) & (gtu > 0)) | ((nu >= 1.0) & (gtu < 0)))
        ftv = ~(((nv <= 0.0) & (gtv > 0)) | ((nv >= 1.0) & (gtv < 0)))
        pg_t = np.hypot(np.where(ftu, gtu, 0.0), np.where(ftv, gtv, 0.0))
        ok = moved & (
            (Et <= E[ai] + 1e-4 * np.minimum(pred, 0.0))
            | ((Et <= E[ai] + slack[ai]) & (pg_t < 0.5 * pg[idx]))
        )
        acc = idx[ok]
        aa = a[acc]
        u[aa], v[aa] = nu[ok], nv[ok]
        E[aa], R[aa] = Et[ok], Rt[ok]
        for k in cur:
            cur[k][aa] = rt[k][ok]
        done[acc] = True
        still = idx[~ok]
        stop = ~moved[~ok] | (al[still] <= 2.0**-MAX_HALVINGS)
        done[still[stop]] = True
        al[still[~stop]] *= 0.5


def _newton_compiled(surface, kernel, X, face, u, v, max_iter, threads):
    """:func:`newton_descent` by the compiled descent (points checked first: the kernel trusts its input)."""
    face, u, v = surface._check(face, u, v)
    X = np.ascontiguousarray(X.reshape(-1, 3) if X.size else np.zeros((0, 3)))
    if X.shape[0] != u.size:
        raise CCProofError(f"X must have one row per point, got {X.shape[0]} rows for {u.size} points")
    n = u.size
    E = np.empty(n)
    table = surface._kernel_table()

    def block(lo, hi):
        kernel(X[lo:hi], face[lo:hi], u[lo:hi], v[lo:hi], max_iter, MAX_HALVINGS, table, E[lo:hi])

    in_blocks(block, n, threads_for(threads, n * 16), 2048)  # a descent costs some 10 to 30 evaluations
    return u, v, E
