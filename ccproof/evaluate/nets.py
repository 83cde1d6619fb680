"""The nets and rings the kernels compute, computed with numpy by the same sums in the same order.

Every net of a point is a linear function of its job's ring: ``sum_j op[j] * (X[ring[j]] - X[ring[0]])``
over j = 1, 2, ... in order from 0.0 (:func:`ring_products`), the order every backend keeps, so that all
give the same bits. Here: the nets a small table keeps precomputed (:func:`with_nets`, within
:data:`NETS_BUDGET` and :data:`HOT_BUDGET`), the kept rings of large corner faces (:func:`kept_rings`), and
the nets the numpy backend computes at evaluation time (:func:`composed_nets`, :func:`corner_limits`,
:func:`corner_rings`).
"""

from __future__ import annotations

import weakref

import numpy as np

from ccproof.errors import MeshError
from ccproof.evaluate.patch_table import KIND_CORNER, KIND_REGULAR

#: jobs per block when the limit points or precomputed nets are computed (bounds the temporaries)
_BLOCK = 1 << 13

#: largest size of the layer-0 nets of the corner faces kept precomputed (``PatchTable.hot``, 1,224
#: bytes per corner face); beyond it every corner net is computed at evaluation time
HOT_BUDGET = 32 << 20

#: corner rings of at least this many points are kept per corner face (``PatchTable.ring``)
KEEP_RING_NC = 40

#: largest size of the regular nets kept precomputed (``PatchTable.nets``, 408 bytes per regular patch);
#: beyond it every regular net is computed at evaluation time from the ring
NETS_BUDGET = 32 << 20


#: precomputing the nets costs a product with every point of every job's ring: none are precomputed where
#: the rings average more points than this (an n-gon's n corner faces share its centre's 2n + 8 points, n^2
#: products in all: a lone 1000-gon's 3.4 s of CPU); they are then computed per point (the same bits)
RING_MEAN_PRECOMPUTED = 64

#: :func:`ring_products` adds all terms in one array operation up to this many terms (else term by term)
_ACCUMULATE_MAX = 1 << 17


def with_nets(T, groups):
    """``T`` with the precomputed nets that fit their budgets: the regular nets (:data:`NETS_BUDGET`, or the
    environment variable ``CCPROOF_NETS_BUDGET`` in bytes) and the layer-0 corner nets (:data:`HOT_BUDGET`,
    ``CCPROOF_HOT_BUDGET``), both by the kernels' sums (none where they do not fit: the same bits), and none
    where the rings average more than :data:`RING_MEAN_PRECOMPUTED` points."""
    sizes = [(jobs.size, rings.size) for _, jobs, rings in groups if jobs is not None and jobs.size]
    if sum(r for _, r in sizes) > RING_MEAN_PRECOMPUTED * sum(k for k, _ in sizes):
        return kept_rings(T, groups)
    n_cor = T.n_corner
    if 0 < T.n_regular and T.n_regular * 17 * 3 * 8 <= budget("CCPROOF_NETS_BUDGET", NETS_BUDGET):
        T = T._replace(nets=regular_nets(T, groups))
    if 0 < n_cor and n_cor * 3 * 17 * 3 * 8 <= budget("CCPROOF_HOT_BUDGET", HOT_BUDGET):
        T = T._replace(hot=layer0_nets(T, groups))
    return kept_rings(T, groups)


def kept_rings(T, groups):
    """``T`` with the rings of its corner faces with at least :data:`KEEP_RING_NC` points kept
    (:attr:`PatchTable.ring`, by :func:`corner_rings`: the kernels' sums), or ``T`` where there are none."""
    parts, off = [], 0
    cor_ring = None
    for t, jobs, _ in groups:
        if not jobs.size:
            continue
        root = int(T.job_root[jobs[0]])
        for vf, kind in enumerate(t.kind):
            g = root + vf
            if kind != KIND_CORNER or T.op_size[T.cfg[g]] < KEEP_RING_NC:
                continue
            if cor_ring is None:
                cor_ring = np.full(T.n_corner, -1, dtype=np.int64)
            m = int(T.op_size[T.cfg[g]]) - 1
            for lo in range(0, jobs.size, _BLOCK):
                jb = jobs[lo:lo + _BLOCK]
                parts.append(corner_rings(T, jb, g)[:, 1:].reshape(-1, 3))
                cor_ring[T.job_corner[jb] + t.leaf[vf]] = off + m * np.arange(jb.size)
                off += m * jb.size
    if cor_ring is None:
        return T
    return T._replace(cor_ring=cor_ring, ring=np.concatenate(parts))


