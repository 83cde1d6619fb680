"""Basis rows of a limit surface: the sparse linear map from the file's control points to points and derivatives.

The patch table (:mod:`ccproof.evaluate.patch_table`) computes every float it holds as a linear function of the
control points: per job, ``rel = X[ring] - X[ring[0]]`` and a template operator (``R`` for regular nets,
``Q`` for corner rings, ``O`` for limit points); a corner layer's net is its configuration's layer
operator ``L[n, code]`` applied to the corner ring. Composing these per *key* (a regular virtual face, or
a corner virtual face with its layer and patch code) gives a 16 x k matrix ``A`` from k ring vertices to
the patch's 4 x 4 net, once per key; a point's row is then ``B(s, t) A`` (the tensor B-spline weights
of the point, OpenSubdiv's limit stencils). On a PolyMesh the rings index the vertices the builder
classified (the file's vertices, or those of one Catmull-Clark step); the step's sparse matrix composes
the rows back to the file's vertices.

Everything is topology: the operators per key and the step are cached on the surface and shared by the
surfaces :meth:`~ccproof.evaluate.surface.LimitSurface.with_vertices` derives.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
import scipy.sparse as sp

from ccproof.evaluate._parallel import in_blocks, threads_for
from ccproof.evaluate.bspline import bspline_basis

__all__ = ["BASIS_KEYS", "basis_rows"]

#: ``kind`` of a corner face (one irregular corner) in the patch table (:class:`ccproof.evaluate.patch_map.Location`)
CORNER_KIND = 1

#: the keys of :meth:`LimitSurface.basis` per derivative order, and the key of ``evaluate`` each one reproduces
BASIS_KEYS = {0: ("P",), 1: ("P", "Du", "Dv"), 2: ("P", "Du", "Dv", "Duu", "Duv", "Dvv")}


class _Topology:
    """Per surface topology: every job's ring in one flat array, the operators per key (built when a
    point first needs them) in flat arrays the kernels read, the step's matrix of a PolyMesh surface."""

    def __init__(self, S):
        T = S._table
        n_jobs = T.job_root.shape[0]
        self.job_ring = np.zeros(n_jobs, dtype=np.int64)  # start of every job's ring in ``ring``
        self.vf_group = np.zeros(T.kind.shape[0], dtype=np.int64)
        self.root, parts, off = [], [], 0
        for g, (t, jobs, rings) in enumerate(S._groups):
            self.job_ring[jobs] = off + t.n * np.arange(jobs.size)
            parts.append(np.asarray(rings, dtype=np.int64).reshape(-1))
            off += rings.size
            root = int(T.job_root[jobs[0]]) if jobs.size else -1
            self.root.append(root)
            if root >= 0:
                self.vf_group[root:root + len(t.kind)] = g
        self.ring = np.concatenate(parts) if parts else np.zeros(0, np.int64)
        self.stride = 3 * max(int(S.max_layers), 1) + 1
        self.op_of_key = np.full(T.kind.shape[0] * self.stride, -1, dtype=np.int64)
        self._ops = []  # (dev, org, cols) per operator id
        self.arrays = None
        self.vertex_map = None
        # per smooth regular job (its net is its ring): the net's vertices by column and every net entry's
        # place among them (the rows sorted by column without a sort per point)
        self.grid_net = np.zeros(16 * n_jobs, dtype=np.int64)
        self.grid_rank = np.zeros(16 * n_jobs, dtype=np.int8)
        self.grid_repeats = 0  # columns repeated in those nets (a small periodic mesh), in all jobs
        for t, jobs, rings in S._groups:
            if getattr(t, "smooth_grid", None) is not None and jobs.size:
                net = np.asarray(rings, dtype=np.int64).reshape(jobs.size, 16)
                order = np.argsort(net, axis=1, kind="stable")
                at = (16 * jobs[:, None] + np.arange(16)).reshape(-1)
                self.grid_net[at] = np.take_along_axis(net, order, axis=1).reshape(-1)
                self.grid_rank[at] = np.argsort(order, axis=1).reshape(-1)
                by_column = self.grid_net[at].reshape(jobs.size, 16)
                self.grid_repeats += int(np.count_nonzero(by_column[:, 1:] == by_column[:, :-1]))

    def operator_ids(self, S, key):
        """The operator id of every key (building the missing operators)."""
        op = self.op_of_key[key]
        missing = np.unique(key[op < 0])
        if missing.size:
            for k in missing.tolist():
                self.op_of_key[k] = len(self._ops)
                self._ops.append(self._operator(S, k))
            self.arrays = None
            op = self.op_of_key[key]
        return op

    def flat(self):
        """The operators as flat arrays: ``(cols_start, n_cols, dev_start, cols, dev, org)``; ``dev_start``
        -1 for a smooth regular quad (its net is its ring), else the (16, n_cols - 1) deviation at
        ``dev[dev_start:]`` and the limit row at ``org[dev_start // 16:]``."""
        if self.arrays is None:
            n = len(self._ops)
            ncols = np.array([c.size for _, _, c in self._ops], dtype=np.int64)
            cstart = np.zeros(n, dtype=np.int64)
            cstart[1:] = np.cumsum(ncols)[:-1]
            sizes = np.array([0 if d is None else o.size for d, o, _ in self._ops], dtype=np.int64)
            ostart = np.zeros(n, dtype=np.int64)
            ostart[1:] = np.cumsum(sizes)[:-1]
            dstart = np.where([d is None for d, _, _ in self._ops], -1, 16 * ostart)
            cols = np.concatenate([np.zeros(0, np.int64)] + [c for _, _, c in self._ops]).astype(np.int64)
            dev = np.concatenate([np.zeros(0)] + [d.reshape(-1) for d, _, _ in self._ops if d is not None])
            org = np.concatenate([np.zeros(0)] + [o for d, o, _ in self._ops if d is not None])
            self.arrays = (cstart, ncols, dstart, cols, dev, org)
        return self.arrays

    def operator(self, i):
        return self._ops[i]

    def _operator(self, S, key):
        """``(dev, org, cols)`` of ``key``: the net (16 x k) less the limit point, and the limit point (k,),
        as weights of the ring's columns ``cols[1:]`` relative to its column 0, ``cols[0] == 0``
        (None, None for a smooth regular quad: its net is its ring's 16 columns)."""
        T = S._table
        vf, rest = divmod(int(key), self.stride)
        g = int(self.vf_group[vf])
        t = S._groups[g][0]
        lv = vf - self.root[g]
        if getattr(t, "smooth_grid", None) is not None:  # the net is the ring's grid (its template)
            return None, None, np.arange(16)
        if T.kind[vf] == CORNER_KIND:
            layer, code = divmod(rest - 1, 3)
            c, cfg = int(t.leaf[lv]), int(T.cfg[vf])
            Nc, st, nl = int(T.op_size[cfg]), int(T.op_start[cfg]), int(T.n_layers[cfg])
            Ls = T.ops[st:st + nl * 48 * Nc].reshape(nl * 3, Nc, 16)[3 * layer + code]
            p = int(t.pts[lv])
            dev, org = Ls[1:].T @ t.Q[p:p + Nc - 1], t.O[c]  # the net less the limit point, the limit point
        else:
            r = 17 * int(t.leaf[lv])
            dev, org = t.R[r:r + 16], t.R[r + 16]
        # both act on rel = X[ring] - X[ring[0]]: column 0 is ring[0], whose weight is the rest (below)
        nz = 1 + np.flatnonzero(((dev[:, 1:] != 0.0).any(axis=0)) | (org[1:] != 0.0))
        return np.ascontiguousarray(dev[:, nz]), org[nz].copy(), np.concatenate([[0], nz])


