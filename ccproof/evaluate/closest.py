"""Globally nearest points of the limit surface (float path).

:func:`closest_points` projects a batch of 3-D points ``X`` (shape (n, 3)) onto the limit surface of a
:class:`~ccproof.evaluate.LimitSurface`: for every point the parameter ``(face, u, v)`` of the nearest
limit point, the point ``P``, the distance ``|X - P|`` and the unit normal there. It needs only the
evaluator's public :meth:`~ccproof.evaluate.LimitSurface.evaluate` (and the number of parameter
faces), so it works on every mesh the evaluator accepts and on any object with that method; on the
evaluator's own surfaces (natural parameterization, compiled kernel) the Newton descents run
compiled, point by point, with the numpy descent's formulas in the same order (bit-identical
results, tests/evaluate/test_newton_compiled.py).

Method (global search, then local refinement):

1. **Cells.** Every face's parameter square is cut into ``m x m`` cells; the surface is sampled on
   the ``(2m+1)^2`` grid of cell corners, edge midpoints and centres. Each cell gets a bounding
   *cylinder* around its centre sample ``c`` with axis the normal ``n`` there: lateral radius ``r``
   and half-height ``delta`` are the largest lateral and normal offsets of the cell's 9 samples
   (the bilinear interpolant of the samples lies in their convex hull, hence in the cylinder),
   enlarged by ``SAFETY`` times the largest second difference of the samples (the interpolation
   error of a bilinear patch is at most 1/8 of the second differences). The lower bound of the
   distance from ``X`` to the cell is the distance to the cylinder,
   ``sqrt(max(rho - r, 0)^2 + max(z - delta, 0)^2)`` with ``z = |<X - c, n>|`` and ``rho`` the lateral
   offset. These bounds are sampled estimates (the rigorous counterpart, from convex hulls of control
   nets in interval arithmetic, is :mod:`ccproof.evaluate.closest_certified`).
   **One bound per face.** The structure keeps, per face, a cylinder holding all its cells' cylinders
   (:func:`~ccproof.evaluate.closest_cells.enclosing_cylinders`: its lower bound never exceeds theirs), a
   bounding-volume hierarchy over them (:mod:`ccproof.evaluate._bvh`) and a k-d tree of face centres: about
   ``FACE_BYTES`` per face. The samples are dropped after the build; a face's cells are computed again (the
   same bits) when a query reaches it, and cached (``CACHE_CELLS`` at most). :func:`search_memory` estimates the peak.
2. **First descent.** From the cell centre nearest to X in the face of the nearest face centre; the
   projected Newton iteration below gives an upper bound ``d*`` of the distance.
3. **Pruning.** The faces whose bound is below ``d*``, then their cells whose bound is below ``d*``, are
   the candidates (the same cells as a search over all cells). A candidate is
   *covered* once a descent in its face started in it or ended within ``cover`` cells of it
   (default 3); uncovered candidates start new descents, best first (per round one descent per
   point, from its open candidate of lowest bound), until every candidate is covered or its bound
   exceeds the best distance found. A descent whose result is a new best on an edge of its face is
   *handed off* to the face on the other side: a new descent starts from the sample of another face
   nearest to the end point (the faces whose bound is near the end point are sampled), so minima
   next to face edges and corners are reached from both sides without any adjacency information.
   The answer is the best of all descents.
4. **Projected Newton** (:func:`ccproof.evaluate.newton.newton_descent`) on ``E(u, v) = |P(u, v) - X|^2 / 2``
   in ``[0, 1]^2``, backtracked so that ``E`` never increases, also next to extraordinary vertices.

The normal is the surface's own (:meth:`~ccproof.evaluate.LimitSurface.normals`: ``P_u x P_v / |P_u x P_v|``,
and at an extraordinary corner the exact tangent plane of its subdivision matrix), or ``P_u x P_v`` normalized
for a surface that has only ``evaluate``.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from ccproof.errors import CCProofError
from ccproof.evaluate import _bvh
from ccproof.evaluate.closest_cells import CellCache, enclosing_cylinders, morton_order
from ccproof.evaluate.newton import newton_descent, row_dot, unit_normal

__all__ = ["ClosestPoints", "ClosestPointFinder", "closest_points", "parameter_faces", "search_memory"]

#: cells per face side
CELLS = 8
#: a descent covers the candidate cells within this many cells of its end (and its start cell)
COVER = 3
#: enlargement of the sampled cell bounds, in units of the largest second difference of the samples
SAFETY = 2.0
#: rounds of descents at most (each runs one descent per point still open)
MAX_ROUNDS = 64
#: hand-offs across face edges at most per point
MAX_HANDOFFS = 4
#: points per chunk
CHUNK = 1 << 13
#: samples per evaluation while the face bounds are built or faces refined (bounds the transient memory)
BATCH_SAMPLES = 1 << 17
#: cells of refined faces kept for later queries at most (64 bytes each; emptied when full)
CACHE_CELLS = 1 << 20
#: bytes per searched face the structure holds at its peak (face cylinders, hierarchy, k-d tree of face centres, the
#: cache's slot): 222 measured at 245,760 faces (``python scripts/bench_project.py --memory --levels 6``)
FACE_BYTES = 250
#: bytes per cell in the cache (centre, axis, radius, half-height)
CELL_BYTES = 64
#: transient bytes per sample evaluated at once (positions, derivatives, parameters, the evaluator's work arrays)
SAMPLE_BYTES = 400
#: relative enlargement of d* against the face bounds (a face bound may exceed its cells' by round-off)
FACE_SLACK = 1e-10


def parameter_faces(surface):
    """Number of parameter faces (ptex faces) of ``surface``: face ids are ``0 .. parameter_faces - 1``.

    ``surface``: anything with ``n_ptex_faces`` / ``n_param_faces``, or a ``mesh`` with ``n_ptex_faces``,
    ``n_ptex`` or ``n_faces`` (a quad one parameter face, an n-gon n: OpenSubdiv's ptex convention,
    docs/evaluate.md "Conventions"); :class:`CCProofError` if it says none of these.

    >>> from ccproof.evaluate import limit_surface
    >>> from ccproof.mesh.examples import cube
    >>> parameter_faces(limit_surface(cube()))
    6
    """
    for name in ("n_ptex_faces", "n_param_faces"):
        n = getattr(surface, name, None)
        if n is not None:
            return int(n)
    mesh = getattr(surface, "mesh", None)
    for name in ("n_ptex_faces", "n_ptex", "n_faces"):  # a PolyMesh's n_faces counts polygons, not ptex faces
        n = getattr(mesh, name, None)
        if n is not None:
            return int(n)
    raise CCProofError("the surface does not say how many parameter faces it has")


def search_memory(n_faces, cells=CELLS):
    """Estimated peak bytes of a :class:`ClosestPointFinder` over ``n_faces`` faces (before any work).

    ``FACE_BYTES`` per face, the cell cache (at most ``CACHE_CELLS`` cells, or one face's ``cells^2``, of
    ``CELL_BYTES``) and the samples evaluated at once (``BATCH_SAMPLES``, or one face's ``(2 cells + 1)^2``,
    of ``SAMPLE_BYTES``); the surface's own table is not counted.

    >>> round(search_memory(245760) / 1e6)  # a 81,920-triangle scan (3 ptex faces per triangle)
    181
    >>> round(search_memory(2036, cells=100000) / 1e9)  # one face's 200001^2 samples at once
    16640
    """
    mm = cells * cells
    cache = min(n_faces * mm, max(CACHE_CELLS, mm)) * CELL_BYTES
    return n_faces * FACE_BYTES + cache + max(BATCH_SAMPLES, (2 * cells + 1) ** 2) * SAMPLE_BYTES


@dataclass
class ClosestPoints:
    """Result of :func:`closest_points` for n points.

    Attributes
    ----------
    face : ndarray of int64, shape (n,)
        Parameter (ptex) face of the nearest limit point.
    u, v : ndarray, shape (n,)
        Its parameter in the face, in [0, 1].
    P : ndarray, shape (n, 3)
        The nearest limit point.
    distance : ndarray, shape (n,)
        ``|X - P|``.
    normal : ndarray, shape (n, 3)
        Unit normal at (face, u, v): the surface's ``normals`` (exact at extraordinary corners), else
        ``P_u x P_v / |P_u x P_v|``.
    descents : ndarray of int32, shape (n,)
        Number of Newton descents run for the point (1 when the first one was provably best
        among the candidate cells).

    Notes
    -----
    The float path of docs/closest.md ("Float path: method"); no certificate (see
    :func:`ccproof.evaluate.closest_certified.certify_closest`).

    Examples
    --------
    A point of the torus's limit surface is its own nearest point:

    >>> from ccproof.evaluate import limit_surface
    >>> from ccproof.mesh.examples import torus
    >>> S = limit_surface(torus())
    >>> X = S.evaluate([5], [0.25], [0.75])["P"]
    >>> res = closest_points(S, X, cells=4)
    >>> isinstance(res, ClosestPoints), res.face.tolist(), res.u.tolist(), res.v.tolist()
    (True, [5], [0.25], [0.75])
    >>> bool(res.distance[0] < 1e-12)
    True
    """

    face: np.ndarray
    u: np.ndarray
    v: np.ndarray
    P: np.ndarray
    distance: np.ndarray
    normal: np.ndarray
    descents: np.ndarray


class ClosestPointFinder:
    """Reusable search structure for :func:`closest_points` on one surface.

    Parameters
    ----------
    surface : LimitSurface
    cells : int
        Cells per face side (``cells^2`` bounding cylinders per face from ``(2 cells + 1)^2`` samples,
        computed when a query needs them; the structure keeps one cylinder per face).
    cover : int, optional
        A descent in a face covers its start cell and the candidate cells of that face within
        ``cover`` cells of its end cell (default ``COVER``; ``cover >= cells``: the whole face, i.e.
        one descent per point and face, faster but it misses a second local minimum in a face).
    faces : array_like of int, optional
        Search only these parameter faces (default: all); e.g. the faces that carry a patch of a
        finite-element model (ccproof.apps.dynamics). The answers lie on these faces only.
    progress : bool, optional
        A progress bar (tqdm, on stderr) over the faces while the bounds are built.

    Notes
    -----
    One bounding cylinder per face (enclosing its cells' cylinders), a hierarchy over them and a k-d
    tree of face centres; the cells of a face are computed again when a query reaches it (a cache of
    ``CACHE_CELLS`` cells). docs/closest.md "Float path: method"; :meth:`query` answers like
    :func:`closest_points`; :meth:`nbytes` is the memory the structure keeps.

    Examples
    --------
    >>> from ccproof.evaluate import limit_surface
    >>> from ccproof.mesh.examples import torus
    >>> S = limit_surface(torus())
    >>> finder = ClosestPointFinder(S, cells=4)
    >>> X = S.evaluate([5, 30], [0.25, 0.5], [0.75, 0.125])["P"]
    >>> res = finder.query(X)
    >>> res.face.tolist(), res.u.round(12).tolist(), res.v.round(12).tolist(), bool(res.distance.max() < 1e-12)
    ([5, 30], [0.25, 0.5], [0.75, 0.125], True)
    """

    def __init__(self, surface, cells=CELLS, cover=None, faces=None, progress=False):
        from scipy.spatial import cKDTree

        if int(cells) != cells or cells < 1:
            raise CCProofError(f"cells must be a positive integer, got {cells!r}")
        self.surface = surface
        self.m = m = int(cells)
        self._mm = m * m
        self.cover = min(COVER, m) if cover is None else int(cover)
        nall = parameter_faces(surface)
        if faces is None:
            sel = np.arange(nall)
        else:
            sel = np.unique(np.asarray(faces).reshape(-1))
            if sel.size == 0 or not np.issubdtype(sel.dtype, np.integer) or sel[0] < 0 or sel[-1] >= nall:
                raise CCProofError(f"faces must be a non-empty list of parameter faces in [0, {nall})")
            sel = sel.astype(np.int64)
        self.faces = sel
        self.n_faces = nall
        t = np.arange(2 * m + 1) / (2 * m)
        U, V = np.meshgrid(t, t, indexing="ij")  # [i along u, j along v]
        self._U, self._V = U.ravel(), V.ravel()
        self._eps = 0.0  # the face bounds enclose the cells' bounds without it; added below
        self._cache = CellCache(self.faces.size, self._mm, max(1, min(CACHE_CELLS // self._mm, self.faces.size)),
                                self._refined_blocks)
        fc, fn, fr, fh, scale = self._face_bounds(progress)
        self._eps = 1e-13 * scale  # added to every cell's radius and half-height: round-off of the samples
        self._cache.r += self._eps
        self._cache.h += self._eps
        self._tiny = 1e-12 * scale
        fr += 2.0 * self._eps
        fh += 2.0 * self._eps
        self._fc, self._fn, self._fr, self._fh = fc, fn, fr, fh
        self._bvh = _bvh.build(fc, np.hypot(fr, fh))
        # face centres, for the first descent (unbalanced, non-compact nodes: faster for far points)
        self._ftree = cKDTree(fc, balanced_tree=False, compact_nodes=False)

    def nbytes(self):
        """Bytes the structure keeps (face cylinders, hierarchy, k-d tree estimate, cell cache now)."""
        arrays = [self.faces, self._fc, self._fn, self._fr, self._fh, *self._bvh]  # (the cache: up to 64 CACHE_CELLS)
        kd = self._fc.nbytes + 8 * self.faces.size + 64 * (self.faces.size // 8 + 1)  # data, indices, nodes
        return int(sum(a.nbytes for a in arrays) + kd + self._cache.nbytes())

    # ------------------------------------------------------------------ bounds
    def _refine(self, pos):
        """Samples (k, 2m + 1, 2m + 1, 3) and cell cylinders ``(c, n, r, h)`` of the faces ``faces[pos]``."""
        g2, k, g = self._U.size, pos.size, 2 * self.m + 1
        r = self.surface.evaluate(np.repeat(self.faces[pos], g2), np.tile(self._U, k), np.tile(self._V, k), 1)
        grid = (k, g, g, 3)
        P = r["P"].reshape(grid)
        c, n, rr, h = _bvh.cell_bounds(P, r["Pu"].reshape(grid), r["Pv"].reshape(grid), self.m, SAFETY, 0.0)
        return P, (c, n, rr + self._eps, h + self._eps)  # (the same bits whether built or refined later)

    def _blocks(self, n):
        """Ranges of at most ``BATCH_SAMPLES`` samples' faces covering ``0 .. n - 1``."""
        step = max(1, BATCH_SAMPLES // self._U.size)
        return [np.arange(lo, min(n, lo + step)) for lo in range(0, n, step)]

    def _refined_blocks(self, pos):
        """The faces ``pos`` in blocks with their cells: ``(block, (c, n, r, h))``."""
        for blk in self._blocks(pos.size):
            yield pos[blk], self._refine(pos[blk])[1]

    def _face_bounds(self, progress):
        """One cylinder per face enclosing its cells' cylinders (samples computed in blocks and dropped; a
        bar on stderr if ``progress``); returns centres, axes, radii, half-heights and the largest sample
        coordinate."""
        nf, m = self.faces.size, self.m
        bar = None
        if progress:
            import sys

            from tqdm import tqdm

            bar = tqdm(total=nf, desc="search structure", unit="face", file=sys.stderr)
        fc, fn, fr, fh = np.empty((nf, 3)), np.empty((nf, 3)), np.empty(nf), np.empty(nf)
        scale = 0.0
        for pos in self._blocks(nf):
            P, (c, n, r, h) = self._refine(pos)
            scale = max(scale, float(np.abs(P).max()))
            fc[pos], fn[pos], fr[pos], fh[pos] = enclosing_cylinders(P[:, m, m], c, n, r, h, self._mm)
            if self._cache.capacity == nf:  # every face fits the cache: its cells are kept (eps added after)
                self._cache.store(pos, c, n, r, h)
            if bar is not None:
                bar.update(pos.size)
        if bar is not None:
            bar.close()
        return fc, fn, fr, fh, (scale if nf else 1.0)

    def lower_bounds(self, X, faces):
        """Lower bounds of the distance from points ``X`` (n, 3) to the faces at positions ``faces`` (n,)
        of :attr:`faces` (their enclosing cylinders)."""
        w = X - self._fc[faces]
        z = np.abs(row_dot(w, self._fn[faces]))
        rho = np.sqrt(np.maximum(row_dot(w, w) - z * z, 0.0))
        return np.hypot(np.maximum(rho - self._fr[faces], 0.0), np.maximum(z - self._fh[faces], 0.0))

    def _face_candidates(self, X, dstar):
        """Pairs (point, face position) whose face bound is below d* (enlarged by its round-off)."""
        pid, pos, _ = _bvh.candidates(X, dstar * (1.0 + FACE_SLACK) + self._tiny, self._bvh, self._fc, self._fn,
                                      self._fr, self._fh)
        return pid, pos

    def _candidates(self, X, dstar):
        """Pairs (point, cell) with cell lower bound < d*: arrays pid, cid, lb (cell ``cid`` is cell
        ``cid % cells^2`` of the face at position ``cid // cells^2``)."""
        pid, pos = self._face_candidates(X, dstar)
        order = np.argsort(pos, kind="stable")
        pid, pos = pid[order], pos[order]
        parts = []
        ufaces = np.unique(pos)
        for blk in np.array_split(ufaces, -(-ufaces.size // self._cache.capacity) if ufaces.size else 1):
            if blk.size == 0:
                continue
            a, b = np.searchsorted(pos, [blk[0], blk[-1] + 1])
            slot = self._cache.ensure(pos[a:b])
            parts.append(_bvh.expand_cells(X, dstar, pid[a:b], pos[a:b], slot, self._cache.cells(), self._mm))
        if not parts:
            e = np.empty(0, dtype=np.int64)
            return e, e.copy(), np.empty(0)
        return tuple(np.concatenate(x) for x in zip(*parts))

    def _starts(self, X):
        """First descents: from the cell centre nearest to X among all faces' cells (the faces whose bound is
        closer than the nearest cell centre of the face of the nearest face centre)."""
        n = X.shape[0]
        _, j = self._ftree.query(X, k=1)
        best, cid = np.full(n, np.inf), np.zeros(n, dtype=np.int64)
        self._nearest_cells(X, np.arange(n), np.asarray(j, dtype=np.int64), best, cid)
        pid, pos = self._face_candidates(X, np.sqrt(best))
        self._nearest_cells(X, pid, pos, best, cid)
        return cid

    def _nearest_cells(self, X, pid, pos, best, cid):
        """Update ``best`` (squared distance) and ``cid`` (cell) of the points ``pid`` with the cell centres of
        the faces at ``pos`` (pairs aligned), in blocks of faces that fit the cache."""
        order = np.argsort(pos, kind="stable")
        pid, pos = pid[order], pos[order]
        ufaces = np.unique(pos)
        mm = self._mm
        for blk in np.array_split(ufaces, -(-ufaces.size // self._cache.capacity) if ufaces.size else 1):
            if blk.size == 0:
                continue
            a, b = np.searchsorted(pos, [blk[0], blk[-1] + 1])
            p, slot = pid[a:b], self._cache.ensure(pos[a:b])
            k, dk = _bvh.nearest_centres(X, p, slot, self._cache.c, mm)
            o = np.lexsort((pos[a:b] * mm + k, dk, p))  # per point its nearest pair first (ties: lowest cell)
            first = o[np.r_[True, p[o[1:]] != p[o[:-1]]]]
            upd = first[dk[first] < best[p[first]]]
            best[p[upd]] = dk[upd]
            cid[p[upd]] = pos[a + upd] * mm + k[upd]

    def _cell(self, cid):
        """Face, ci, cj of cell ids."""
        f = cid // self._mm
        return self.faces[f], (cid // self.m) % self.m, cid % self.m

    # ------------------------------------------------------------------ query
    def query(self, X, *, chunk=CHUNK):
        """Nearest limit points of ``X`` (n, 3); returns :class:`ClosestPoints`."""
        X = check_query_points(X)
        n = X.shape[0]
        out = ClosestPoints(
            np.empty(n, dtype=np.int64), np.empty(n), np.empty(n), np.empty((n, 3)), np.empty(n),
            np.empty((n, 3)), np.empty(n, dtype=np.int32),
        )
        order = morton_order(X)  # nearby points in the same chunk: fewer faces refined, more found in the cache
        for lo in range(0, n, chunk):
            idx = order[lo:lo + chunk]
            f, u, v, nd = self._query_chunk(X[idx])
            out.face[idx], out.u[idx], out.v[idx], out.descents[idx] = f, u, v, nd
        r = self.surface.evaluate(out.face, out.u, out.v, 1)
        out.P[:] = r["P"]
        out.distance[:] = np.linalg.norm(X - r["P"], axis=1)
        normals = getattr(self.surface, "normals", None)  # exact at an irregular corner (its tangent masks)
        out.normal[:] = unit_normal(r["Pu"], r["Pv"]) if normals is None else normals(out.face, out.u, out.v)
        _warn_undefined_normals(out)
        return out

    __call__ = query

    def _query_chunk(self, X):
        n = X.shape[0]
        m = self.m
        # starts of the current round: point, face, (u, v)
        sp = np.arange(n)
        sf, ci, cj = self._cell(self._starts(X))
        su, sv = (ci + 0.5) / m, (cj + 0.5) / m
        bf = np.zeros(n, dtype=np.int64)
        bu, bv, bE = np.zeros(n), np.zeros(n), np.full(n, np.inf)
        ndesc = np.zeros(n, dtype=np.int32)
        handoffs = np.zeros(n, dtype=np.int32)
        pid = None
        for _round in range(MAX_ROUNDS + 1):
            nu, nv, nE = newton_descent(self.surface, X[sp], sf, su, sv)
            np.add.at(ndesc, sp, 1)
            # best per point among this round's descents, then against the best so far
            order = np.lexsort((nE, sp))
            first = order[np.r_[True, sp[order[1:]] != sp[order[:-1]]]] if sp.size else order
            better = first[nE[first] < bE[sp[first]]]
            q = sp[better]
            bf[q], bu[q], bv[q], bE[q] = sf[better], nu[better], nv[better], nE[better]
            if pid is None:
                pid, cid, lb = self._candidates(X, np.sqrt(2.0 * bE))
                order = np.lexsort((cid, lb, pid))  # sorted by point, then bound (kept by every compression)
                pid, cid, lb = pid[order], cid[order], lb[order]
                covered = np.zeros(pid.size, dtype=bool)
            # coverage: every descent covers its start cell and the cells near its end, in its face
            for grp in self._one_per_point(sp):
                rf = np.full(n, -1, dtype=np.int64)
                ri = np.zeros((4, n), dtype=np.int64)
                g = grp
                rf[sp[g]] = sf[g]
                ri[0, sp[g]], ri[1, sp[g]] = self._cell_of(su[g]), self._cell_of(sv[g])
                ri[2, sp[g]], ri[3, sp[g]] = self._cell_of(nu[g]), self._cell_of(nv[g])
                covered |= self._covered_by(pid, cid, rf[pid], *ri[:, pid])
            # hand-off across face edges: a new best on an edge of its face continues in the face on
            # the other side, from the sample there nearest to the end point (found geometrically)
            edge = (bu[q] == 0.0) | (bu[q] == 1.0) | (bv[q] == 0.0) | (bv[q] == 1.0)
            hq = q[edge & (handoffs[q] < MAX_HANDOFFS)]
            hf, hu, hv, hp = self._across(hq, bf[hq], bu[hq], bv[hq])
            handoffs[hp] += 1
            keep = ~covered & (lb < np.sqrt(2.0 * bE[pid]))
            pid, cid, lb, covered = pid[keep], cid[keep], lb[keep], covered[keep]
            if (pid.size == 0 and hp.size == 0) or _round == MAX_ROUNDS:
                break
            # best first: one descent per point from its open candidate of lowest bound
            first = np.flatnonzero(np.r_[True, pid[1:] != pid[:-1]]) if pid.size else np.zeros(0, dtype=np.int64)
            cp, (cf, ci, cj) = pid[first], self._cell(cid[first])
            sp = np.concatenate([cp, hp])
            sf = np.concatenate([cf, hf])
            su = np.concatenate([(ci + 0.5) / m, hu])
            sv = np.concatenate([(cj + 0.5) / m, hv])
        return bf, bu, bv, ndesc

    @staticmethod
    def _one_per_point(sp):
        """Split indices of ``sp`` into groups with each point at most once."""
        if sp.size == 0:
            return []
        order = np.argsort(sp, kind="stable")
        s = sp[order]
        start = np.r_[0, np.flatnonzero(s[1:] != s[:-1]) + 1]
        rank = np.arange(s.size) - np.repeat(start, np.diff(np.r_[start, s.size]))
        return [order[rank == r] for r in range(int(rank.max()) + 1)]

    def _across(self, p, f, u, v):
        """For end points (f, u, v) on a face edge: the nearest sample of another face (points p).

        The faces whose bound holds the end point P (its neighbours across the edge among them) give a
        sample of another face at distance delta; then every face whose bound is within delta of P is
        sampled, and the nearest sample of a face other than f wins."""
        e = np.empty(0, dtype=np.int64)
        if p.size == 0:
            return e, np.empty(0), np.empty(0), e
        P = self.surface.evaluate(f, u, v, 0)["P"]
        best = np.full(p.size, np.inf)
        arg = np.full((p.size, 2), -1, dtype=np.int64)  # (face position, sample)
        for ds in (np.zeros(p.size), None):
            ds = best if ds is None else ds
            live = np.isfinite(ds) if ds is best else np.ones(p.size, dtype=bool)
            q, pos = self._face_candidates(P[live], ds[live])
            q = np.flatnonzero(live)[q]
            other = self.faces[pos] != f[q]
            self._nearest_samples(P, q[other], pos[other], best, arg)
        has = arg[:, 0] >= 0
        pos, k = arg[has, 0], arg[has, 1]
        return self.faces[pos], self._U[k], self._V[k], p[has]

    def _nearest_samples(self, P, q, pos, best, arg):
        """Update ``best`` (distance) and ``arg`` (face position, sample) of points ``P[q]`` with the samples
        of the faces at ``pos`` (pairs aligned)."""
        order = np.argsort(pos, kind="stable")
        q, pos = q[order], pos[order]
        ufaces = np.unique(pos)
        for blk in self._blocks(ufaces.size):
            a, b = np.searchsorted(pos, [ufaces[blk[0]], ufaces[blk[-1]] + 1])
            S, _ = self._refine(ufaces[blk])
            loc = np.searchsorted(ufaces[blk], pos[a:b])
            d = np.linalg.norm(S.reshape(blk.size, -1, 3)[loc] - P[q[a:b], None, :], axis=2)
            k = np.argmin(d, axis=1)
            dk = d[np.arange(k.size), k]
            qq = q[a:b]
            o = np.lexsort((dk, qq))  # per point, its nearest pair first
            first = o[np.r_[True, qq[o[1:]] != qq[o[:-1]]]]
            upd = first[dk[first] < best[qq[first]]]
            best[qq[upd]] = dk[upd]
            arg[qq[upd], 0], arg[qq[upd], 1] = pos[a + upd], k[upd]

    def _cell_of(self, t):
        return np.minimum((np.asarray(t) * self.m).astype(np.int64), self.m - 1)

    def _covered_by(self, pid, cid, rf, si, sj, ei, ej):
        """Candidates (pid, cid) in the face ``rf`` of a descent of the same point, within one cell of
        its start cell (si, sj) or its end cell (ei, ej) (all arrays aligned with pid)."""
        cf, ci, cj = self._cell(cid)
        same = cf == rf
        if self.cover >= self.m:
            return same
        c = self.cover
        near = ((ci == si) & (cj == sj)) | ((np.abs(ci - ei) <= c) & (np.abs(cj - ej) <= c))
        return same & near


#: largest coordinate magnitude of a query point: the squared distances of the search must stay finite
#: in float64 (1e150^2 = 1e300 < 1.8e308); farther points would give an infinite distance to every cell
MAX_COORDINATE = 1e150


def check_query_points(X):
    """``X`` as a float (n, 3) array; refuses non-finite and too large coordinates, naming the point.

    >>> check_query_points([[0.0, 1e200, 0.0]])  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ccproof.errors.CCProofError: point 0: coordinates [0.0, 1e+200, 0.0] exceed 1e+150 in magnitude ...
    """
    X = np.asarray(X, dtype=np.float64)
    if X.ndim != 2 or X.shape[1] != 3:
        raise CCProofError(f"points must have shape (n, 3), got {X.shape}")
    bad = np.flatnonzero(~np.isfinite(X).all(axis=1))
    if bad.size:
        raise CCProofError(f"point {int(bad[0])}: coordinates {X[bad[0]].tolist()} are not finite")
    bad = np.flatnonzero((np.abs(X) > MAX_COORDINATE).any(axis=1))
    if bad.size:
        raise CCProofError(f"point {int(bad[0])}: coordinates {X[bad[0]].tolist()} exceed {MAX_COORDINATE:g} in "
                           "magnitude (squared distances overflow); scale the data")
    return X


class UndefinedNormalWarning(UserWarning):
    """A nearest point where Pu x Pv = 0 (a face of zero area there): its normal is NaN."""


def _warn_undefined_normals(res):
    """Warn (:class:`UndefinedNormalWarning`), naming the first point and its face, when some normals are
    NaN; the distances and points stay valid."""
    bad = np.flatnonzero(~np.isfinite(res.normal).all(axis=1))
    if bad.size:
        i = int(bad[0])
        warnings.warn(f"{bad.size} nearest point(s) have no normal (NaN): Pu x Pv = 0 there, a face of zero area; "
                      f"first: point {i} on face {int(res.face[i])} at (u, v) = ({res.u[i]:.6g}, {res.v[i]:.6g})",
                      UndefinedNormalWarning, stacklevel=3)


def closest_points(surface, X, *, cells=CELLS, cover=None, faces=None, finder=None):
    """Globally nearest limit points of ``X`` (shape (n, 3)) on ``surface``.

    Parameters
    ----------
    surface : LimitSurface
    X : array_like, shape (n, 3)
    cells, cover : int
        Cells per face side of the search structure, covering radius of a descent in cells
        (default ``COVER``); see :class:`ClosestPointFinder`.
    faces : array_like of int, optional
        Search only these parameter faces (default: all).
    finder : ClosestPointFinder, optional
        A prepared search structure to reuse (then ``surface`` and ``cells`` are ignored).

    Returns
    -------
    ClosestPoints
        ``face``, ``u``, ``v``, ``P`` (n, 3), ``distance`` (n,), ``normal`` (n, 3), ``descents``.

    Examples
    --------
    >>> from ccproof.evaluate import limit_surface
    >>> from ccproof.mesh.examples import cube
    >>> S = limit_surface(cube())
    >>> res = closest_points(S, [[0.0, 0.0, 2.0]])
    >>> round(float(res.distance[0] * 81), 9), round(float(res.P[0, 2] * 81), 9)  # top face centre, z = 68/81
    (94.0, 68.0)
    """
    if finder is None:
        if not hasattr(surface, "evaluate"):
            raise CCProofError(f"closest_points takes a limit surface (ccproof.limit_surface(mesh)), "
                               f"not {type(surface).__name__}")
        finder = ClosestPointFinder(surface, cells=cells, cover=cover, faces=faces)
    return finder.query(X)