def budget(name, default):
    """The byte budget in the environment variable ``name`` (a non-negative integer), else ``default``.

    >>> budget("CCPROOF_NO_SUCH_BUDGET", 7)
    7
    """
    import os

    v = os.environ.get(name)
    if v is None or v == "":
        return default
    try:
        b = int(v)
    except ValueError:
        b = -1
    if b < 0:
        raise MeshError(f"{name}={v!r}: a budget in bytes, a non-negative integer")
    return b


def ring_products(op, X, rings):
    """``op`` (N, r) applied to the rings (k, N) of positions ``X``, the kernels' sums: per ring
    ``sum_j op[j] * (X[ring[j]] - X[ring[0]])`` over j = 1, 2, ... in order from 0.0. Shape (k, r, 3).

    >>> X = np.array([[0.0, 0, 0], [1, 0, 0], [0, 2, 0]])
    >>> ring_products(np.array([[9.0], [1.0], [0.5]]), X, np.array([[0, 1, 2]]))[0].tolist()
    [[1.0, 1.0, 0.0]]
    """
    X0 = X[rings[:, 0]]
    k, N = rings.shape
    if 1 < N and k * (N - 1) * op.shape[1] * 3 <= _ACCUMULATE_MAX:
        # small blocks (many calls on a small mesh): the same sums at once, np.add.accumulate adding the
        # terms in order; ``+ 0.0`` gives the loop's +0.0 where every term is -0.0 (0.0 + (-0.0) = 0.0)
        D = (X[rings[:, 1:]] - X0[:, None, :]).transpose(1, 0, 2)  # (N - 1, k, 3)
        terms = op[1:, None, :, None] * D[:, :, None, :]  # (N - 1, k, r, 3)
        return np.add.accumulate(terms, axis=0)[-1] + 0.0
    acc = np.zeros((rings.shape[0], op.shape[1], 3))
    for j in range(1, op.shape[0]):
        acc += op[j][None, :, None] * (X[rings[:, j]] - X0)[:, None, :]
    return acc


