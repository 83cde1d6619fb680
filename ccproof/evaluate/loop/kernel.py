"""Compiled Loop evaluation (numba): the descent through local splits, the box-spline patches and Stam's
layers point by point, with the arithmetic of :mod:`ccproof.evaluate.loop.surface`'s numpy path (the
same tables; results equal to rounding, checked by tests/evaluate/test_loop.py).

Tables (built by :meth:`ccproof.evaluate.loop.surface.LoopSurface`): the node arrays (kind, rotation,
reference, children), per regular patch its polynomial coefficients (15 monomials x 3), per corner piece
its ring's offset in one flat array of control points and its configuration, per configuration its layers
as polynomial coefficients (``(K D[n, j])^T``: N ring points x 15 monomials, K the box spline's
coefficient matrix; regular patches' coefficients likewise 3 x 15) and its limit mask, in flat arrays.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from ccproof.evaluate.loop.box_spline import MONOMIALS

__all__ = ["evaluate_points"]

_MP = np.array([p for p, _ in MONOMIALS], dtype=np.int64)
_MQ = np.array([q for _, q in MONOMIALS], dtype=np.int64)
#: corner patches' coefficients kept per kernel call (a power of 2; 384 bytes each), on calls of at least
#: _CACHE_MIN points
_CACHE_SLOTS = 16384
_CACHE_MIN = 256
#: (Jacobian, offset) per rotation (surface.ROTATIONS), flattened: j00 j01 j10 j11 o0 o1
_ROT = np.array([[1.0, 0.0, 0.0, 1.0, 0.0, 0.0], [0.0, 1.0, -1.0, -1.0, 0.0, 1.0],
                 [-1.0, -1.0, 1.0, 0.0, 1.0, 0.0]])


@numba.njit(cache=True)
def _monomials(a, b, mono, mp, mq, pa, pb, nrows):
    """mono[0..5, m]: u^p v^q and its d/du, d/dv, d2/du2, d2/dudv, d2/dv2 at (a, b), the first nrows rows
    (pa, pb: work (5,))."""
    pa[0] = 1.0
    pb[0] = 1.0
    for i in range(1, 5):
        pa[i] = pa[i - 1] * a
        pb[i] = pb[i - 1] * b
    for m in range(15):
        p, q = mp[m], mq[m]
        mono[0, m] = pa[p] * pb[q]
        if nrows > 1:
            mono[1, m] = p * pa[p - 1] * pb[q] if p >= 1 else 0.0
            mono[2, m] = q * pa[p] * pb[q - 1] if q >= 1 else 0.0
        if nrows > 3:
            mono[3, m] = p * (p - 1) * pa[p - 2] * pb[q] if p >= 2 else 0.0
            mono[4, m] = p * q * pa[p - 1] * pb[q - 1] if p >= 1 and q >= 1 else 0.0
            mono[5, m] = q * (q - 1) * pa[p] * pb[q - 2] if q >= 2 else 0.0


@numba.njit(cache=True)
def _apply(mono, coef, nrows, out):
    """out[r, c] = sum_m mono[r, m] coef[c, m] for the first nrows derivative rows."""
    for r in range(nrows):
        x0 = x1 = x2 = 0.0
        for m in range(15):
            w = mono[r, m]
            x0 += w * coef[0, m]
            x1 += w * coef[1, m]
            x2 += w * coef[2, m]
        out[r, 0], out[r, 1], out[r, 2] = x0, x1, x2


@numba.njit(cache=True)
def _corner_local(g, p, a, b, nrows, corner, scratch, out):
    """Local value and derivatives at corner piece p of configuration g (Stam's layers) into out (6, 3);
    returns the derivatives' scale. ``corner``: the tables (piece offsets, per configuration N, layer count,
    layer and mask offsets, layers, masks, control points); ``scratch``: work arrays and the hashed cache
    of the coefficients of (piece, layer, child) for the other points of the call on the same patch
    (``ckey`` of size 1: none)."""
    piece_offs, gN, gnl, glay, gmask, layers, masks, coords = corner
    mono, work, ckey, clim, ccoef = scratch
    mp, mq = _MP, _MQ
    piece_off = piece_offs[p]
    N, nl = gN[g], gnl[g]
    s = a + b
    if s > 0.0:
        _, e = math.frexp(s)
        n = max(-e, 0)
    else:
        n = nl
    deep = n >= nl
    if deep:
        n = nl - 1
    U, V = math.ldexp(a, n), math.ldexp(b, n)
    if deep:
        U, V = 0.5, 0.0
    if U >= 0.5:
        j, x, y, sg = 0, 2 * U - 1, 2 * V, 1.0
    elif V >= 0.5:
        j, x, y, sg = 1, 2 * U, 2 * V - 1, 1.0
    else:
        j, x, y, sg = 2, 1 - 2 * U, 1 - 2 * V, -1.0
    lim, coef, pa, pb = work
    slot = 0
    if ckey.size > 1:
        key = p * 4096 + n * 4 + j
        slot = ((key * 2654435761) >> 16) & (ckey.size - 1)  # the middle bits: p enters them
        lim, coef = clim[slot], ccoef[slot]
        if ckey[slot] == key:
            _monomials(x, y, mono, mp, mq, pa, pb, nrows)
            _apply(mono, coef, nrows, out)
            for c in range(3):
                out[0, c] = lim[c] if deep else out[0, c] + lim[c]
            return sg * math.ldexp(1.0, n + 1)
        ckey[slot] = key
    base = glay[g] + (n * 3 + j) * N * 15
    x0 = x1 = x2 = 0.0
    mo = gmask[g]
    for k in range(N):
        w = masks[mo + k]
        o = piece_off + 3 * k
        x0 += w * coords[o]
        x1 += w * coords[o + 1]
        x2 += w * coords[o + 2]
    lim[0], lim[1], lim[2] = x0, x1, x2
    coef[:] = 0.0
    for k in range(N):  # coef[c, m] += KD[n, j, k, m] C[k, c]: 45 independent sums, m contiguous
        o = piece_off + 3 * k
        c0, c1, c2 = coords[o], coords[o + 1], coords[o + 2]
        lo = base + k * 15
        for m in range(15):
            w = layers[lo + m]
            coef[0, m] += w * c0
            coef[1, m] += w * c1
            coef[2, m] += w * c2
    _monomials(x, y, mono, mp, mq, pa, pb, nrows)
    _apply(mono, coef, nrows, out)
    for c in range(3):
        out[0, c] = lim[c] if deep else out[0, c] + lim[c]
    return sg * math.ldexp(1.0, n + 1)


@numba.njit(cache=True)
def evaluate_points(face, u, v, nrows, tables, out):
    """out[r, i, c] for points i: rows 0 (P), 1-2 (Pu, Pv), 3-5 (Puu, Puv, Pvv), the first nrows rows.

    ``tables``: (root, kind, rot, ref, children, gid, reg_coef) and the corner tables (piece offsets, gN, gnl,
    glay, gmask, layers, masks, coords), as :meth:`ccproof.evaluate.loop.surface.LoopSurface` builds them.
    """
    root, kind, rot, ref, children, gid, reg_coef = tables[:7]
    corner = tables[7:]
    mp, mq, R = _MP, _MQ, _ROT
    mono = np.empty((6, 15))
    loc = np.empty((6, 3))
    work = (np.zeros(3), np.zeros((3, 15)), np.empty(5), np.empty(5))
    slots = _CACHE_SLOTS if face.size >= _CACHE_MIN else 1
    ckey = np.full(slots, -1, dtype=np.int64)
    clim = np.empty((slots, 3))
    ccoef = np.empty((slots, 3, 15))
    scratch = (mono, work, ckey, clim, ccoef)
    for i in range(face.size):
        node = root[face[i]]
        a, b = u[i], v[i]
        t00, t01, t10, t11 = 1.0, 0.0, 0.0, 1.0
        while True:
            r = rot[node]
            if r != 0:
                j00, j01, j10, j11, o0, o1 = R[r, 0], R[r, 1], R[r, 2], R[r, 3], R[r, 4], R[r, 5]
                a, b = j00 * a + j01 * b + o0, j10 * a + j11 * b + o1
                t00, t01, t10, t11 = (j00 * t00 + j01 * t10, j00 * t01 + j01 * t11,
                                      j10 * t00 + j11 * t10, j10 * t01 + j11 * t11)
            if kind[node] != 2:
                break
            if a >= 0.5:
                c, a, b, f = 1, 2 * a - 1, 2 * b, 2.0
            elif b >= 0.5:
                c, a, b, f = 2, 2 * a, 2 * b - 1, 2.0
            elif a + b <= 0.5:
                c, a, b, f = 0, 2 * a, 2 * b, 2.0
            else:
                c, a, b, f = 3, 1 - 2 * a, 1 - 2 * b, -2.0
            t00, t01, t10, t11 = f * t00, f * t01, f * t10, f * t11
            node = children[node, c]
        scale = 1.0
        if kind[node] == 0:
            _monomials(a, b, mono, mp, mq, work[2], work[3], nrows)
            _apply(mono, reg_coef[ref[node]], nrows, loc)
        else:
            p = ref[node]
            scale = _corner_local(gid[node], p, a, b, nrows, corner, scratch, loc)
        for c in range(3):
            out[0, i, c] = loc[0, c]
            if nrows > 1:
                gu, gv = scale * loc[1, c], scale * loc[2, c]
                out[1, i, c] = t00 * gu + t10 * gv
                out[2, i, c] = t01 * gu + t11 * gv
            if nrows > 3:
                s2 = scale * scale
                huu, huv, hvv = s2 * loc[3, c], s2 * loc[4, c], s2 * loc[5, c]
                # H = T^T H' T
                out[3, i, c] = t00 * t00 * huu + 2 * t00 * t10 * huv + t10 * t10 * hvv
                out[4, i, c] = t00 * t01 * huu + (t00 * t11 + t10 * t01) * huv + t10 * t11 * hvv
                out[5, i, c] = t01 * t01 * huu + 2 * t01 * t11 * huv + t11 * t11 * hvv
