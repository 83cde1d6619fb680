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
2. **First descent.** A k-d tree (scipy ``cKDTree``) over the cell centres gives the nearest one;
   the projected Newton iteration below from it gives an upper bound ``d*`` of the distance.
3. **Pruning.** The cells whose lower bound is below ``d*`` are the candidates, listed by a
   bounding-volume hierarchy over the cells (:mod:`ccproof.evaluate._bvh`). A candidate is
   *covered* once a descent in its face started in it or ended within ``cover`` cells of it
   (default 3); uncovered candidates start new descents, best first (per round one descent per
   point, from its open candidate of lowest bound), until every candidate is covered or its bound
   exceeds the best distance found. A descent whose result is a new best on an edge of its face is
   *handed off* to the face on the other side: a new descent starts from the sample of another face
   nearest to the end point (a k-d tree over the samples, queried with surface points), so minima
   next to face edges and corners are reached from both sides without any adjacency information.
   The answer is the best of all descents.
4. **Projected Newton** (:mod:`ccproof.evaluate.newton`) on ``E(u, v) = |P(u, v) - X|^2 / 2`` in ``[0, 1]^2``: gradient
   ``(<P_u, R>, <P_v, R>)``, Hessian ``J^T J + <P_ww, R>`` (``R = P - X``); variables at a bound with
   the gradient pushing outwards are frozen (minima on face edges and corners, boundaries); an
   indefinite Hessian is replaced by ``J^T J`` plus a Levenberg term; every step is backtracked
   (Armijo) so ``E`` never increases, and the iteration stops after ``MAX_ITER`` steps at the latest.
   Near an extraordinary vertex the natural parameterization is singular at the corner (derivatives
   tend to 0 for valence 3 and to infinity for valence >= 5); there the clipping at the face's
   corner and the backtracking still give a monotone descent, and the evaluator's self-similar
   layers keep the derivatives exact down to ``2^-60`` of the corner, so Newton converges (linearly
   in the last layers at worst) to the corner or to the nearby minimum.

The normal is ``P_u x P_v / |P_u x P_v|`` at the answer (at a face corner that is an
extraordinary vertex this is the normal of the innermost stored layer, which converges to the
limit normal).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from ccproof.errors import CCProofError
from ccproof.evaluate import _bvh
from ccproof.evaluate.newton import newton, row_dot, unit_normal

__all__ = ["ClosestPoints", "ClosestPointFinder", "closest_points", "parameter_faces"]

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
CHUNK = 1 << 16