def regular_nets(T, groups):
    """The nets of every regular patch of table ``T`` (:attr:`PatchTable.nets`), computed as the kernels
    compute them (:func:`ring_products` of the leaf's operator, row 16 plus the ring's point 0)."""
    nets = np.empty((T.n_regular, 17, 3))
    X = T.points
    for t, jobs, rings in groups:
        if not jobs.size:
            continue
        root = int(T.job_root[jobs[0]])
        vfs = [vf for vf, kind in enumerate(t.kind) if kind == KIND_REGULAR]
        if not vfs:
            continue
        # the regular patches of one template share their jobs' rings: their operators side by side, one
        # ring_products per block of jobs (each entry's sum the same, in the same order)
        op = _kept_operator(T, "regular", root, vfs)
        step = max(1, (_BLOCK * 17) // op.shape[1])
        leaves = np.array([t.leaf[vf] for vf in vfs], dtype=np.int64)
        for lo in range(0, jobs.size, step):
            R = rings[lo:lo + step]
            a = ring_products(op, X, R).reshape(R.shape[0], len(vfs), 17, 3)
            a[:, :, 16] += X[R[:, 0]][:, None, :]
            nets[(T.job_net[jobs[lo:lo + step]][:, None] + leaves[None, :]).reshape(-1)] = a.reshape(-1, 17, 3)
    return nets


def composed_nets(T, jobs, vf, lay, code=None):
    """The nets (k, 17, 3) of patch ``code`` of layer ``lay`` < :data:`~ccproof.evaluate.patch_table.COMPOSED_LAYERS`
    of the corner face ``vf`` of ``jobs`` (k,): :func:`ring_products` of the composed operator, row 16 the limit
    point. ``code`` None: the three patch codes at once, shape (k, 3, 17, 3), their operators side by side in one
    product (each entry's sum the same, in the same order)."""
    N, st, Nc = int(T.vn[vf]), int(T.vop_start[vf]), int(T.op_size[T.cfg[vf]])
    codes = 3 if code is None else 1
    st += N * (Nc - 1) + N + (3 * lay + (0 if code is None else code)) * N * 16
    op = T.vop[st:st + codes * N * 16].reshape(codes, N, 16).transpose(1, 0, 2).reshape(N, codes * 16)
    R = T.rings[T.job_ring[jobs][:, None] + np.arange(N)]
    out = np.empty((R.shape[0], codes, 17, 3))
    out[:, :, :16] = ring_products(op, T.points, R).reshape(-1, codes, 16, 3)
    out[:, :, 16] = corner_limits(T, jobs, vf)[:, None, :]
    return out if code is None else out[:, 0]


def corner_limits(T, jobs, vf):
    """The limit points (k, 3) at the irregular corner of the corner face ``vf`` of ``jobs`` (k,), computed
    as the kernels compute them (:func:`ring_products` of its operator row, plus the ring's point 0)."""
    N, st, Nc = int(T.vn[vf]), int(T.vop_start[vf]), int(T.op_size[T.cfg[vf]])
    st += N * (Nc - 1)
    R = T.rings[T.job_ring[jobs][:, None] + np.arange(N)]
    return ring_products(T.vop[st:st + N].reshape(N, 1), T.points, R)[:, 0] + T.points[R[:, 0]]


def corner_rings(T, jobs, vf):
    """The rings (k, Nc, 3) relative to their corner vertex (row 0 zero) of the corner face ``vf`` (a
    virtual face of the table ``T``) of ``jobs`` (k,), computed as the kernels compute them."""
    N, st, Nc = int(T.vn[vf]), int(T.vop_start[vf]), int(T.op_size[T.cfg[vf]])
    R = T.rings[T.job_ring[jobs][:, None] + np.arange(N)]
    out = np.zeros((R.shape[0], Nc, 3))
    op = T.vop[st:st + N * (Nc - 1)].reshape(N, Nc - 1)
    parts = _sparse_parts(op) if N >= 256 and Nc >= 256 else None
    if parts is None:
        out[:, 1:] = ring_products(op, T.points, R)
    else:  # an n-gon centre's ring: linear in n, the same sums but in another order (rounding ~1e-16)
        S, m = parts
        D = T.points[R] - T.points[R[:, :1]]  # (k, N, 3)
        for c in range(3):
            out[:, 1:, c] = (S.T @ D[:, :, c].T).T + (D[:, :, c] @ m)[:, None]
    return out


def _sparse_parts(op):
    """``(S, m)`` with ``op = S + m 1^T`` (``m`` the row medians: the part every output shares, as the centre
    of an n-gon's ring is in every point relative to the corner), ``S`` sparse (at most 10 % entries), or None."""
    import scipy.sparse

    m = np.median(op, axis=1)
    S = op - m[:, None]
    if np.count_nonzero(S) > 0.1 * S.size:
        return None
    return scipy.sparse.csr_matrix(S), m


def layer0_nets(T, groups):
    """The nets of layer 0 of every corner face of table ``T`` (see :attr:`PatchTable.hot`): per
    corner face c and patch code the composed operator's sums (:func:`composed_nets`, the compiled
    kernel's), row 16 the limit point (:func:`corner_limits`). Shape (3 n_corner, 17, 3).

    The corner faces of one template share their jobs' rings: their operators go side by side into one
    :func:`ring_products` per block of jobs (each entry's sum the same, in the same order)."""
    hot = np.empty((3 * T.n_corner, 17, 3))
    for t, jobs, _ in groups:
        if jobs is None or not jobs.size or not t.O.shape[0]:
            continue
        root = int(T.job_root[jobs[0]])
        vfs = [vf for vf, kind in enumerate(t.kind) if kind == KIND_CORNER]
        op = _kept_operator(T, "layer 0", root, vfs)  # (N, 49 per corner face)
        N, nv = op.shape[0], len(vfs)
        leaves = np.array([t.leaf[vf] for vf in vfs], dtype=np.int64)
        step = max(1, (_BLOCK * 64) // op.shape[1])
        for lo in range(0, jobs.size, step):
            jb = jobs[lo:lo + step]
            R = T.rings[T.job_ring[jb][:, None] + np.arange(N)]
            acc = ring_products(op, T.points, R).reshape(jb.size, nv, 49, 3)
            nets = np.empty((jb.size, nv, 3, 17, 3))
            nets[:, :, :, :16] = acc[:, :, :48].reshape(jb.size, nv, 3, 16, 3)
            nets[:, :, :, 16] = (acc[:, :, 48] + T.points[R[:, 0]][:, None, :])[:, :, None, :]
            ci = T.job_corner[jb][:, None] + leaves[None, :]  # (k, nv): the corner faces' rows
            hot[(3 * ci[:, :, None] + np.arange(3)).reshape(-1)] = nets.reshape(-1, 17, 3)
    return hot


#: per (kind of net, the table's shared leaf operators' identity, the slices of them read): the operators of a
#: template's patches side by side (:func:`regular_nets`, :func:`layer0_nets`), read-only, those of recent setups
#: in this process (a weak reference to the shared array kept with them: they do not keep it alive) within
#: :data:`_KEPT_BUDGET` bytes (the oldest dropped first)
_KEPT: dict = {}
_KEPT_BUDGET = 8 << 20


def _side_by_side(T, kind, root, vfs):
    """The operators of the patches ``vfs`` of the template at ``root`` side by side: ``kind`` "regular", each
    leaf's (N, 17); "layer 0", each corner face's (N, 49) of :func:`_layer0_operator`."""
    if kind == "regular":
        N = int(T.vn[root + vfs[0]])
        return np.concatenate([T.vop[int(T.vop_start[root + vf]):int(T.vop_start[root + vf]) + 17 * N].reshape(N, 17)
                               for vf in vfs], axis=1)
    return np.concatenate([_layer0_operator(T, root + vf) for vf in vfs], axis=1)


def _kept_operator(T, kind, root, vfs):
    """:func:`_side_by_side` of ``T`` (a new array or one kept), the same array again while ``T.vop`` is a
    read-only view of the same shared read-only array and the slices read the same
    (their starts, sizes and ring sizes: the array's content is all the result depends on)."""
    base = T.vop.base
    if base is None or T.vop.flags.writeable or base.flags.writeable or T.vop.size != base.size:
        return _side_by_side(T, kind, root, vfs)
    idx = root + np.asarray(vfs, dtype=np.int64)
    key = (kind, id(base), tuple(T.vop_start[idx].tolist()), tuple(T.vn[idx].tolist()),
           tuple(T.op_size[T.cfg[idx]].tolist()) if kind != "regular" else ())
    hit = _KEPT.get(key)
    if hit is not None and hit[0]() is base:
        return hit[1]
    op = _side_by_side(T, kind, root, vfs)
    op.setflags(write=False)
    held = sum(h[1].nbytes for h in _KEPT.values())
    while _KEPT and held + op.nbytes > _KEPT_BUDGET:
        held -= _KEPT.pop(next(iter(_KEPT)))[1].nbytes
    if op.nbytes <= _KEPT_BUDGET:
        _KEPT[key] = (weakref.ref(base), op)
    return op


def _layer0_operator(T, vf):
    """(N, 49): the composed operators of layer 0 of the corner face ``vf`` (the three patch codes' 16 columns,
    :func:`composed_nets`), then its limit point's (:func:`corner_limits`)."""
    N, st, Nc = int(T.vn[vf]), int(T.vop_start[vf]), int(T.op_size[T.cfg[vf]])
    lim = T.vop[st + N * (Nc - 1):st + N * (Nc - 1) + N].reshape(N, 1)
    st += N * (Nc - 1) + N
    op = T.vop[st:st + 3 * N * 16].reshape(3, N, 16).transpose(1, 0, 2).reshape(N, 48)
    return np.concatenate([op, lim], axis=1)
