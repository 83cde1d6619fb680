"""Optional compiled evaluation kernel (numba), the same arithmetic as the numpy path point by point.

Imported only when numba is installed; :mod:`ccproof.evaluate.surface` falls back to numpy otherwise.
"""

from __future__ import annotations

import math

import numpy as np

try:
    import numba
except ImportError:  # pragma: no cover - optional dependency
    numba = None

_REGULAR, _CORNER, _SPLIT = 0, 1, 2


def _basis(x, B, D, D2):
    t = 1.0 - x
    x2 = x * x
    x3 = x2 * x
    B[0] = t * t * t / 6
    B[1] = (3 * x3 - 6 * x2 + 4) / 6
    B[2] = (-3 * x3 + 3 * x2 + 3 * x + 1) / 6
    B[3] = x3 / 6
    D[0] = -0.5 * t * t
    D[1] = 1.5 * x2 - 2 * x
    D[2] = -1.5 * x2 + x + 0.5
    D[3] = 0.5 * x2
    D2[0] = t
    D2[1] = 3 * x - 2
    D2[2] = -3 * x + 1
    D2[3] = x


def _evaluate_points(f, u, v, d, refused, vkind, vchild, vu0, vv0, vh, vpatch, vcold, hot_layers, vcu, vcv, vnmax,
                     split_depth, nets, pu0, pv0, ph, P, Pu, Pv, Puu, Puv, Pvv):
    """Fill P (n, 3) and, for d >= 1, Pu, Pv, for d >= 2, Puu, Puv, Pvv (each (n, 3)).

    Returns -1, or the index of the first point whose face is out of range or ``refused`` (a hole)
    or whose (u, v) is outside [0, 1]^2 or NaN; the caller then names it (the outputs from that
    point on are not written).
    """
    n = f.shape[0]
    m = refused.shape[0]
    Bs = np.empty(4)
    Ds = np.empty(4)
    D2s = np.empty(4)
    Bt = np.empty(4)
    Dt = np.empty(4)
    D2t = np.empty(4)
    T0 = np.empty((4, 3))
    T1 = np.empty((4, 3))
    T2 = np.empty((4, 3))
    for k in range(n):
        vf = f[k]
        uu = u[k]
        ww = v[k]
        if vf < 0 or vf >= m or not (uu >= 0.0 and uu <= 1.0 and ww >= 0.0 and ww <= 1.0) or refused[vf]:
            return k
        kind = vkind[vf]
        for _ in range(split_depth):
            if kind != _SPLIT:
                break
            half = vh[vf] * 0.5
            q = 0
            if uu >= vu0[vf] + half:
                q += 1
            if ww >= vv0[vf] + half:
                q += 2
            vf = vchild[vf, q]
            kind = vkind[vf]
        p = vpatch[vf]
        if kind == _CORNER:
            U0 = vu0[vf]
            V0 = vv0[vf]
            H = vh[vf]
            du = ((U0 + H) - uu if vcu[vf] else uu - U0) / H
            dv = ((V0 + H) - ww if vcv[vf] else ww - V0) / H
            mx = max(du, dv)
            nmax = vnmax[vf]
            if mx > 0:
                e = math.frexp(mx)[1]
                lay = min(max(-e, 0), nmax)
            else:
                lay = nmax
            du = math.ldexp(du, lay)
            dv = math.ldexp(dv, lay)
            a = du >= 0.5
            b = dv >= 0.5
            if a and not b:
                code = 0
            elif a and b:
                code = 1
            elif b:
                code = 2
            else:
                code = 1
            if lay >= hot_layers:
                p = vcold[vf]
            p += 3 * lay + code
        h = ph[p]
        s = min(max((uu - pu0[p]) / h, 0.0), 1.0)
        t = min(max((ww - pv0[p]) / h, 0.0), 1.0)
        g = 1.0 / h
        _basis(s, Bs, Ds, D2s)
        _basis(t, Bt, Dt, D2t)
        for i in range(4):
            for c in range(3):
                x0 = 0.0
                x1 = 0.0
                x2 = 0.0
                for j in range(4):
                    w = nets[p, i + 4 * j, c]
                    x0 += Bt[j] * w
                    if d >= 1:
                        x1 += Dt[j] * w
                    if d >= 2:
                        x2 += D2t[j] * w
                T0[i, c] = x0
                T1[i, c] = x1
                T2[i, c] = x2
        for c in range(3):
            a0 = 0.0
            for i in range(4):
                a0 += Bs[i] * T0[i, c]
            P[k, c] = nets[p, 16, c] + a0
        if d >= 1:
            for c in range(3):
                a1 = 0.0
                a2 = 0.0
                for i in range(4):
                    a1 += Ds[i] * T0[i, c]
                    a2 += Bs[i] * T1[i, c]
                Pu[k, c] = a1 * g
                Pv[k, c] = a2 * g
        if d >= 2:
            g2 = g * g
            for c in range(3):
                a3 = 0.0
                a4 = 0.0
                a5 = 0.0
                for i in range(4):
                    a3 += D2s[i] * T0[i, c]
                    a4 += Ds[i] * T1[i, c]
                    a5 += Bs[i] * T2[i, c]
                Puu[k, c] = a3 * g2
                Puv[k, c] = a4 * g2
                Pvv[k, c] = a5 * g2
    return -1


if numba is not None:
    _basis = numba.njit(cache=True, nogil=True)(_basis)
    evaluate_points = numba.njit(cache=True, nogil=True)(_evaluate_points)
else:  # pragma: no cover
    evaluate_points = None
