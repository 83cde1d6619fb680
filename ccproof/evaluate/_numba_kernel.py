"""Compiled evaluation kernel (numba), the same arithmetic as the numpy path point by point, and the
compiled Newton descent of the closest points (:func:`ccproof.evaluate.newton.newton_descent`, point by point).

The numba backend (chosen by :mod:`ccproof.evaluate.backend`; without numba its kernels are None).
"""

from __future__ import annotations

import math

import numpy as np

try:
    import numba
except ImportError:  # pragma: no cover - optional dependency
    numba = None

from ccproof.evaluate.patch_table import COMPOSED_LAYERS, KIND_CORNER, KIND_SPLIT

#: corner nets (layers beyond the precomputed ones) kept per kernel call: slots (a power of 2, 408 bytes each)
_CACHE_SLOTS = 16384
#: calls on fewer points compute every corner net (no cache to allocate)
_CACHE_MIN = 256
#: multiplier spreading the patch keys over the slots (Knuth's multiplicative hash)
_HASH = 2654435761


def point_blocks(kernel, table, f, u, v, d, outs):
    """``(block, [])`` for :func:`ccproof.evaluate.backend.evaluation_blocks`: ``block(lo, hi)`` calls ``kernel``
    (:func:`evaluate_points`) on the points lo:hi of ``table`` (a :class:`~ccproof.evaluate.patch_table.PatchTable`)
    and the six outputs ``outs`` (None where absent)."""
    dummy = np.empty((0, 3))
    arrs = [dummy if a is None else a for a in outs]

    def block(lo, hi):
        return kernel(f[lo:hi], u[lo:hi], v[lo:hi], d, table, tuple(a[lo:hi] if a.shape[0] else a for a in arrs))
    return block, []


def _basis(x):
    """Cubic B-spline basis at x, its first and second derivatives: twelve scalars (4 each; the formulas of
    :func:`ccproof.evaluate.bspline.bspline_basis`)."""
    t = 1.0 - x
    x2 = x * x
    x3 = x2 * x
    return (t * t * t / 6, (3 * x3 - 6 * x2 + 4) / 6, (-3 * x3 + 3 * x2 + 3 * x + 1) / 6, x3 / 6,
            -0.5 * t * t, 1.5 * x2 - 2 * x, -1.5 * x2 + x + 0.5, 0.5 * x2,
            t, 3 * x - 2, -3 * x + 1, x)


def _sum4(a0, a1, a2, a3, w0, w1, w2, w3):
    """``sum_j a_j w_j`` from 0.0, left to right (the order of the numpy path's contractions)."""
    return (((0.0 + a0 * w0) + a1 * w1) + a2 * w2) + a3 * w3