def _topology(S):
    cache = S.__dict__.get("_basis_topology")
    if cache is None or cache[0] is not S._groups:
        cache = S._basis_topology = (S._groups, _Topology(S))
    return cache[1]


def _vertex_map(S, top):
    """The sparse (classified vertices x file vertices) matrix, or None where the rings index the file's vertices."""
    if S._ptex_face is None:
        return None
    if top.vertex_map is None:
        mesh = S.mesh
        man = mesh.manifold
        if man.is_all_quads:
            m = np.asarray(mesh.manifold_vertex_map, dtype=np.int64)
            top.vertex_map = sp.csr_matrix((np.ones(m.size), m, np.arange(m.size + 1)),
                                           shape=(m.size, mesh.n_vertices))
        else:
            St = sp.csr_matrix(mesh.subdivision_operator())
            St.data[~np.isfinite(St.data)] = 0.0  # an unused vertex's row (no ring holds it)
            top.vertex_map = St
    return top.vertex_map


#: (order in u, order in v) of every key
_ORDERS = {"P": (0, 0), "Du": (1, 0), "Dv": (0, 1), "Duu": (2, 0), "Duv": (1, 1), "Dvv": (0, 2)}


def _rows(name, bs, bt, h, dev, org):
    """The weights (k, len(cols)) of one operator's points for the row ``name`` (no cancellation near an
    irregular corner: the derivatives are products with the net's deviation from the limit point)."""
    a, b = _ORDERS[name]
    B = (bt[b][:, :, None] * bs[a][:, None, :]).reshape(-1, 16)  # net index 4 j + i, i along s
    if a + b:
        B *= h if a + b == 1 else h * h
    if dev is None:
        return B
    w = np.empty((B.shape[0], dev.shape[1] + 1))
    rest = w[:, 1:]
    np.matmul(B, dev, out=rest)
    if name == "P":
        rest += org
    w[:, 0] = (1.0 if name == "P" else 0.0) - rest.sum(axis=1)
    return w


