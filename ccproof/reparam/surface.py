"""The differentiable parameterizations of bmz04 section 4 on real meshes: f o F_b.

:func:`limit_surface` returns a :class:`ReparamLimitSurface`, a
:class:`~ccproof.evaluate.surface.LimitSurface` whose :meth:`~ReparamLimitSurface.evaluate` takes
``parameterization="natural" | "vanishing" | "characteristic"``:

* ``natural``: the evaluator's own parameterization (Stam; bmz04 section 2);
* ``vanishing``: f o F_b with F_i = F^alpha and w = b(|t|) (section 4.2);
* ``characteristic``: f o F_b with F_i = Phi^-1 and w = b(s) b(t) (section 4.3).

F_b (:func:`ccproof.reparam.blend.face_map`) is applied at every corner that is an interior
vertex of valence != 4; it is the identity at valence-4 vertices and at *boundary* vertices
(bmz04's characteristic map and its bound on alpha are for interior vertices; the boundary rules
have other eigenstructures, so the natural parameterization is kept there). The derivatives are
the chain rule ``D(f o F_b) = Df(F_b(t)) DF_b(t)`` (second derivatives
``D^2 f[DF_b, DF_b] + Df D^2 F_b``), with the analytic derivatives of F_b.

At a point exactly at an extraordinary corner the natural derivatives are 0 (k = 3) or infinite
(k >= 5) and DF_b is singular, so the limit is returned instead: 0 for ``vanishing``, and for
``characteristic`` the exact limit D(f o Phi^-1)(0) of :mod:`ccproof.reparam.corner` (the
lam-eigencomponent of the surface at the two edge neighbours). The same limit values are used at
the (very few) points whose preimage F_b(t) is closer to the corner than the deepest layer the
evaluator stores (about 2^-47 .. 2^-100 of the face, where it returns the limit point): there the
limit is the best available value of the derivative. Second derivatives are NaN at these points
(f o F_b is C1 but in general not C2 at an extraordinary vertex).

Precision near corners: F_b(t) is computed in the corner's local frame with full relative precision;
written as a face parameter near a corner at 1 (u = 1 - s) it would lose it (s < 2^-53 even collapses
onto the corner). Active points within 2^-8 of a corner other than (0, 0) are therefore evaluated on
the same surface with every face's vertex list rotated so that the corner is (0, 0) (built once, on
first use, per rotation), and their derivatives are rotated back.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any, overload

import numpy as np

from ccproof.errors import CCProofError
from ccproof.evaluate.surface import CHUNK, LimitSurface
from ccproof.mesh import QuadMesh
from ccproof.reparam.blend import CORNER_FRAMES, PARAMETERIZATIONS, active_points, blend_points
from ccproof.reparam.quadrant import check_alpha, default_alpha

if TYPE_CHECKING:
    from ccproof.evaluate.tagged import TaggedLimitSurface
    from ccproof.mesh.polymesh import PolyMesh

__all__ = ["ReparamLimitSurface", "limit_surface"]

_KEYS = {0: ("P",), 1: ("P", "Pu", "Pv"), 2: ("P", "Pu", "Pv", "Puu", "Puv", "Pvv")}
#: points whose preimage is this close to the corner (local max-norm) are checked against the
#: evaluator's deepest stored layer (every corner stores more than 40 layers)
_DEEP = 2.0**-30
#: active points of a quarter whose corner is not at (0, 0) and whose preimage is this close to it
#: are evaluated in the corner's own frame (relative precision of the local coordinates kept)
_NEAR = 2.0**-8


def _put_rows(a, idx, x):
    """a[idx] = x for an (n, 3) array (row scatter through a void view: ~10x faster than fancy indexing)."""
    if a.flags.c_contiguous and x.flags.c_contiguous and a.dtype == x.dtype == np.float64:
        row = np.dtype((np.void, 8 * a.shape[1]))
        a.view(row).reshape(-1)[idx] = x.view(row).reshape(-1)
    else:  # pragma: no cover - the evaluator's outputs are contiguous
        a[idx] = x


def _chain_rule(R, idx, J, H, derivatives):
    """In place: derivatives of f o F at rows idx of R from those of f, J = DF, H = D^2 F."""
    Pu, Pv = np.take(R["Pu"], idx, axis=0), np.take(R["Pv"], idx, axis=0)
    if derivatives >= 2:
        Puu, Puv, Pvv = (np.take(R[key], idx, axis=0) for key in ("Puu", "Puv", "Pvv"))
        for key, i, j in (("Puu", 0, 0), ("Puv", 0, 1), ("Pvv", 1, 1)):
            _put_rows(R[key], idx, Puu * (J[:, 0, i] * J[:, 0, j])[:, None]
                      + Puv * (J[:, 0, i] * J[:, 1, j] + J[:, 1, i] * J[:, 0, j])[:, None]
                      + Pvv * (J[:, 1, i] * J[:, 1, j])[:, None]
                      + Pu * H[:, 0, i, j, None] + Pv * H[:, 1, i, j, None])
    _put_rows(R["Pu"], idx, Pu * J[:, 0, 0, None] + Pv * J[:, 1, 0, None])
    _put_rows(R["Pv"], idx, Pu * J[:, 0, 1, None] + Pv * J[:, 1, 1, None])


class ReparamLimitSurface(LimitSurface):
    """Limit surface with the three parameterizations of bmz04 (see the module docstring).

    "natural" (Stam's, docs/readings.md R12), "vanishing" (F^alpha blended, bmz04 section 4.2) and
    "characteristic" (Phi^-1 blended, bmz04 section 4.3, eq. 4); docs/reparam.md. Made by
    :func:`limit_surface`.

    Parameters
    ----------
    mesh : QuadMesh
        A manifold quad mesh.
    alpha : float or dict of int -> float, optional
        Exponent of F^alpha per valence ("vanishing"); default
        :func:`~ccproof.reparam.quadrant.default_alpha` of each valence.

    Attributes
    ----------
    alpha : dict of int -> float
        Exponent of F^alpha for every extraordinary interior valence of the mesh (besides the
        attributes of LimitSurface).
    corner_valence : ndarray, shape (n_faces, 4) int64
        The valence of each face corner, 0 where F_i is the identity.

    Examples
    --------
    Every corner of the cube has valence 3:

    >>> from ccproof.mesh.examples import cube
    >>> from ccproof.reparam.quadrant import default_alpha
    >>> S = limit_surface(cube())
    >>> S.corner_valence[0].tolist(), S.alpha == {3: default_alpha(3)}
    ([3, 3, 3, 3], True)
    """

    def __init__(self, mesh: QuadMesh, alpha: float | Mapping[int, float] | None = None, *,
                 progress: bool | None = None) -> None:
        super().__init__(mesh, progress=progress)
        val = np.asarray(mesh.valence, dtype=np.int64)
        code = np.where(mesh.is_boundary_vertex | (val == 4), 0, val)
        self.corner_valence = code[mesh.faces]
        kinds = sorted({int(k) for k in np.unique(code) if k > 0})
        self.alpha = {}
        for k in kinds:
            if alpha is None:
                a = default_alpha(k)
            elif isinstance(alpha, dict):
                a = alpha[k] if k in alpha else default_alpha(k)
            else:
                a = alpha
            self.alpha[k] = check_alpha(a, k)
        self._tangent_cache: dict[tuple[int, int], Any] = {}
        self._rotated_cache: dict[int, LimitSurface] = {}

    def evaluate(self, face_ids, u, v, derivatives=1, *, parameterization="natural", chunk=CHUNK, out=None,
                 backend=None, threads=None):
        """Positions and derivatives at points (face, u, v) in the chosen parameterization.

        Parameters
        ----------
        face_ids : array_like of int, shape (n,)
        u, v : array_like of float, shape (n,)
            Face parameters in [0, 1] (corner i of the face at (0,0), (1,0), (1,1), (0,1)).
        derivatives : int, 0, 1 or 2
        parameterization : {"natural", "vanishing", "characteristic"}
            bmz04 section 2, 4.2 or 4.3.
        chunk, out, backend, threads
            As in :meth:`ccproof.evaluate.surface.LimitSurface.evaluate`.

        Returns
        -------
        dict of ndarray, shape (n, 3)
            ``P``; ``Pu``, ``Pv`` with ``derivatives >= 1``; ``Puu``, ``Puv``, ``Pvv`` with 2:
            derivatives of f o F_b with respect to the face's own (u, v).

        Raises
        ------
        CCProofError
            Unknown parameterization; face id out of range; (u, v) outside [0, 1]^2 or NaN.

        Examples
        --------
        >>> from ccproof.mesh.examples import k_regular_disk
        >>> S = limit_surface(k_regular_disk(5, 2))
        >>> r = S.evaluate([0], [0.0], [0.0], parameterization="characteristic")
        >>> bool(np.linalg.norm(np.cross(r["Pu"][0], r["Pv"][0])) > 0.1)   # rank 2 at the vertex
        True
        """
        if parameterization not in PARAMETERIZATIONS:
            raise CCProofError(
                f"unknown parameterization {parameterization!r}; use one of {', '.join(PARAMETERIZATIONS)}")
        if derivatives not in (0, 1, 2):
            raise CCProofError(f"derivatives must be 0, 1 or 2, got {derivatives!r}")
        if parameterization == "natural":
            return super().evaluate(face_ids, u, v, derivatives, chunk=chunk, out=out, backend=backend,
                                    threads=threads)
        f, u, v = self._check(face_ids, u, v)
        idx, q, s, t, k = active_points(self.corner_valence, f, u, v, parameterization)
        if idx.size == 0:
            return super().evaluate(f, u, v, derivatives, chunk=chunk, out=out, backend=backend, threads=threads)
        res = blend_points(q, s, t, k, parameterization, self.alpha, derivatives)
        u2, v2 = u.copy(), v.copy()
        u2[idx], v2[idx] = res["u"], res["v"]
        R = super().evaluate(f, u2, v2, derivatives, chunk=chunk, out=out, backend=backend, threads=threads)
        if derivatives >= 1:
            _chain_rule(R, idx, res["J"], res.get("H"), derivatives)
        m = res["local"].max(axis=1)
        # near a corner at 1, u = 1 - s loses the relative precision of s: evaluate those points
        # in the corner's own frame (the mesh with its faces' vertex lists rotated)
        for qq in (1, 2, 3):
            sel = np.flatnonzero((q == qq) & (m < _NEAR))
            if sel.size:
                self._eval_in_corner_frame(qq, f[idx[sel]], idx[sel], sel, res, R, derivatives, backend)
        if derivatives >= 1:
            self._fix_corner_limits(f[idx], idx, q, m, res, R, parameterization, derivatives)
        return R

    def _rotated(self, q):
        """The same surface with every face's vertex list rotated by q (corner q becomes corner 0)."""
        if q not in self._rotated_cache:
            F = np.roll(self.mesh.faces, -q, axis=1)
            self._rotated_cache[q] = LimitSurface(QuadMesh(self.mesh.vertices, F))
        return self._rotated_cache[q]

    def _eval_in_corner_frame(self, q, f, rows, sel, res, R, d, backend):
        """Rows ``rows`` of R (active points ``sel`` of ``res``) evaluated in the frame of corner q."""
        S = self._rotated(q)
        G = res["local"][sel]
        Rl = LimitSurface.evaluate(S, f, G[:, 0], G[:, 1], d, backend=backend)
        R["P"][rows] = Rl["P"]
        if d == 0:
            return
        _chain_rule(Rl, np.arange(sel.size), res["J_local"][sel], res["H_local"][sel] if d >= 2 else None, d)
        A = CORNER_FRAMES[q]  # d/du_i = sum_b A[i, b] d/ds_b
        R["Pu"][rows] = A[0, 0] * Rl["Pu"] + A[0, 1] * Rl["Pv"]
        R["Pv"][rows] = A[1, 0] * Rl["Pu"] + A[1, 1] * Rl["Pv"]
        if d >= 2:
            L = {(0, 0): Rl["Puu"], (0, 1): Rl["Puv"], (1, 0): Rl["Puv"], (1, 1): Rl["Pvv"]}
            for key, i, j in (("Puu", 0, 0), ("Puv", 0, 1), ("Pvv", 1, 1)):
                R[key][rows] = sum(A[i, b] * A[j, c] * L[(b, c)] for b in range(2) for c in range(2))

    def _fix_corner_limits(self, f, idx, q, m, res, R, parameterization, derivatives):
        """Limit derivatives at the corner and beyond the evaluator's deepest layer (module doc).

        ``f``, ``q``, ``m``: face, quarter and max local coordinate of the active points ``idx``."""
        cand = np.flatnonzero(m < _DEEP)
        if cand.size == 0:
            return
        loc = res["local"]
        scale = np.empty(cand.size)
        for qq in range(4):
            sel = cand[q[cand] == qq]
            if sel.size:
                S = self if qq == 0 else self._rotated(qq)
                scale[q[cand] == qq] = S._locate(f[sel], loc[sel, 0], loc[sel, 1])[3]
        # a point inside a stored layer of side h has max(local) >= h, i.e. m * scale >= 1
        fix = cand[(m[cand] * scale < 1.0) | res["corner"][cand]]
        if fix.size == 0:
            return
        rows = idx[fix]
        if parameterization == "vanishing":
            R["Pu"][rows] = 0.0
            R["Pv"][rows] = 0.0
        else:
            for row, ff, qq in zip(rows.tolist(), f[fix].tolist(), q[fix].tolist()):
                D = self.corner_derivatives(ff, qq)  # (2, 3): d/ds, d/dt in the corner frame
                A = CORNER_FRAMES[qq]
                R["Pu"][row] = A[0, 0] * D[0] + A[0, 1] * D[1]
                R["Pv"][row] = A[1, 0] * D[0] + A[1, 1] * D[1]
        if derivatives >= 2:
            for key in ("Puu", "Puv", "Pvv"):
                R[key][rows] = np.nan

    def corner_derivatives(self, face, corner):
        """D(f o Phi^-1)(0) at corner ``corner`` of ``face``: rows d/ds, d/dt in the corner frame, (2, 3).

        See :mod:`ccproof.reparam.corner`. Only for interior vertices of valence != 4.
        """
        key = (int(face), int(corner))
        if key not in self._tangent_cache:
            from ccproof.reparam.corner import corner_tangents

            self._tangent_cache[key] = corner_tangents(self.mesh, *key)
        return self._tangent_cache[key]


@overload
def limit_surface(mesh: QuadMesh | str | os.PathLike[str], alpha: float | Mapping[int, float] | None = None, *,
                  progress: bool | None = None) -> ReparamLimitSurface: ...
@overload
def limit_surface(mesh: PolyMesh, alpha: None = None, *, progress: bool | None = None) -> TaggedLimitSurface: ...
def limit_surface(mesh: QuadMesh | PolyMesh | str | os.PathLike[str], alpha: float | Mapping[int, float] | None = None,
                  *, progress: bool | None = None) -> ReparamLimitSurface | TaggedLimitSurface:
    """The limit surface of a mesh: exact evaluation, normals and the parameterizations of bmz04.

    The one entry point for limit surfaces (``ccproof.limit_surface``). A quad mesh gives a
    :class:`ReparamLimitSurface`: ``evaluate(face, u, v, derivatives, parameterization=...)`` with
    ``"natural"`` (default; docs/evaluate.md), ``"vanishing"`` or ``"characteristic"`` (bmz04
    section 4, docs/reparam.md). A :class:`~ccproof.mesh.polymesh.PolyMesh` (triangles, n-gons,
    creases, corners, holes) gives the tagged evaluator of
    :func:`ccproof.evaluate.natural_limit_surface` (natural parameterization only).

    Parameters
    ----------
    mesh : QuadMesh or PolyMesh or str or os.PathLike
        A path is read with :func:`ccproof.mesh.read_mesh` (every format; a plain quad mesh gives
        the reparameterizable surface, any other mesh the tagged evaluator).
    alpha : float or dict or None
        Exponent of F^alpha for the "vanishing" parameterization: one value for every valence, a
        dict valence -> value (missing valences get the default), or None for
        :func:`~ccproof.reparam.quadrant.default_alpha` (twice the bound of bmz04 section 4.2).
    progress : bool, optional
        Show a progress bar (tqdm, on stderr) when building the patch table takes more than 2 s;
        default: when stderr is a terminal.

    Returns
    -------
    ReparamLimitSurface, or TaggedLimitSurface for a PolyMesh

    Raises
    ------
    CCProofError
        alpha not above -log 2 / log lam(k) for a valence k of an interior extraordinary vertex,
        or alpha given for a PolyMesh.

    Examples
    --------
    >>> from ccproof.mesh.examples import k_regular_disk
    >>> S = limit_surface(k_regular_disk(5, 2))
    >>> r = S.evaluate([0, 1], [0.1, 0.5], [0.2, 0.5], parameterization="characteristic")
    >>> r["P"].shape, r["Pu"].shape
    ((2, 3), (2, 3))
    """
    from ccproof.mesh.polymesh import PolyMesh

    if isinstance(mesh, PolyMesh):
        if alpha is not None:
            raise CCProofError("alpha applies to the parameterizations of quad meshes only, not to a PolyMesh")
        from ccproof.evaluate.surface import natural_limit_surface

        return natural_limit_surface(mesh, progress=progress)
    if isinstance(mesh, QuadMesh):
        return ReparamLimitSurface(mesh, alpha, progress=progress)
    from ccproof.mesh.io import read_mesh

    poly = read_mesh(mesh)
    if poly.is_plain_quads:
        return ReparamLimitSurface(poly.to_quad_mesh(), alpha, progress=progress)
    if alpha is not None:
        raise CCProofError(f"alpha applies to the parameterizations of plain quad meshes only, not to {mesh}")
    return limit_surface(poly, progress=progress)