def _bicubic(net, p, s, t, g, d, k, out):
    """Row k of P (and of the derivatives up to order d; ``out`` = (P, Pu, Pv, Puu, Puv, Pvv)) from the bicubic
    net ``net[p]`` (17 x 3, row 16 the origin) at (s, t), derivatives scaled by g per order; in registers: the
    columns ``T_r[i] = sum_j B_r(t)_j net[i + 4 j]`` then ``sum_i B(s)_i T_r[i]``, each sum from 0.0 left to
    right."""
    P, Pu, Pv, Puu, Puv, Pvv = out
    s0, s1, s2, s3, s4, s5, s6, s7, s8, s9, s10, s11 = _basis(s)
    t0, t1, t2, t3, t4, t5, t6, t7, t8, t9, t10, t11 = _basis(t)
    g2 = g * g
    for c in range(3):
        w0, w1, w2, w3 = net[p, 0, c], net[p, 4, c], net[p, 8, c], net[p, 12, c]
        x0 = _sum4(t0, t1, t2, t3, w0, w1, w2, w3)
        w4, w5, w6, w7 = net[p, 1, c], net[p, 5, c], net[p, 9, c], net[p, 13, c]
        y0 = _sum4(t0, t1, t2, t3, w4, w5, w6, w7)
        w8, w9, w10, w11 = net[p, 2, c], net[p, 6, c], net[p, 10, c], net[p, 14, c]
        z0 = _sum4(t0, t1, t2, t3, w8, w9, w10, w11)
        w12, w13, w14, w15 = net[p, 3, c], net[p, 7, c], net[p, 11, c], net[p, 15, c]
        q0 = _sum4(t0, t1, t2, t3, w12, w13, w14, w15)
        P[k, c] = net[p, 16, c] + _sum4(s0, s1, s2, s3, x0, y0, z0, q0)
        if d >= 1:
            x1 = _sum4(t4, t5, t6, t7, w0, w1, w2, w3)
            y1 = _sum4(t4, t5, t6, t7, w4, w5, w6, w7)
            z1 = _sum4(t4, t5, t6, t7, w8, w9, w10, w11)
            q1 = _sum4(t4, t5, t6, t7, w12, w13, w14, w15)
            Pu[k, c] = _sum4(s4, s5, s6, s7, x0, y0, z0, q0) * g
            Pv[k, c] = _sum4(s0, s1, s2, s3, x1, y1, z1, q1) * g
            if d >= 2:
                x2 = _sum4(t8, t9, t10, t11, w0, w1, w2, w3)
                y2 = _sum4(t8, t9, t10, t11, w4, w5, w6, w7)
                z2 = _sum4(t8, t9, t10, t11, w8, w9, w10, w11)
                q2 = _sum4(t8, t9, t10, t11, w12, w13, w14, w15)
                Puu[k, c] = _sum4(s8, s9, s10, s11, x0, y0, z0, q0) * g2
                Puv[k, c] = _sum4(s4, s5, s6, s7, x1, y1, z1, q1) * g2
                Pvv[k, c] = _sum4(s0, s1, s2, s3, x2, y2, z2, q2) * g2


def _regular_net(T, job, vf, W, s):
    """Net ``W[s]`` (17 x 3) of the regular leaf ``vf`` of ``job``: row i ``sum_j op[j, i] (X[ring[j]] -
    X[ring[0]])`` over the ring points j = 1, 2, ... in order from 0.0, row 16 that sum plus ``X[ring[0]]``."""
    N = T.vn[vf]
    o = T.vop_start[vf]
    r0_ = T.job_ring[job]
    i0 = T.rings[r0_]
    for i in range(17):
        W[s, i, 0] = 0.0
        W[s, i, 1] = 0.0
        W[s, i, 2] = 0.0
    for j in range(1, N):
        ij = T.rings[r0_ + j]
        r0 = T.points[ij, 0] - T.points[i0, 0]
        r1 = T.points[ij, 1] - T.points[i0, 1]
        r2 = T.points[ij, 2] - T.points[i0, 2]
        r = o + 17 * j
        for i in range(17):
            w = T.vop[r + i]
            W[s, i, 0] += w * r0
            W[s, i, 1] += w * r1
            W[s, i, 2] += w * r2
    for c in range(3):
        W[s, 16, c] = W[s, 16, c] + T.points[i0, c]
    return W


def _regular_lookup(T, job, vf, lm, cache, tags, W):
    """``(array, row)`` holding the net of the regular leaf ``vf`` of ``job``: the kept nets, the call's
    cache (computed into it when missing; keys after the corner nets'), or ``W`` (no cache)."""
    p = T.job_net[job] + T.leaf[vf]
    if T.nets.shape[0] > 0:
        return T.nets, p
    ns = cache.shape[0]
    if ns == 0:
        return _regular_net(T, job, vf, W, 0), 0
    key = 3 * lm * T.n_corner + p
    s = (key * _HASH) & (ns - 1)
    if tags[s] != key:
        _regular_net(T, job, vf, cache, s)
        tags[s] = key
    return cache, s


