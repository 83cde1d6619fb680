"""Guaranteed fallback of the inverse characteristic map: Bezier-hull subdivision, then Newton.

Used for the points where the fast path (implicit-cubic location + Newton from a fitted first
guess, :mod:`ccproof.inverse.algorithm`) does not end inside the piece it started in, stalls, or
produces something that is not finite.

Why subdivision with Bezier hulls (and not Bezier clipping or interval Newton)
--------------------------------------------------------------------------------
* It needs no location at all: every candidate piece (layers n0 - 2 .. n0 + 2 around the first
  guess n0 of the layer, pieces P1 and P2) starts as one box [0,1]^2 with its Bezier net.
* Containment: a bicubic piece maps a box into the convex hull of the box's Bezier net (partition
  of unity, non-negative basis), so a box whose net's bounding box (widened by a tolerance that
  covers the float rounding of the nets) misses the target cannot contain the preimage and is
  dropped; the box that contains the preimage is never dropped.
* Termination: at most ``MAX_LEVEL`` halvings; each level keeps a bounded number of boxes per
  point (those whose image is within O(width) of the target: a few, more at piece corners).
* Verification: from level ``NEWTON_LEVEL`` on, Newton runs from the centre of every surviving
  box; an answer is *accepted* only when Newton has converged (last step < 1e-13), the solution
  lies in its piece's closed domain (within 1e-12) and the residual |P(s,t) - target| is within
  1e-15 of the target's scale. If no box of a point is accepted the subdivision simply goes on:
  at ``MAX_LEVEL`` = 52 the surviving boxes have the width of the float grid and their centre
  with the smallest residual is returned (still marked ``verified=False`` if no test passed).
  Bezier clipping converges faster but needs care near tangencies; interval Newton needs arb and
  is what the optional rigorous mode (:mod:`ccproof.inverse.certified`) does per point.
"""

from __future__ import annotations

import numpy as np

from ccproof.inverse.data import NMAX
from ccproof.inverse.kernels import patch_eval

#: first level at which Newton is tried from the surviving box centres
NEWTON_LEVEL = 8
#: last level: box width 2^-52
MAX_LEVEL = 52
#: layer offsets tried around the first guess
OFFSETS = (-2, -1, 0, 1, 2)


def _split_s(nets):
    """de Casteljau at s = 1/2 of nets (B, 4, 4, 2) -> (left, right)."""
    p0, p1, p2, p3 = nets[:, 0], nets[:, 1], nets[:, 2], nets[:, 3]
    p01, p12, p23 = (p0 + p1) * 0.5, (p1 + p2) * 0.5, (p2 + p3) * 0.5
    p012, p123 = (p01 + p12) * 0.5, (p12 + p23) * 0.5
    mid = (p012 + p123) * 0.5
    left = np.stack([p0, p01, p012, mid], axis=1)
    right = np.stack([mid, p123, p23, p3], axis=1)
    return left, right


def _split_t(nets):
    left, right = _split_s(nets.transpose(0, 2, 1, 3))
    return left.transpose(0, 2, 1, 3), right.transpose(0, 2, 1, 3)


