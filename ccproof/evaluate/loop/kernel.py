"""Compiled Loop evaluation (numba): the descent through local splits, then one polynomial patch per point.

Every patch the kernel evaluates is a quartic in monomial form: 3 x 15 coefficients (``MONOMIALS`` order of
:mod:`ccproof.evaluate.loop.box_spline`), one *block* of the table ``coef``. The blocks are built at setup
(:meth:`ccproof.evaluate.loop.surface.LoopSurface`): one per box-spline patch, and per corner piece (a
triangle at an irregular vertex, Stam's layers) one per child j of its first ``PRECOMPUTED_LAYERS`` layers,
the piece's limit point added to the constant terms. A point of a corner piece finds its layer n and child j
from the exponent of u + v (O(1)); in the first layers it reads its block like any patch; deeper (a fraction
4^-PRECOMPUTED_LAYERS of the piece's area) it forms the block from the configuration's layer table (``KD[n, j]``:
N ring points x 15 monomials) and the ring's N control points.

Three loops (:func:`_points`): the points of box-spline patches (blocks prefetched a few points ahead), then
the points handed over in corner pieces' stored layers, then the deeper ones; each loop reads only the
tables it needs. Every point's arithmetic is the same whatever the order and the batch
(tests/evaluate/test_loop.py checks bit-identical outputs on permuted points and in small calls).
"""

from __future__ import annotations

import numba
import numpy as np
from llvmlite import ir
from numba.core import cgutils, types
from numba.extending import intrinsic

__all__ = ["evaluate_loop_points", "PRECOMPUTED_LAYERS"]

#: layers whose blocks are stored per corner piece (3 blocks of 360 bytes each per layer; a uniformly random point
#: of a corner piece is deeper with probability 1/64)
PRECOMPUTED_LAYERS = 3
#: corner points located (and their blocks prefetched) before they are evaluated
_BLOCK = 16
#: corner points listed by the patches' loop before they are evaluated
_SLOW = 1024
#: the patches' loop prefetches the block of the point this many points ahead
_AHEAD = 12
#: (Jacobian, offset) per rotation (surface.ROTATIONS), flattened: j00 j01 j10 j11 o0 o1
_ROT = np.array([[1.0, 0.0, 0.0, 1.0, 0.0, 0.0], [0.0, 1.0, -1.0, -1.0, 0.0, 1.0],
                 [-1.0, -1.0, 1.0, 0.0, 1.0, 0.0]])


@intrinsic
def _prefetch(typingctx, arr, idx):
    """Prefetch (read, all cache levels) the cache line of ``arr[idx]`` (a 1-d array): ``llvm.prefetch``."""
    def codegen(context, builder, signature, args):
        aryty = signature.args[0]
        ary = context.make_array(aryty)(context, builder, args[0])
        ptr = cgutils.get_item_pointer(context, builder, aryty, ary, [args[1]], wraparound=False)
        i8p, i32 = ir.IntType(8).as_pointer(), ir.IntType(32)
        fn = cgutils.get_or_insert_function(builder.module, ir.FunctionType(ir.VoidType(), [i8p, i32, i32, i32]),
                                            "llvm.prefetch.p0i8")
        builder.call(fn, [builder.bitcast(ptr, i8p), ir.Constant(i32, 0), ir.Constant(i32, 3), ir.Constant(i32, 1)])
        return context.get_dummy_value()
    return types.void(arr, idx), codegen