def _composed_net(T, r0_, N, o, b, W, s):
    """Net ``W[s]`` of a corner face in a composed layer: ``sum_j M[j] (X[ring[j]] - X[ring[0]])`` (M the
    (N, 16) operator at ``vop[b:]``), row 16 the limit point (its weights at ``vop[o:]``), the sums over j =
    1, 2, ... in order from 0.0; ``r0_`` the job's ring in ``rings``."""
    i0 = T.rings[r0_]
    e0 = 0.0
    e1 = 0.0
    e2 = 0.0
    for i in range(16):
        W[s, i, 0] = 0.0
        W[s, i, 1] = 0.0
        W[s, i, 2] = 0.0
    for j in range(1, N):
        ij = T.rings[r0_ + j]
        r0 = T.points[ij, 0] - T.points[i0, 0]
        r1 = T.points[ij, 1] - T.points[i0, 1]
        r2 = T.points[ij, 2] - T.points[i0, 2]
        r = b + 16 * j
        for i in range(16):
            w = T.vop[r + i]
            W[s, i, 0] += w * r0
            W[s, i, 1] += w * r1
            W[s, i, 2] += w * r2
        e0 += T.vop[o + j] * r0
        e1 += T.vop[o + j] * r1
        e2 += T.vop[o + j] * r2
    W[s, 16, 0] = e0 + T.points[i0, 0]
    W[s, 16, 1] = e1 + T.points[i0, 1]
    W[s, 16, 2] = e2 + T.points[i0, 2]
    return W


def _corner_net(T, job, vf, cfg, lay, code, ci, W, s, rc):
    """Net ``W[s]`` (17 x 3, row 16 the limit point) of patch ``code`` of layer ``lay`` of corner face
    ``vf`` of ``job``: below :data:`COMPOSED_LAYERS` the composed operator's sums over the ring points; deeper,
    its ring relative to the corner vertex (``Q @ (X[ring] - X[ring[0]])``, summed over
    j = 1, 2, ... in order), then ``L[lay, code] @ ring`` summed over the ring points j = 1, 2, ... in order
    (row 0 of the relative ring is 0), the 16 entries side by side."""
    Nc = T.op_size[cfg]
    m = Nc - 1
    N = T.vn[vf]
    q = T.vop_start[vf]
    r0_ = T.job_ring[job]
    i0 = T.rings[r0_]
    o = q + N * m  # the limit point's weights
    e0 = 0.0
    e1 = 0.0
    e2 = 0.0
    if lay < COMPOSED_LAYERS:  # one product: the composed operator (N x 16) of this layer and code
        return _composed_net(T, r0_, N, o, o + N + (3 * lay + code) * N * 16, W, s)
    kept = T.cor_ring[ci] if T.cor_ring.shape[0] > 0 else -1
    if kept >= 0:  # the kept ring (the same sums); the limit point's sum alone
        for r in range(m):
            rc[r, 0] = T.ring[kept + r, 0]
            rc[r, 1] = T.ring[kept + r, 1]
            rc[r, 2] = T.ring[kept + r, 2]
        for j in range(1, N):
            ij = T.rings[r0_ + j]
            e0 += T.vop[o + j] * (T.points[ij, 0] - T.points[i0, 0])
            e1 += T.vop[o + j] * (T.points[ij, 1] - T.points[i0, 1])
            e2 += T.vop[o + j] * (T.points[ij, 2] - T.points[i0, 2])
    else:
        for r in range(m):  # rc: the caller's scratch, (at least m, 3)
            rc[r, 0] = 0.0
            rc[r, 1] = 0.0
            rc[r, 2] = 0.0
    for j in range(1, N if kept < 0 else 1):
        ij = T.rings[r0_ + j]
        r0 = T.points[ij, 0] - T.points[i0, 0]
        r1 = T.points[ij, 1] - T.points[i0, 1]
        r2 = T.points[ij, 2] - T.points[i0, 2]
        b = q + m * j
        for r in range(m):
            w = T.vop[b + r]
            rc[r, 0] += w * r0
            rc[r, 1] += w * r1
            rc[r, 2] += w * r2
        e0 += T.vop[o + j] * r0
        e1 += T.vop[o + j] * r1
        e2 += T.vop[o + j] * r2
    o = T.op_start[cfg] + (3 * lay + code) * 16 * Nc
    for i in range(16):
        W[s, i, 0] = 0.0
        W[s, i, 1] = 0.0
        W[s, i, 2] = 0.0
    for j in range(1, Nc):
        r0 = rc[j - 1, 0]
        r1 = rc[j - 1, 1]
        r2 = rc[j - 1, 2]
        r = o + 16 * j
        for i in range(16):
            w = T.ops[r + i]
            W[s, i, 0] += w * r0
            W[s, i, 1] += w * r1
            W[s, i, 2] += w * r2
    W[s, 16, 0] = e0 + T.points[i0, 0]
    W[s, 16, 1] = e1 + T.points[i0, 1]
    W[s, 16, 2] = e2 + T.points[i0, 2]
    return W