def _fill_numpy(top, loc, op, indptr, names, derivatives, indices, data):
    """The reference path: the points of every operator at once, numpy products; every row sorted by
    column. Returns the number of repeated columns within rows."""
    order = np.argsort(op, kind="stable")
    ids, first = np.unique(op[order], return_index=True)
    for i, sel in zip(ids.tolist(), np.split(order, first[1:])):
        dev, org, cols = top.operator(i)
        where = (indptr[sel][:, None] + np.arange(cols.size)).reshape(-1)
        indices[where] = top.ring[top.job_ring[loc.job[sel]][:, None] + cols].reshape(-1)
        bs, bt = bspline_basis(loc.s[sel], derivatives), bspline_basis(loc.t[sel], derivatives)
        h = loc.scale[sel][:, None]
        for k, name in enumerate(names):
            data[k][where] = _rows(name, bs, bt, h, dev, org).reshape(-1)
    # every row by column (stable: repeated columns keep the ring's order, as the kernel's insertion sort)
    order = np.lexsort((indices, np.repeat(np.arange(indptr.size - 1), np.diff(indptr))))
    indices[:] = indices[order]
    for d in data:
        d[:] = d[order]
    repeat = np.zeros(indices.size, dtype=bool)
    repeat[1:] = indices[1:] == indices[:-1]
    repeat[indptr[:-1][indptr[:-1] < indices.size]] = False  # a row's first entry repeats nothing
    return int(np.count_nonzero(repeat))


class _Located(NamedTuple):
    """What the fill needs of :meth:`PatchMap.locate` (see :class:`ccproof.evaluate.patch_map.Location`)."""

    job: np.ndarray
    s: np.ndarray
    t: np.ndarray
    scale: np.ndarray


def _locate(S, top, f, u, v, kernels, nt):
    """The points' jobs, parameters and scales in their patches, and their operator keys."""
    if kernels is None:
        loc = S.patch_map.locate(f, u, v)
        key = loc.vface.astype(np.int64) * top.stride
        if loc.corner.size:
            key[loc.corner] += 1 + 3 * loc.layer + loc.code
        return _Located(loc.job, loc.s, loc.t, loc.scale), key
    T = S._table
    n = f.size
    job, key = np.empty(n, dtype=np.int64), np.empty(n, dtype=np.int64)
    s, t, scale = np.empty(n), np.empty(n), np.empty(n)
    table = (T.top, T.job_root, T.kind, T.child, T.u0, T.v0, T.h, T.cfg, T.cu, T.cv, T.n_layers, T.unit)
    out = (job, key, s, t, scale)
    in_blocks(lambda lo, hi: kernels[0](lo, hi, f, u, v, table, top.stride, out), n, nt, 32768, per_thread=4)
    return _Located(job, s, t, scale), key