@numba.njit(cache=True, inline="always")
def _quartic(c, i, a, b, nrows, loc):
    """loc[r, k] for the first nrows rows (P; Pu, Pv; Puu, Puv, Pvv) of the quartic with coefficients c[i] (3, 15)
    at (a, b): the monomials once, then per coordinate their products with its 15 coefficients."""
    a2, ab, b2 = a * a, a * b, b * b
    a3, a2b, ab2, b3 = a2 * a, a2 * b, a * b2, b2 * b
    a4, a3b, a2b2, ab3, b4 = a2 * a2, a3 * b, a2 * b2, a * b3, b2 * b2
    a_2, b_2, ab_2, a2_3, b2_3 = 2.0 * a, 2.0 * b, 2.0 * ab, 3.0 * a2, 3.0 * b2
    a3_4, b3_4, a2b_3, ab2_3, a2b_2, ab2_2 = 4.0 * a3, 4.0 * b3, 3.0 * a2b, 3.0 * ab2, 2.0 * a2b, 2.0 * ab2
    a_6, b_6, ab_6, ab_4, a2_12, b2_12 = 6.0 * a, 6.0 * b, 6.0 * ab, 4.0 * ab, 12.0 * a2, 12.0 * b2
    for k in range(3):
        c0, c1, c2, c3, c4 = c[i, k, 0], c[i, k, 1], c[i, k, 2], c[i, k, 3], c[i, k, 4]
        c5, c6, c7, c8, c9 = c[i, k, 5], c[i, k, 6], c[i, k, 7], c[i, k, 8], c[i, k, 9]
        c10, c11, c12, c13, c14 = c[i, k, 10], c[i, k, 11], c[i, k, 12], c[i, k, 13], c[i, k, 14]
        loc[0, k] = (c0 + c1 * a + c2 * b + c3 * a2 + c4 * ab + c5 * b2 + c6 * a3 + c7 * a2b + c8 * ab2 + c9 * b3
                     + c10 * a4 + c11 * a3b + c12 * a2b2 + c13 * ab3 + c14 * b4)
        if nrows > 1:
            loc[1, k] = (c1 + c3 * a_2 + c4 * b + c6 * a2_3 + c7 * ab_2 + c8 * b2 + c10 * a3_4 + c11 * a2b_3
                         + c12 * ab2_2 + c13 * b3)
            loc[2, k] = (c2 + c4 * a + c5 * b_2 + c7 * a2 + c8 * ab_2 + c9 * b2_3 + c11 * a3 + c12 * a2b_2
                         + c13 * ab2_3 + c14 * b3_4)
        if nrows > 3:
            loc[3, k] = 2.0 * c3 + c6 * a_6 + c7 * b_2 + c10 * a2_12 + c11 * ab_6 + c12 * 2.0 * b2
            loc[4, k] = c4 + c7 * a_2 + c8 * b_2 + c11 * a2_3 + c12 * ab_4 + c13 * b2_3
            loc[5, k] = 2.0 * c5 + c8 * a_2 + c9 * b_6 + c12 * 2.0 * a2 + c13 * ab_6 + c14 * b2_12


@numba.njit(cache=True, inline="always")
def _ring_sums(layers, lo, N, coords, o, k):
    """``sum_q layers[lo + 15 q + m] coords[o + 3 q + k]`` for m = 0 .. 14: 15 sums kept in registers."""
    s0 = s1 = s2 = s3 = s4 = s5 = s6 = s7 = s8 = s9 = s10 = s11 = s12 = s13 = s14 = 0.0
    for q in range(N):
        c = coords[o + 3 * q + k]
        w = lo + 15 * q
        s0 += layers[w] * c
        s1 += layers[w + 1] * c
        s2 += layers[w + 2] * c
        s3 += layers[w + 3] * c
        s4 += layers[w + 4] * c
        s5 += layers[w + 5] * c
        s6 += layers[w + 6] * c
        s7 += layers[w + 7] * c
        s8 += layers[w + 8] * c
        s9 += layers[w + 9] * c
        s10 += layers[w + 10] * c
        s11 += layers[w + 11] * c
        s12 += layers[w + 12] * c
        s13 += layers[w + 13] * c
        s14 += layers[w + 14] * c
    return s0, s1, s2, s3, s4, s5, s6, s7, s8, s9, s10, s11, s12, s13, s14


@numba.njit(cache=True, inline="always")
def _deep_block(n, j, N, base, o0, layers, coords, plim, p, tmp):
    """tmp[0] (3, 15): the block of layer n, child j of a corner piece (ring of N points at coords[o0:], layer
    table at layers[base:]: ``KD[n, j]``, N x 15), its limit point ``plim[p]`` included."""
    lo = base + (n * 3 + j) * N * 15
    for k in range(3):
        s0, s1, s2, s3, s4, s5, s6, s7, s8, s9, s10, s11, s12, s13, s14 = _ring_sums(layers, lo, N, coords, o0, k)
        t = tmp[0, k]
        t[0], t[1], t[2], t[3], t[4], t[5], t[6], t[7] = s0 + plim[p, k], s1, s2, s3, s4, s5, s6, s7
        t[8], t[9], t[10], t[11], t[12], t[13], t[14] = s8, s9, s10, s11, s12, s13, s14