def _evaluate_points(f, u, v, d, T, out):
    """Fill ``out`` = (P, Pu, Pv, Puu, Puv, Pvv): P (n, 3) and, for d >= 1, Pu, Pv, for d >= 2, Puu, Puv, Pvv
    (each (n, 3)) from the patch table ``T`` (:class:`ccproof.evaluate.patch_table.PatchTable`).

    Returns -1, or the index of the first point whose face is out of range or refused (a hole)
    or whose (u, v) is outside [0, 1]^2 or NaN; the caller then names it (the outputs from that
    point on are not written).
    """
    n = f.shape[0]
    m = T.refused.shape[0]
    W = np.empty((1, 17, 3))  # the net of a point in a corner face, row 16 its origin
    # the corner nets computed in this call, by patch (a direct-mapped cache: a net is the same sums
    # whether computed or found, so the results do not depend on the cache, the blocks or the threads)
    ns = 0
    if n >= _CACHE_MIN:
        ns = _CACHE_SLOTS
    cache = np.empty((ns, 17, 3))
    tags = np.full(ns, -1, dtype=np.int64)
    lm = 1
    mc = 1
    for c in range(T.n_layers.shape[0]):
        lm = max(lm, T.n_layers[c])
        mc = max(mc, T.op_size[c])
    rc = np.empty((mc, 3))  # a corner ring of the deeper layers (_corner_net)
    for k in range(n):
        pf = f[k]
        uu = u[k]
        ww = v[k]
        if pf < 0 or pf >= m or not (uu >= 0.0 and uu <= 1.0 and ww >= 0.0 and ww <= 1.0) or T.refused[pf]:
            return k
        q = 0
        if uu >= 0.5:
            q += 1
        if ww >= 0.5:
            q += 2
        job = T.top[pf, q]
        vf = T.job_root[job]
        kind = T.kind[vf]
        for _ in range(T.split_depth):
            if kind != KIND_SPLIT:
                break
            half = T.h[vf] * 0.5
            q = 0
            if uu >= T.u0[vf] + half:
                q += 1
            if ww >= T.v0[vf] + half:
                q += 2
            vf = T.child[vf, q]
            kind = T.kind[vf]
        if kind == KIND_CORNER:
            U0 = T.u0[vf]
            V0 = T.v0[vf]
            H = T.h[vf]
            cu = T.cu[vf]
            cv = T.cv[vf]
            du = ((U0 + H) - uu if cu else uu - U0) / H
            dv = ((V0 + H) - ww if cv else ww - V0) / H
            mx = max(du, dv)
            cfg = T.cfg[vf]
            nmax = T.n_layers[cfg] - 1
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
            sc = math.ldexp(H, -lay)
            pu0 = T.unit[cfg, code, 0] * sc + ((U0 + H) if cu else U0)
            pv0 = T.unit[cfg, code, 1] * sc + ((V0 + H) if cv else V0)
            h = T.unit[cfg, code, 2] * sc
            ci = T.job_corner[job] + T.leaf[vf]
            if lay == 0 and T.hot.shape[0] > 0:  # layer 0 precomputed: the same sums
                net = T.hot
                p = 3 * ci + code
            elif ns > 0:
                key = 3 * (lm * ci + lay) + code
                p = (key * _HASH) & (ns - 1)
                if tags[p] != key:
                    _corner_net(T, job, vf, cfg, lay, code, ci, cache, p, rc)
                    tags[p] = key
                net = cache
            else:
                net = _corner_net(T, job, vf, cfg, lay, code, ci, W, 0, rc)
                p = 0
        else:
            net, p = _regular_lookup(T, job, vf, lm, cache, tags, W)
            pu0 = T.u0[vf]
            pv0 = T.v0[vf]
            h = T.h[vf]
        s = min(max((uu - pu0) / h, 0.0), 1.0)
        t = min(max((ww - pv0) / h, 0.0), 1.0)
        g = 1.0 / h
        _bicubic(net, p, s, t, g, d, k, out)
    return -1