def basis_rows(S, f, u, v, derivatives, backend=None, threads=None):
    """The dict of CSR matrices of :meth:`LimitSurface.basis` (natural parameterization), checked points.

    ``backend``: ``"numpy"`` (the reference: :meth:`PatchMap.locate` and numpy products per operator),
    else the numba kernels where numba is installed."""
    top = _topology(S)
    kernels = _kernel() if backend != "numpy" and f.size else None
    nt = threads_for(threads, f.size)
    loc, key = _locate(S, top, f, u, v, kernels, nt)
    op = top.operator_ids(S, key)
    cstart, ncols, dstart, cols, dev, org = top.flat()
    counts = ncols[op]
    nnz = int(counts.sum())
    M = _vertex_map(S, top)
    n_cols = S.mesh.n_vertices if M is None else M.shape[0]
    ix = np.int32 if max(nnz, n_cols) < 2**31 else np.int64  # scipy's own choice: no copies
    indptr = np.zeros(f.size + 1, dtype=ix)
    np.cumsum(counts, out=indptr[1:])
    names = BASIS_KEYS[derivatives]
    indices = np.empty(nnz, dtype=ix)
    data = [np.empty(nnz) for _ in names]  # separate arrays: scipy copies a view of a larger one
    if kernels is None:
        repeats = _fill_numpy(top, loc, op, indptr, names, derivatives, indices, data)
    else:
        pad = [data[0]] * (6 - len(names))
        pts = (loc.s, loc.t, loc.scale, op, loc.job, top.job_ring, top.grid_net, top.grid_rank)
        ops = (cstart, ncols, dstart, cols, dev, org)
        data6 = tuple(data) + tuple(pad)
        repeats = sum(in_blocks(lambda lo, hi: kernels[1](lo, hi, pts, ops, top.ring, indptr, indices, len(names),
                                                          data6), f.size, nt, 32768, per_thread=4))
    canonical = repeats == 0 and top.grid_repeats == 0  # (a repeat in any smooth job's net: conservative)
    return _matrices(names, data, indices, indptr, (f.size, n_cols), canonical, M)


def _matrices(names, data, indices, indptr, shape, canonical, M):
    """The CSR matrices of the rows (sorted by column). Canonical rows (no column twice) share one pair
    of index arrays, read-only (an in-place change of one matrix's structure, such as ``eliminate_zeros``,
    raises instead of changing the others': ``.copy()`` first); else each matrix has its own."""
    shared = canonical and len(names) > 1
    if shared:
        indices.flags.writeable = False
        indptr.flags.writeable = False
    out = {}
    for k, name in enumerate(names):
        ind, ptr = (indices, indptr) if shared or k == 0 else (indices.copy(), indptr.copy())
        W = sp.csr_matrix((data[k], ind, ptr), shape=shape)
        if canonical:
            W.has_canonical_format = True
        else:
            W.has_sorted_indices = True
        if M is not None:  # composed with the step: scipy's product, a column once per row
            W = (W @ M).tocsr()
            W.sort_indices()
        out[name] = W
    return out