@numba.njit(cache=True, inline="always")
def _layer(a, b, nl):
    """(layer n, child j, x, y, scale, deep) of a point (a, b) of a corner piece of nl layers: (a + b) 2^n in
    [1/2, 1) (doublings: exact; a few for most points), (x, y) in child j of layer n, the derivatives' scale;
    deep: beyond the last layer (then its child 0 at (0, 0))."""
    s, U, V, n, scale = a + b, a, b, 0, 2.0
    while s < 0.5 and n < nl:
        s, U, V, n, scale = 2.0 * s, 2.0 * U, 2.0 * V, n + 1, 2.0 * scale
    deep = n >= nl
    if deep:
        n, U, V, scale = nl - 1, 0.5, 0.0, 0.5 * scale
    if U >= 0.5:
        return n, 0, 2 * U - 1, 2 * V, scale, deep
    if V >= 0.5:
        return n, 1, 2 * U, 2 * V - 1, scale, deep
    return n, 2, 1 - 2 * U, 1 - 2 * V, -scale, deep


@numba.njit(cache=True, inline="always")
def _store(out, i, nrows, loc, scale, t00, t01, t10, t11):
    """Row i of out from the local rows: derivatives scaled, then by the chain rule (H = T^T H' T)."""
    for c in range(3):
        out[0, i, c] = loc[0, c]
        if nrows > 1:
            gu, gv = scale * loc[1, c], scale * loc[2, c]
            out[1, i, c] = t00 * gu + t10 * gv
            out[2, i, c] = t01 * gu + t11 * gv
        if nrows > 3:
            s2 = scale * scale
            huu, huv, hvv = s2 * loc[3, c], s2 * loc[4, c], s2 * loc[5, c]
            out[3, i, c] = t00 * t00 * huu + 2 * t00 * t10 * huv + t10 * t10 * hvv
            out[4, i, c] = t00 * t01 * huu + (t00 * t11 + t10 * t01) * huv + t10 * t11 * hvv
            out[5, i, c] = t01 * t01 * huu + 2 * t01 * t11 * huv + t11 * t11 * hvv


def evaluate_loop_points(face, u, v, nrows, tables, out):
    """out[r, i, c] for points i: rows 0 (P), 1-2 (Pu, Pv), 3-5 (Puu, Puv, Pvv), the first nrows rows.

    ``tables``: ``(finfo, cinfo, coef, corner)`` as :meth:`ccproof.evaluate.loop.surface.LoopSurface` builds
    them: per face its root node's word, per split its four children's words, the blocks, and ``corner`` =
    ``((pblock, pgid, pcoord, plim), (gN, gnl, glay), layers, coords)``.
    """
    finfo, cinfo, coef, corner = tables
    (pblock, pgid, pcoord, plim), (gN, gnl, glay), layers, coords = corner
    _points(face, u, v, nrows, finfo, cinfo, coef, pblock, pgid, pcoord, plim, gN, gnl, glay, layers, coords, out)


@numba.njit(cache=True, inline="always")
def _descend(face, u, v, i, finfo, cinfo, R):
    """(word, a, b, t00, t01, t10, t11) of point i: the descent through the splits to its patch or corner piece
    (the parameter turned and scaled, T its Jacobian). A node is one word: reference * 16 + rotation * 4 + kind."""
    x = finfo[face[i]]
    a, b = u[i], v[i]
    t00, t01, t10, t11 = 1.0, 0.0, 0.0, 1.0
    while True:
        r = (x >> 2) & 3
        if r != 0:
            j00, j01, j10, j11, o0, o1 = R[r, 0], R[r, 1], R[r, 2], R[r, 3], R[r, 4], R[r, 5]
            a, b = j00 * a + j01 * b + o0, j10 * a + j11 * b + o1
            t00, t01, t10, t11 = (j00 * t00 + j01 * t10, j00 * t01 + j01 * t11,
                                  j10 * t00 + j11 * t10, j10 * t01 + j11 * t11)
        if x & 3 != 2:
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
        x = cinfo[x >> 4, c]
    return x, a, b, t00, t01, t10, t11


@numba.njit(cache=True)
def _points(face, u, v, nrows, finfo, cinfo, coef, pblock, pgid, pcoord, plim, gN, gnl, glay, layers, coords, out):
    """The points in box-spline patches by :func:`_patch_points`, the others listed and then evaluated by
    :func:`_corner_points` (the stored layers) and :func:`_deep_points` (deeper), _SLOW at a time: each loop
    reads only the tables it needs (a loop that might touch more tables runs slower)."""
    slow = np.empty((min(face.size, _SLOW), 2), dtype=np.int64)  # point, word
    state = np.empty((min(face.size, _SLOW), 6))  # a, b, t00, t01, t10, t11
    deep = np.empty(min(face.size, _SLOW), dtype=np.int64)
    i = 0
    while i < face.size:
        i, ns = _patch_points(face, u, v, i, nrows, finfo, cinfo, coef, out, slow, state)
        nd = _corner_points(slow, state, ns, nrows, coef, pblock, pgid, gnl, out, deep) if ns else 0
        if nd:
            _deep_points(deep, nd, face, u, v, nrows, finfo, cinfo, pgid, pcoord, plim, gN, gnl, glay, layers, coords,
                         out)