def _dot3(a, i, b, j):
    """Row i of a (., 3) dot row j of b, summed left to right."""
    return a[i, 0] * b[j, 0] + a[i, 1] * b[j, 1] + a[i, 2] * b[j, 2]


def _free(w, g):
    """Whether parameter value w in [0, 1] may move with gradient g (not pushed out of the square)."""
    return not ((w <= 0.0 and g > 0) or (w >= 1.0 and g < 0))


def _newton_points(X, face, u, v, max_iter, max_halvings, T, E):
    """The descent of :func:`ccproof.evaluate.newton.newton_descent`, point by point: the same formulas in
    the same order (u, v updated in place, E filled). The points must be valid (checked by the
    caller); each evaluation is the batch kernel's on one point."""
    n = X.shape[0]
    fk = np.empty(1, dtype=np.int64)  # the one point the kernel evaluates per call
    uw = np.empty(1)
    vw = np.empty(1)
    cur = np.empty((6, 1, 3))  # P, Pu, Pv, Puu, Puv, Pvv at the current (u, v)
    new = np.empty((6, 1, 3))
    c0, c1, c2, c3, c4, c5 = cur[0], cur[1], cur[2], cur[3], cur[4], cur[5]
    n0, n1, n2, n3, n4, n5 = new[0], new[1], new[2], new[3], new[4], new[5]
    C = cur.reshape(6, 3)  # views: row r of cur_out / new_out
    Cn = new.reshape(6, 3)
    R = np.empty((1, 3))
    Rt = np.empty((1, 3))
    tiny = 2.0 ** -max_halvings
    for k in range(n):
        f = face[k]
        uk = min(max(u[k], 0.0), 1.0)
        vk = min(max(v[k], 0.0), 1.0)
        fk[0], uw[0], vw[0] = f, uk, vk
        evaluate_points(fk, uw, vw, 2, T, (c0, c1, c2, c3, c4, c5))
        for c in range(3):
            R[0, c] = C[0, c] - X[k, c]
        Ek = 0.5 * _dot3(R, 0, R, 0)
        xs = max(abs(X[k, 0]), max(abs(X[k, 1]), abs(X[k, 2])))
        slack = 1e-13 * Ek + 4e-16 * math.sqrt(2.0 * Ek) * (xs + math.sqrt(2.0 * Ek))
        alpha = 1.0
        for _ in range(max_iter):
            gu, gv = _dot3(C, 1, R, 0), _dot3(C, 2, R, 0)
            guu, guv, gvv = _dot3(C, 1, C, 1), _dot3(C, 1, C, 2), _dot3(C, 2, C, 2)
            huu = guu + _dot3(C, 3, R, 0)
            huv = guv + _dot3(C, 4, R, 0)
            hvv = gvv + _dot3(C, 5, R, 0)
            fu = _free(uk, gu)
            fv = _free(vk, gv)
            tr = abs(guu) + abs(gvv) + 1e-300
            pd = (huu > 0) and (hvv > 0) and (huu * hvv - huv * huv > 1e-14 * tr * tr)
            pd1u = huu > 1e-14 * tr
            pd1v = hvv > 1e-14 * tr
            lm = 1e-6 * tr
            Auu = huu if (pd or (fu and not fv and pd1u)) else guu + lm
            Avv = hvv if (pd or (fv and not fu and pd1v)) else gvv + lm
            Auv = huv if pd else guv
            if fu and fv:
                det = Auu * Avv - Auv * Auv
                du = -(Avv * gu - Auv * gv) / det if det != 0.0 else math.nan
                dv = -(Auu * gv - Auv * gu) / det if det != 0.0 else math.nan
            else:
                du = (-gu / Auu if Auu != 0.0 else math.nan) if fu else 0.0
                dv = (-gv / Avv if Avv != 0.0 else math.nan) if fv else 0.0
            if not (math.isfinite(du) and math.isfinite(dv)):
                du, dv = -gu / tr, -gv / tr
            pg = math.hypot(gu if fu else 0.0, gv if fv else 0.0)
            al = alpha
            u0, v0 = uk, vk
            for _ls in range(max_halvings + 1):
                nu = min(max(u0 + al * du, 0.0), 1.0)
                nv = min(max(v0 + al * dv, 0.0), 1.0)
                moved = (nu != u0) or (nv != v0)
                uw[0], vw[0] = nu, nv
                evaluate_points(fk, uw, vw, 2, T, (n0, n1, n2, n3, n4, n5))
                for c in range(3):
                    Rt[0, c] = Cn[0, c] - X[k, c]
                Et = 0.5 * _dot3(Rt, 0, Rt, 0)
                pred = gu * (nu - u0) + gv * (nv - v0)
                gtu, gtv = _dot3(Cn, 1, Rt, 0), _dot3(Cn, 2, Rt, 0)
                pg_t = math.hypot(gtu if _free(nu, gtu) else 0.0, gtv if _free(nv, gtv) else 0.0)
                if moved and ((Et <= Ek + 1e-4 * min(pred, 0.0)) or ((Et <= Ek + slack) and (pg_t < 0.5 * pg))):
                    uk, vk, Ek = nu, nv, Et
                    for c in range(3):
                        R[0, c] = Rt[0, c]
                    for r in range(6):
                        for c in range(3):
                            C[r, c] = Cn[r, c]
                    break
                if not moved or al <= tiny:
                    break
                al *= 0.5
            step = max(abs(uk - u0), abs(vk - v0))
            ucorner = max(min(uk, 1.0 - uk), min(vk, 1.0 - vk))
            nR = math.sqrt(2.0 * Ek)
            keep = (step > 0) and not ((al >= 1.0) and (step <= 4e-16)) and not (step <= 1e-12 * ucorner)
            keep = keep and not (pg <= 1e-15 * nR * math.sqrt(guu + gvv))
            alpha = min(1.0, al * 2.0)
            if not keep:
                break
        u[k] = uk
        v[k] = vk
        E[k] = Ek