def parameter_faces(surface):
    """Number of parameter faces (ptex faces) of ``surface``: face ids are ``0 .. parameter_faces - 1``.

    Parameters
    ----------
    surface : LimitSurface
        Anything with ``n_ptex_faces`` / ``n_param_faces``, or a ``mesh`` with ``n_ptex_faces``,
        ``n_ptex`` or ``n_faces``.

    Returns
    -------
    int
        A quad mesh has one parameter face per face; a polygon of n != 4 sides has n (OpenSubdiv's
        ptex convention, docs/evaluate.md "Conventions").

    Raises
    ------
    CCProofError
        If ``surface`` says none of these.

    Examples
    --------
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
        Unit normal ``P_u x P_v / |P_u x P_v|`` at (face, u, v).
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
        Cells per face side (``cells^2`` bounding cylinders per face, ``(2 cells + 1)^2`` samples).
    cover : int, optional
        A descent in a face covers its start cell and the candidate cells of that face within
        ``cover`` cells of its end cell (default ``COVER``; ``cover >= cells``: the whole face, i.e.
        one descent per point and face, faster but it misses a second local minimum in a face).
    faces : array_like of int, optional
        Search only these parameter faces (default: all); e.g. the faces that carry a patch of a
        finite-element model (ccproof.apps.dynamics). The answers lie on these faces only.

    Notes
    -----
    Bounding cylinders per cell and a k-d tree of samples, docs/closest.md "Float path: method";
    :meth:`query` answers like :func:`closest_points`.

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

    def __init__(self, surface, cells=CELLS, cover=None, faces=None):
        from scipy.spatial import cKDTree

        if int(cells) != cells or cells < 1:
            raise CCProofError(f"cells must be a positive integer, got {cells!r}")
        self.surface = surface
        self.m = m = int(cells)
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
        nf = sel.size
        self.n_faces = nall
        g = 2 * m + 1
        t = np.arange(g) / (2 * m)
        U, V = np.meshgrid(t, t, indexing="ij")  # [i along u, j along v]
        fu = np.repeat(sel, g * g)
        r = surface.evaluate(fu, np.tile(U.ravel(), nf), np.tile(V.ravel(), nf), 1)
        self._samples = r["P"]
        self._sample_face = fu
        self._sample_u = np.tile(U.ravel(), nf)
        self._sample_v = np.tile(V.ravel(), nf)
        # samples, for hand-offs across face edges (queried with surface points only: fast; the
        # unbalanced, non-compact tree builds 2.6x faster and answers as fast)
        self._stree = cKDTree(self._samples, balanced_tree=False, compact_nodes=False)
        # cells [face, ci, cj]: cylinders around the centre samples (compiled; numpy reference
        # _bvh.cell_bounds_numpy)
        scale = np.abs(self._samples).max() if self._samples.size else 1.0
        grid = (nf, g, g, 3)
        self._c, self._n, self._r, self._h = _bvh.cell_bounds(
            r["P"].reshape(grid), r["Pu"].reshape(grid), r["Pv"].reshape(grid), m, SAFETY, 1e-13 * scale
        )
        self._R = np.hypot(self._r, self._h)
        self._Rmax = float(self._R.max()) if self._R.size else 0.0
        self._bvh = _bvh.build(self._c, self._R)
        # (unbalanced, non-compact nodes: several times faster queries for points far from the surface)
        self._ctree = cKDTree(self._c, balanced_tree=False, compact_nodes=False)
        cid = np.arange(nf * m * m)
        self._cface = sel[cid // (m * m)]
        self._ci = (cid // m) % m
        self._cj = cid % m

    # ------------------------------------------------------------------ bounds
    def lower_bounds(self, X, cells):
        """Lower bounds of the distance from points ``X`` (n, 3) to cells ``cells`` (n,) (sampled cylinders)."""
        w = X - self._c[cells]
        z = np.abs(row_dot(w, self._n[cells]))
        rho = np.sqrt(np.maximum(row_dot(w, w) - z * z, 0.0))
        return np.hypot(np.maximum(rho - self._r[cells], 0.0), np.maximum(z - self._h[cells], 0.0))

    def _candidates(self, X, dstar):
        """Pairs (point, cell) with lower bound < d*: arrays pid, cid, lb."""
        return _bvh.candidates(X, dstar, self._bvh, self._c, self._n, self._r, self._h)

    # ------------------------------------------------------------------ query
    def query(self, X, *, chunk=CHUNK):
        """Nearest limit points of ``X`` (n, 3); returns :class:`ClosestPoints`."""
        X = check_query_points(X)
        n = X.shape[0]
        out = ClosestPoints(
            np.empty(n, dtype=np.int64), np.empty(n), np.empty(n), np.empty((n, 3)), np.empty(n),
            np.empty((n, 3)), np.empty(n, dtype=np.int32),
        )
        for lo in range(0, n, chunk):
            hi = min(n, lo + chunk)
            f, u, v, nd = self._query_chunk(X[lo:hi])
            out.face[lo:hi], out.u[lo:hi], out.v[lo:hi], out.descents[lo:hi] = f, u, v, nd
        r = self.surface.evaluate(out.face, out.u, out.v, 1)
        out.P[:] = r["P"]
        out.distance[:] = np.linalg.norm(X - r["P"], axis=1)
        out.normal[:] = unit_normal(r["Pu"], r["Pv"])
        _warn_undefined_normals(out)
        return out

    __call__ = query

    def _query_chunk(self, X):
        n = X.shape[0]
        m = self.m
        _, j = self._ctree.query(X, k=1)
        # starts of the current round: point, face, (u, v)
        sp, sf = np.arange(n), self._cface[j]
        su, sv = (self._ci[j] + 0.5) / m, (self._cj[j] + 0.5) / m
        bf = np.zeros(n, dtype=np.int64)
        bu, bv, bE = np.zeros(n), np.zeros(n), np.full(n, np.inf)
        ndesc = np.zeros(n, dtype=np.int32)
        handoffs = np.zeros(n, dtype=np.int32)
        pid = None
        for _round in range(MAX_ROUNDS + 1):
            nu, nv, nE = newton(self.surface, X[sp], sf, su, sv)
            np.add.at(ndesc, sp, 1)
            # best per point among this round's descents, then against the best so far
            order = np.lexsort((nE, sp))
            first = order[np.r_[True, sp[order[1:]] != sp[order[:-1]]]] if sp.size else order
            better = first[nE[first] < bE[sp[first]]]
            q = sp[better]
            bf[q], bu[q], bv[q], bE[q] = sf[better], nu[better], nv[better], nE[better]
            if pid is None:
                pid, cid, lb = self._candidates(X, np.sqrt(2.0 * bE))
                order = np.lexsort((lb, pid))  # sorted by point, then bound (kept by every compression)
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
            cp, cc = pid[first], cid[first]
            sp = np.concatenate([cp, hp])
            sf = np.concatenate([self._cface[cc], hf])
            su = np.concatenate([(self._ci[cc] + 0.5) / m, hu])
            sv = np.concatenate([(self._cj[cc] + 0.5) / m, hv])
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
        """For end points (f, u, v) on a face edge: the nearest sample of another face (points p)."""
        if p.size == 0:
            e = np.empty(0, dtype=np.int64)
            return e, np.empty(0), np.empty(0), e
        P = self.surface.evaluate(f, u, v, 0)["P"]
        k = 8
        _, J = self._stree.query(P, k=k)
        other = self._sample_face[J] != f[:, None]
        has = other.any(axis=1)
        col = np.argmax(other, axis=1)
        jj = J[np.arange(p.size), col][has]
        return self._sample_face[jj], self._sample_u[jj], self._sample_v[jj], p[has]

    def _cell_of(self, t):
        return np.minimum((np.asarray(t) * self.m).astype(np.int64), self.m - 1)

    def _covered_by(self, pid, cid, rf, si, sj, ei, ej):
        """Candidates (pid, cid) in the face ``rf`` of a descent of the same point, within one cell of
        its start cell (si, sj) or its end cell (ei, ej) (all arrays aligned with pid)."""
        same = self._cface[cid] == rf
        if self.cover >= self.m:
            return same
        ci, cj, c = self._ci[cid], self._cj[cid], self.cover
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