@numba.njit(cache=True)
def _patch_points(face, u, v, i, nrows, finfo, cinfo, coef, out, slow, state):
    """Points i, i + 1, ... in box-spline patches evaluated (the blocks of faces _AHEAD points on prefetched), the
    others listed in ``slow`` until it is full; returns (the next point, the count listed)."""
    R = _ROT
    loc = np.empty((6, 3))
    flat = coef.reshape(-1)
    n, ns = face.size, 0
    while i < n and ns < slow.shape[0]:
        if i + _AHEAD < n:
            x = finfo[face[i + _AHEAD]]
            if x & 3 == 0:
                for q in range(0, 45, 8):
                    _prefetch(flat, 45 * (x >> 4) + q)
                _prefetch(flat, 45 * (x >> 4) + 44)
        x, a, b, t00, t01, t10, t11 = _descend(face, u, v, i, finfo, cinfo, R)
        if x & 3 != 0:
            slow[ns, 0], slow[ns, 1] = i, x
            st = state[ns]
            st[0], st[1], st[2], st[3], st[4], st[5] = a, b, t00, t01, t10, t11
            ns += 1
        else:
            _quartic(coef, x >> 4, a, b, nrows, loc)
            _store(out, i, nrows, loc, 1.0, t00, t01, t10, t11)
        i += 1
    return i, ns


@numba.njit(cache=True)
def _corner_points(idx, state, ns, nrows, coef, pblock, pgid, gnl, out, deep):
    """Points idx[:ns] in corner pieces, _BLOCK at a time: first their layers located (the stored layers' blocks
    prefetched), then evaluated; those in deeper layers listed in ``deep`` (returns their count)."""
    loc = np.empty((6, 3))
    flat = coef.reshape(-1)
    iw = np.empty(_BLOCK, dtype=np.int64)  # block, -1: deeper
    fw = np.empty((_BLOCK, 7))  # a, b, scale, t00, t01, t10, t11
    nd = 0
    for k0 in range(0, ns, _BLOCK):
        k1 = min(k0 + _BLOCK, ns)
        for k in range(k0, k1):
            p = idx[k, 1] >> 4
            t00, t01, t10, t11 = state[k, 2], state[k, 3], state[k, 4], state[k, 5]
            n, j, a, b, scale, beyond = _layer(state[k, 0], state[k, 1], gnl[pgid[p]])
            blk = pblock[p] + 3 * n + j if n < PRECOMPUTED_LAYERS and not beyond else -1
            w = k - k0
            iw[w] = blk
            fw[w, 0], fw[w, 1], fw[w, 2], fw[w, 3], fw[w, 4], fw[w, 5], fw[w, 6] = a, b, scale, t00, t01, t10, t11
            if blk >= 0:
                for q in range(0, 45, 8):
                    _prefetch(flat, 45 * blk + q)
                _prefetch(flat, 45 * blk + 44)
            else:
                deep[nd] = idx[k, 0]
                nd += 1
        for k in range(k0, k1):
            w = k - k0
            if iw[w] >= 0:
                _quartic(coef, iw[w], fw[w, 0], fw[w, 1], nrows, loc)
                _store(out, idx[k, 0], nrows, loc, fw[w, 2], fw[w, 3], fw[w, 4], fw[w, 5], fw[w, 6])
    return nd


@numba.njit(cache=True)
def _deep_points(idx, nd, face, u, v, nrows, finfo, cinfo, pgid, pcoord, plim, gN, gnl, glay, layers, coords, out):
    """Points idx[:nd] in the deeper layers of corner pieces (or beyond the last): their blocks formed from the
    configuration's layer table and the ring."""
    R = _ROT
    loc = np.empty((6, 3))
    tmp = np.empty((1, 3, 15))
    for k in range(nd):
        i = idx[k]
        x, a, b, t00, t01, t10, t11 = _descend(face, u, v, i, finfo, cinfo, R)
        p = x >> 4
        g = pgid[p]
        n, j, a, b, scale, beyond = _layer(a, b, gnl[g])
        _deep_block(n, j, gN[g], glay[g], pcoord[p], layers, coords, plim, p, tmp)
        _quartic(tmp, 0, a, b, nrows, loc)
        if beyond:
            for c in range(3):
                loc[0, c] = plim[p, c]
        _store(out, i, nrows, loc, scale, t00, t01, t10, t11)