def _take_face(c, org, pos, seen, ring, faces, fc, fl, n, nf):
    """Step of :func:`_ring_walks`: list the face of half-edge ``c`` (read from ``c`` on) unless seen.
    Returns the new counts ``(n, nf)``, or ``(-1, -1)`` when the arrays are full."""
    hf = c // 4
    if seen[hf]:
        return n, nf
    if nf >= faces.shape[0]:
        return -1, -1
    seen[hf] = True
    fl[nf] = hf
    j0 = c - 4 * hf
    for t in range(4):
        hc = 4 * hf + (j0 + t) % 4
        u = org[hc]
        q = pos[u]
        if q < 0:
            if n >= ring.shape[0]:
                faces[nf, 0] = -1
                return -1, nf + 1
            q = n
            pos[u] = n
            ring[n] = u
            fc[n] = hc
            n += 1
        faces[nf, t] = q
    return n, nf + 1


def _ring_walks(halfedges, scratch, g, r, out):
    """:func:`ccproof.evaluate.local.canonical_ring` (depth 1) of quad ``g[k]`` from corner ``r[k]`` of
    an all-quad complex (``halfedges`` = (org, nxt, prv, twin); half-edge ``4 f + i`` is corner i of face f), for
    every k: the same walk.

    Writes into ``out`` = (rings, nring, faces, nfaces, hashes) the ring (vertex labels, ``rings[k, :nring[k]]``),
    the faces in ring labels (``faces[k, :nfaces[k]]``, rows of 4) and a 64-bit FNV-1a hash of (nring, faces).
    ``scratch`` = (pos, seen): ``pos`` (n_vertices,) and ``seen`` (n_faces,), -1 / False on entry and on return.
    ``nring[k] = -1`` if the ring does not fit the arrays or the walk does not close (the caller
    then takes the Python walk).
    """
    org, nxt, prv, twin = halfedges
    pos, seen = scratch
    rings, nring, faces, nfaces, hashes = out
    maxn = rings.shape[1]
    maxf = faces.shape[1]
    fc = np.empty(maxn, dtype=np.int64)
    fl = np.empty(maxf, dtype=np.int64)
    for k in range(g.shape[0]):
        gk = g[k]
        ring = rings[k]
        fk = faces[k]
        n = 0
        nf = 1
        ok = True
        seen[gk] = True
        fl[0] = gk
        for i in range(4):
            h = 4 * gk + (r[k] + i) % 4
            v = org[h]
            fk[0, i] = i
            if pos[v] >= 0:
                ok = False
                break
            pos[v] = n
            ring[n] = v
            fc[n] = h
            n += 1
        idx = 0
        while ok and idx < 4:
            c0 = fc[idx]
            n, nf = _take_face(c0, org, pos, seen, ring, fk, fc, fl, n, nf)
            c = twin[prv[c0]]
            steps = 0
            while n >= 0 and c >= 0 and c != c0 and steps < 4096:  # counter-clockwise
                n, nf = _take_face(c, org, pos, seen, ring, fk, fc, fl, n, nf)
                c = twin[prv[c]]
                steps += 1
            if n < 0 or steps >= 4096:
                ok = False
                break
            if c != c0:  # an open fan: then clockwise from c0
                t_ = twin[c0]
                c = -1 if t_ < 0 else nxt[t_]
                while n >= 0 and c >= 0 and steps < 4096:
                    n, nf = _take_face(c, org, pos, seen, ring, fk, fc, fl, n, nf)
                    t_ = twin[c]
                    c = -1 if t_ < 0 else nxt[t_]
                    steps += 1
                if n < 0 or steps >= 4096:
                    ok = False
                    break
            idx += 1
        if nf < 0:
            nf = maxf
        for i in range(maxn if n < 0 else n):  # reset the scratch arrays
            if i < maxn and ring[i] >= 0 and pos[ring[i]] == i:
                pos[ring[i]] = -1
        for i in range(nf):
            seen[fl[i]] = False
        nring[k] = n if ok else -1
        nfaces[k] = nf
        hsh = np.uint64(14695981039346656037)
        prime = np.uint64(1099511628211)
        hsh = (hsh ^ np.uint64(max(n, 0))) * prime
        for i in range(nf):
            for t in range(4):
                hsh = (hsh ^ np.uint64(fk[i, t] + 1)) * prime
        hashes[k] = hsh


if numba is not None:
    _regular_net = numba.njit(cache=True, nogil=True)(_regular_net)
    _composed_net = numba.njit(cache=True, nogil=True)(_composed_net)
    _regular_lookup = numba.njit(cache=True, nogil=True)(_regular_lookup)
    _corner_net = numba.njit(cache=True, nogil=True)(_corner_net)
    _basis = numba.njit(cache=True, nogil=True, inline="always")(_basis)
    _sum4 = numba.njit(cache=True, nogil=True, inline="always")(_sum4)
    _bicubic = numba.njit(cache=True, nogil=True, inline="always")(_bicubic)
    evaluate_points = numba.njit(cache=True, nogil=True)(_evaluate_points)
    _dot3 = numba.njit(cache=True, nogil=True, inline="always")(_dot3)
    _free = numba.njit(cache=True, nogil=True, inline="always")(_free)
    newton_points = numba.njit(cache=True, nogil=True)(_newton_points)
    _take_face = numba.njit(cache=True, nogil=True)(_take_face)
    ring_walks = numba.njit(cache=True, nogil=True)(_ring_walks)
else:  # pragma: no cover
    evaluate_points = newton_points = ring_walks = None