def subdivision_inverse(D, a, b, n0):
    """Preimages of the points (a, b) (a >= b >= 0, not both 0) with first-guess layer ``n0``.

    Returns ``(n, p, s, t, verified)``: layer, piece (0: P1, 1: P2), local coordinates of the
    piece, and whether the answer passed the acceptance test (see module docstring).
    """
    npts = a.shape[0]
    n_out = np.zeros(npts, dtype=np.int64)
    p_out = np.zeros(npts, dtype=np.int64)
    s_out = np.full(npts, np.nan)
    t_out = np.full(npts, np.nan)
    best_res = np.full(npts, np.inf)
    verified = np.zeros(npts, dtype=bool)
    if npts == 0:
        return n_out, p_out, s_out, t_out, verified

    # one box per (point, layer offset, piece)
    pt, off, pc = (x.ravel() for x in np.meshgrid(np.arange(npts), OFFSETS, (0, 1), indexing="ij"))
    idx = NMAX - (n0[pt] + off)
    mant, expo = D.pow_mant[idx], D.pow_exp[idx]
    tx = np.ldexp(a[pt] * mant, expo)
    ty = np.ldexp(b[pt] * mant, expo)
    nets = D.bezier[pc].copy()
    s0 = np.zeros(pt.shape[0])
    t0 = np.zeros(pt.shape[0])
    width = 1.0
    scale = np.maximum(np.abs(tx), np.abs(ty))
    done = np.zeros(npts, dtype=bool)
    for level in range(MAX_LEVEL + 1):
        # prune: the target must lie in the bounding box of the box's net (widened)
        lo = nets.min(axis=(1, 2))
        hi = nets.max(axis=(1, 2))
        tol = 1e-13 * (1.0 + scale)
        keep = ((lo[:, 0] - tol <= tx) & (tx <= hi[:, 0] + tol)
                & (lo[:, 1] - tol <= ty) & (ty <= hi[:, 1] + tol) & ~done[pt])
        pt, off, pc, tx, ty, scale, nets, s0, t0 = (x[keep] for x in (pt, off, pc, tx, ty, scale, nets, s0, t0))
        if pt.shape[0] == 0:
            break
        if level >= NEWTON_LEVEL:
            sc, tc = s0 + width / 2, t0 + width / 2
            s, t, ok, res = _newton_polish(D, pc, sc, tc, tx, ty, scale)
            # candidate answers: accepted ones; at the last level also the centres themselves
            if level == MAX_LEVEL:
                cand = np.ones(pt.shape[0], dtype=bool)
                s = np.where(ok, s, sc)
                t = np.where(ok, t, tc)
                res = np.where(ok, res, _residual(D, pc, sc, tc, tx, ty))
            else:
                cand = ok
            for i in np.flatnonzero(cand):
                q = pt[i]
                better = res[i] < best_res[q]
                if ok[i] and not verified[q]:
                    better = True
                elif verified[q] and not ok[i]:
                    better = False
                if better:
                    best_res[q] = res[i]
                    n_out[q] = n0[q] + off[i]
                    p_out[q] = pc[i]
                    s_out[q] = s[i]
                    t_out[q] = t[i]
                    verified[q] = verified[q] or bool(ok[i])
            done = verified.copy()
            if done.all() or level == MAX_LEVEL:
                break
        # split every surviving box into four
        l, r = _split_s(nets)
        ll, lr = _split_t(l)
        rl, rr = _split_t(r)
        nets = np.concatenate([ll, lr, rl, rr])
        width *= 0.5
        s0 = np.concatenate([s0, s0, s0 + width, s0 + width])
        t0 = np.concatenate([t0, t0 + width, t0, t0 + width])
        pt, off, pc, tx, ty, scale = (np.concatenate([x] * 4) for x in (pt, off, pc, tx, ty, scale))
    return n_out, p_out, s_out, t_out, verified


def _residual(D, pc, s, t, tx, ty):
    x = np.empty_like(s)
    y = np.empty_like(s)
    for p in (0, 1):
        sel = pc == p
        if sel.any():
            x[sel], y[sel] = patch_eval(D.W[p], s[sel], t[sel])
    return np.maximum(np.abs(x - tx), np.abs(y - ty))


def _newton_polish(D, pc, s, t, tx, ty, scale, iterations=12):
    """Newton on the piece ``pc`` from (s, t); returns (s, t, accepted, residual)."""
    s = s.copy()
    t = t.copy()
    step = np.full(s.shape, np.inf)
    for _ in range(iterations):
        for p in (0, 1):
            sel = np.flatnonzero(pc == p)
            if sel.size == 0:
                continue
            x, y, xs, xt, ys, yt = patch_eval(D.W[p], s[sel], t[sel], True)
            fx = x - tx[sel]
            fy = y - ty[sel]
            with np.errstate(all="ignore"):
                det = xs * yt - xt * ys
                ds = (yt * fx - xt * fy) / det
                dt = (xs * fy - ys * fx) / det
            ds = np.where(np.isfinite(ds), ds, 0.0)
            dt = np.where(np.isfinite(dt), dt, 0.0)
            s[sel] -= np.clip(ds, -0.25, 0.25)
            t[sel] -= np.clip(dt, -0.25, 0.25)
            step[sel] = np.maximum(np.abs(ds), np.abs(dt))
    res = _residual(D, pc, s, t, tx, ty)
    inside = (s >= -1e-12) & (s <= 1 + 1e-12) & (t >= -1e-12) & (t <= 1 + 1e-12)
    ok = (step < 1e-13) & inside & (res <= 1e-15 * (1.0 + scale)) & np.isfinite(s) & np.isfinite(t)
    return s, t, ok, res