def _fill_points(lo, hi, pts, ops, ring, indptr, indices, nk, data):
    """The rows of points lo..hi-1 into ``data[0 .. nk-1]`` (the numba kernel; the sums of :func:`_rows`
    point by point), every row sorted by column. ``pts = (s, t, scale, op, job, job_ring, grid_net,
    grid_rank)``: per point, then per job its ring's start and a smooth regular job's net by column and
    places (:class:`_Topology`); ``ops`` the flat operators (:meth:`_Topology.flat`). A smooth regular
    quad's row is written in one pass (:func:`_grid_row`: no operator, no cancellation, no sort). Returns
    the number of repeated columns within the other rows (the smooth quads' nets:
    :attr:`_Topology.grid_repeats`). ``data`` is indexed by constants only (a tuple indexed at run time
    is kept in memory, and every store would reload it)."""
    s, t, scale, op, job, job_ring, grid_net, grid_rank = pts
    cstart, ncols, dstart, cols, dev, org = ops
    B = np.empty(16)
    bu = np.empty((3, 4))
    bv = np.empty((3, 4))
    width = 16
    for o in range(ncols.shape[0]):
        width = max(width, ncols[o])
    place = np.empty(width, dtype=np.int64)  # a corner row's sort
    tmp = np.empty(width)
    repeats = 0
    for p in range(lo, hi):
        o = op[p]
        q = indptr[p]
        ds = dstart[o]
        _bspline(s[p], bu)
        _bspline(t[p], bv)
        g = scale[p]
        if ds < 0:  # a smooth regular quad: its net is its ring (cols 0..15), the weights are B itself
            g0 = 16 * job[p]
            _grid_row(q, grid_net[g0:g0 + 16], grid_rank[g0:g0 + 16], bu, bv, g, indices, nk, data)
            continue
        nc, c0, r0 = ncols[o], cstart[o], job_ring[job[p]]
        for c in range(nc):
            indices[q + c] = ring[r0 + cols[c0 + c]]
        row = (q, nc, ds, dev, org, bu, bv, B)
        _corner_key(row, 0, 0, 1.0, data[0])
        if nk > 1:
            _corner_key(row, 1, 0, g, data[1])
            _corner_key(row, 0, 1, g, data[2])
        if nk > 3:
            _corner_key(row, 2, 0, g * g, data[3])
            _corner_key(row, 1, 1, g * g, data[4])
            _corner_key(row, 0, 2, g * g, data[5])
        repeats += _sort_row(q, nc, indices, place)
        _permute(q, nc, place, tmp, data[0])
        if nk > 1:
            _permute(q, nc, place, tmp, data[1])
            _permute(q, nc, place, tmp, data[2])
        if nk > 3:
            _permute(q, nc, place, tmp, data[3])
            _permute(q, nc, place, tmp, data[4])
            _permute(q, nc, place, tmp, data[5])
    return repeats


