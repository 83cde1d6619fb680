"""The numpy backend: the reference evaluation, the same sums in the same order as the compiled kernels.

Points are located by :class:`~ccproof.evaluate.patch_map.PatchMap`; their nets are gathered (kept regular
nets and layer-0 corner nets) or computed from the jobs' rings (:mod:`ccproof.evaluate.nets`), then evaluated
as bicubic B-spline patches, all in vectorized numpy (:func:`evaluate_chunk`). Chosen by
:mod:`ccproof.evaluate.backend`; the tests compare the C and numba backends with it bit for bit.
"""

from __future__ import annotations

import numpy as np

from ccproof.evaluate.bspline import bspline_basis
from ccproof.evaluate.nets import composed_nets, corner_limits, corner_rings, ring_products
from ccproof.evaluate.patch_table import COMPOSED_LAYERS, KIND_REGULAR


def evaluate_chunk(T, patch_map, f, u, v, d, out):
    """Positions and derivatives up to order ``d`` of the points ``f, u, v`` (checked) of the table ``T`` located
    by ``patch_map`` (a :class:`~ccproof.evaluate.patch_map.PatchMap`) into ``out`` (a dict of (n, 3) arrays):
    the nets of :func:`point_nets`, then the bicubic B-spline sums, scaled by the patch's ``1 / h``."""
    _, s, t, g, G = point_nets(T, patch_map, f, u, v)
    bs = bspline_basis(s, d)
    bt = bspline_basis(t, d)
    G = G.reshape(-1, 51)
    N = G[:, :48].reshape(-1, 4, 4, 3)  # [n, j, i, c]
    T0 = np.einsum("nj,njic->nic", bt[0], N)
    np.add(G[:, 48:], np.einsum("ni,nic->nc", bs[0], T0), out=out["P"])
    if d >= 1:
        T1 = np.einsum("nj,njic->nic", bt[1], N)
        gg = g[:, None]
        np.multiply(np.einsum("ni,nic->nc", bs[1], T0), gg, out=out["Pu"])
        np.multiply(np.einsum("ni,nic->nc", bs[0], T1), gg, out=out["Pv"])
    if d >= 2:
        T2 = np.einsum("nj,njic->nic", bt[2], N)
        g2 = (g * g)[:, None]
        np.multiply(np.einsum("ni,nic->nc", bs[2], T0), g2, out=out["Puu"])
        np.multiply(np.einsum("ni,nic->nc", bs[1], T1), g2, out=out["Puv"])
        np.multiply(np.einsum("ni,nic->nc", bs[0], T2), g2, out=out["Pvv"])


def point_nets(T, patch_map, f, u, v, nets=True):
    """Patch ids, parameters (s, t), scales ``1 / h`` and (``nets``) the nets (n, 17, 3) of the
    points: a gather for regular patches, ``L[n, code] @ ring`` for the layers of corner faces."""
    loc = patch_map.locate(f, u, v)
    N = None
    if nets:
        N = np.empty((f.size, 17, 3))
        reg = np.flatnonzero(loc.kind == KIND_REGULAR)
        if T.nets.shape[0]:  # kept (the same sums)
            N[reg] = T.nets[loc.patch[reg]]
        else:
            for w in np.unique(loc.vface[reg]).tolist():
                sel = reg[loc.vface[reg] == w]
                n_, st = int(T.vn[w]), int(T.vop_start[w])
                R = T.rings[T.job_ring[loc.job[sel]][:, None] + np.arange(n_)]
                a = ring_products(T.vop[st:st + 17 * n_].reshape(n_, 17), T.points, R)
                a[:, 16] += T.points[R[:, 0]]
                N[sel] = a
        idx = loc.corner
        if idx.size:
            _corner_point_nets(T, loc, N)
    return loc.patch, loc.s, loc.t, loc.scale, N


def _corner_point_nets(T, loc, N):
    """The nets of the points of ``loc`` (a :class:`~ccproof.evaluate.patch_map.Location`) in corner
    faces into ``N``: layer 0 kept (``hot``), the first layers by their composed operators, the others
    ``L[n, code] @ ring``, summed in the kernels' order."""
    idx = loc.corner
    w = loc.vface[idx]
    n, code, ci = loc.layer, loc.code, loc.corner_face
    todo = np.ones(idx.size, dtype=bool)
    if T.hot.shape[0]:  # layer 0 precomputed (the same sums)
        h0 = np.flatnonzero(n == 0)
        N[idx[h0]] = T.hot[3 * ci[h0] + code[h0]]
        todo[h0] = False
    for vf in np.unique(w[todo]).tolist():
        at = (w == vf) & todo
        for lay in range(COMPOSED_LAYERS):  # one product with the ring
            for code_ in range(3):
                sel = np.flatnonzero(at & (n == lay) & (code == code_))
                if sel.size:
                    N[idx[sel]] = composed_nets(T, loc.job[idx[sel]], vf, lay, code_)
        sel = np.flatnonzero(at & (n >= COMPOSED_LAYERS))
        if not sel.size:
            continue
        c = int(T.cfg[vf])
        Nc, nl, st = int(T.op_size[c]), int(T.n_layers[c]), int(T.op_start[c])
        Lc = T.ops[st:st + nl * 48 * Nc].reshape(nl * 3, Nc, 16)
        Q = corner_rings(T, loc.job[idx[sel]], vf)
        Ls = Lc[3 * n[sel] + code[sel]]  # (k, Nc, 16)
        acc = np.zeros((sel.size, 16, 3))
        for j in range(1, Nc):  # summed in the compiled kernel's order: the same bits
            acc += Ls[:, j, :, None] * Q[:, None, j, :]
        N[idx[sel], :16] = acc
        N[idx[sel], 16] = corner_limits(T, loc.job[idx[sel]], vf)