def _corner_key(row, a, b, f, dk):
    """One key (order a in s, b in t, scale f) of a corner face's row: the net's deviation and limit point
    as weights of the ring's columns 1.., column 0 the rest (the sums of :func:`_rows`, point by point)."""
    q, nc, ds, dev, org, bu, bv, B = row
    for j in range(4):
        for i in range(4):
            B[4 * j + i] = bv[b, j] * bu[a, i] * f
    m = nc - 1
    tot = 0.0
    for c in range(m):
        w = 0.0
        for i in range(16):
            w += B[i] * dev[ds + i * m + c]
        if a + b == 0:
            w += org[ds // 16 + c]
        dk[q + 1 + c] = w
        tot += w
    dk[q] = (1.0 if a + b == 0 else 0.0) - tot


def _grid_row(q, net, rank, bu, bv, g, indices, nk, data):
    """The row of a point of a smooth regular quad at q..q+15: its net's vertices by column ``net``, and
    their tensor B-spline weights (net entry 4 j + i, i along s) at ``q + rank[4 j + i]``, all keys."""
    for c in range(16):
        indices[q + c] = net[c]
    g2 = g * g
    for j in range(4):
        v0, v1, v2 = bv[0, j], bv[1, j], bv[2, j]
        for i in range(4):  # (v u) g: the products of the numpy path, in its order
            k = q + rank[4 * j + i]
            data[0][k] = v0 * bu[0, i]
            if nk > 1:
                data[1][k] = v0 * bu[1, i] * g
                data[2][k] = v1 * bu[0, i] * g
            if nk > 3:
                data[3][k] = v0 * bu[2, i] * g2
                data[4][k] = v1 * bu[1, i] * g2
                data[5][k] = v2 * bu[0, i] * g2


def _sort_row(q, n, indices, place):
    """Insertion sort (stable) of the row's columns at q..q+n-1; ``place[c]``: the entry now at c came from
    q + place[c]. Returns the number of repeated columns."""
    for c in range(n):
        place[c] = c
    for c in range(1, n):
        x, e = indices[q + c], c
        while e > 0 and indices[q + e - 1] > x:
            indices[q + e] = indices[q + e - 1]
            place[e] = place[e - 1]
            e -= 1
        indices[q + e] = x
        place[e] = c
    repeats = 0
    for c in range(1, n):
        if indices[q + c] == indices[q + c - 1]:
            repeats += 1
    return repeats


def _permute(q, n, place, tmp, dk):
    """``dk[q + c] = dk[q + place[c]]`` for c < n (the sort of :func:`_sort_row`)."""
    for c in range(n):
        tmp[c] = dk[q + place[c]]
    for c in range(n):
        dk[q + c] = tmp[c]


def _locate_points(lo, hi, f, u, v, table, stride, out):
    """:meth:`PatchMap.locate` of points lo..hi-1 (the same exact operations), and their operator keys:
    ``table`` the patch table's topology arrays, ``out = (job, key, s, t, scale)``."""
    top, job_root, kind, child, u0, v0, h, cfg, cu, cv, n_layers, unit = table
    job, key, s, t, scale = out
    for p in range(lo, hi):
        x, y = u[p], v[p]
        jb = top[f[p], (1 if x >= 0.5 else 0) + (2 if y >= 0.5 else 0)]
        vf = job_root[jb]
        while kind[vf] == 2:  # split: descend
            half = h[vf] * 0.5
            vf = child[vf, (1 if x >= u0[vf] + half else 0) + (2 if y >= v0[vf] + half else 0)]
        pu0, pv0, hh, k = u0[vf], v0[vf], h[vf], vf * stride
        if kind[vf] == 1:
            U0, V0, H = u0[vf], v0[vf], h[vf]
            du = ((U0 + H) - x if cu[vf] else x - U0) / H
            dv = ((V0 + H) - y if cv[vf] else y - V0) / H
            mx = max(du, dv)
            c = cfg[vf]
            nmax = n_layers[c] - 1
            n = nmax
            if mx > 0:
                n = min(max(-math.frexp(mx)[1], 0), nmax)
            du, dv = math.ldexp(du, n), math.ldexp(dv, n)
            a, b = du >= 0.5, dv >= 0.5
            code = 0 if (a and not b) else (1 if (a and b) else (2 if b else 1))
            sc = math.ldexp(H, -n)
            pu0 = unit[c, code, 0] * sc + ((U0 + H) if cu[vf] else U0)
            pv0 = unit[c, code, 1] * sc + ((V0 + H) if cv[vf] else V0)
            hh = unit[c, code, 2] * sc
            k += 1 + 3 * n + code
        job[p], key[p] = jb, k
        s[p] = min(max((x - pu0) / hh, 0.0), 1.0)
        t[p] = min(max((y - pv0) / hh, 0.0), 1.0)
        scale[p] = 1.0 / hh


def _bspline(x, out):
    """Cubic B-spline values, first and second derivatives at x into ``out`` (3, 4) (:func:`bspline_basis`)."""
    t = 1.0 - x
    x2 = x * x
    x3 = x2 * x
    out[0, 0], out[0, 1], out[0, 2], out[0, 3] = t * t * t / 6, (3 * x3 - 6 * x2 + 4) / 6, \
        (-3 * x3 + 3 * x2 + 3 * x + 1) / 6, x3 / 6
    out[1, 0], out[1, 1], out[1, 2], out[1, 3] = -0.5 * t * t, 1.5 * x2 - 2 * x, -1.5 * x2 + x + 0.5, 0.5 * x2
    out[2, 0], out[2, 1], out[2, 2], out[2, 3] = t, 3 * x - 2, -3 * x + 1, x


_KERNEL = []


def _kernel():
    """The numba kernels ``(locate, fill)`` (compiled once, cached on disk), or None without numba."""
    if not _KERNEL:
        try:
            import numba
        except ImportError:  # pragma: no cover - numba is a dependency
            _KERNEL.append(None)
        else:
            global _bspline, _grid_row, _corner_key, _sort_row, _permute
            _bspline = numba.njit(cache=True, nogil=True, inline="always")(_bspline)
            _grid_row = numba.njit(cache=True, nogil=True, inline="always")(_grid_row)
            _corner_key, _sort_row, _permute = (numba.njit(cache=True, nogil=True)(fn)
                                                for fn in (_corner_key, _sort_row, _permute))
            _KERNEL.append((numba.njit(cache=True, nogil=True)(_locate_points),
                            numba.njit(cache=True, nogil=True)(_fill_points)))
    return _KERNEL[0]
