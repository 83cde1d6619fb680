"""The differentiable parameterizations of bmz04 section 4 on real meshes: f o F_b.

:class:`Parameterization` is a value (as OpenSubdiv's ``Bfr::Parameterization``) passed to the one
public evaluation, ``surface.evaluate(face, u, v, derivatives, parameterization=p)`` of
:class:`~ccproof.evaluate.surface.LimitSurface`, which applies it around its natural evaluation
(:meth:`Parameterization.evaluate_on`, through the evaluator's public ``evaluate`` and ``locate``
only). :func:`limit_surface` (``ccproof.limit_surface``) builds the surface with the values by name (its
``parameterizations``, given to the constructor), so that ``parameterization="vanishing"`` works as well:

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
import threading
import weakref
from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Literal, overload

import numpy as np

from ccproof.errors import CCProofError
from ccproof.evaluate.surface import CHUNK, LimitSurface
from ccproof.mesh import QuadMesh
from ccproof.reparam.blend import CORNER_FRAMES, PARAMETERIZATIONS, active_points, blend_points
from ccproof.reparam.quadrant import check_alpha, default_alpha

if TYPE_CHECKING:
    from ccproof.evaluate.loop import LoopSurface
    from ccproof.mesh.polymesh import PolyMesh

__all__ = ["Parameterization", "corner_valence", "limit_surface", "named_parameterizations"]

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


@dataclass(frozen=True, eq=True, repr=False)
class Parameterization:
    """A parameterization of the limit surface, as a value: bmz04 section 2, 4.2 or 4.3.

    Passed to the one public evaluation, ``surface.evaluate(face, u, v, derivatives,
    parameterization=p)`` (:meth:`ccproof.evaluate.surface.LimitSurface.evaluate`), as OpenSubdiv's
    ``Bfr::Parameterization`` is a value passed to its evaluation: the evaluator stays the natural one,
    and the map F_b is applied around its public :meth:`~ccproof.evaluate.surface.LimitSurface.evaluate`
    and :meth:`~ccproof.evaluate.surface.LimitSurface.locate` (see the module docstring). The value
    does not depend on a mesh; what it derives from a surface (the corner valences, the checked
    exponents, the rotated surfaces near corners at 1, the corner tangents) is cached per surface,
    and goes with it.

    Parameters
    ----------
    kind : {"natural", "vanishing", "characteristic"}
    alpha : float or dict of int -> float, optional
        Exponent of F^alpha ("vanishing"): one value for every valence, a dict valence -> value
        (missing valences get the default), or None for
        :func:`~ccproof.reparam.quadrant.default_alpha` (twice the bound of bmz04 section 4.2).

    Examples
    --------
    >>> from ccproof.evaluate.surface import LimitSurface
    >>> from ccproof.mesh.examples import k_regular_disk
    >>> S = LimitSurface(k_regular_disk(5, 2))
    >>> p = Parameterization("characteristic")
    >>> r = S.evaluate([0], [0.0], [0.0], parameterization=p)
    >>> bool(np.linalg.norm(np.cross(r["Pu"][0], r["Pv"][0])) > 0.1)   # rank 2 at the vertex
    True
    >>> Parameterization("vanishing", 2.5).alphas(S)
    {5: 2.5}
    """

    kind: str
    alpha: float | Mapping[int, float] | None = None

    def __post_init__(self) -> None:
        if self.kind not in PARAMETERIZATIONS:
            raise CCProofError(f"unknown parameterization {self.kind!r}; use one of {', '.join(PARAMETERIZATIONS)}")
        if self.alpha is not None and self.kind != "vanishing":
            raise CCProofError(f"alpha applies to the vanishing parameterization only, not to {self.kind!r}")
        if isinstance(self.alpha, Mapping):
            object.__setattr__(self, "alpha", dict(self.alpha))  # a copy: the value does not change

    def __repr__(self) -> str:
        return f"Parameterization({self.kind!r}" + ("" if self.alpha is None else f", alpha={self.alpha!r}") + ")"

    def __hash__(self) -> int:
        return hash((self.kind, self._alpha_key()))

    def _alpha_key(self) -> Any:
        return tuple(sorted(self.alpha.items())) if isinstance(self.alpha, dict) else self.alpha

    # ------------------------------------------------------------------ per surface
    def alphas(self, surface: LimitSurface) -> dict[int, float]:
        """The exponent of F^alpha for every extraordinary interior valence of ``surface``'s mesh, checked.

        Raises
        ------
        CCProofError
            alpha not above -log 2 / log lam(k) for a valence k of the mesh; a surface that is not
            of an untagged all-quad mesh.
        """
        st = _state(surface)
        key = self._alpha_key()
        if key not in st.alphas:
            st.alphas[key] = self._checked_alphas(st.kinds)
        return dict(st.alphas[key])

    def _checked_alphas(self, kinds: list[int]) -> dict[int, float]:
        """The exponent for every valence of ``kinds``, checked (:func:`~ccproof.reparam.quadrant.check_alpha`)."""
        out = {}
        for k in kinds:
            if self.alpha is None:
                a = default_alpha(k)
            elif isinstance(self.alpha, dict):
                a = self.alpha[k] if k in self.alpha else default_alpha(k)
            else:
                a = self.alpha
            out[k] = check_alpha(a, k)
        return out

    def evaluate_on(self, surface: LimitSurface, f: np.ndarray, u: np.ndarray, v: np.ndarray, derivatives: int = 1,
                    *, chunk: int = CHUNK, out: dict[str, np.ndarray] | None = None, backend: str | None = None,
                    threads: int | None = None) -> dict[str, np.ndarray]:
        """f o F_b at points the surface has checked: what ``surface.evaluate(..., parameterization=self)`` returns.

        Called by :meth:`ccproof.evaluate.surface.LimitSurface.evaluate` with ``f`` (n,) int64 and
        ``u``, ``v`` (n,) float64 already checked; uses only the surface's public ``evaluate`` (natural)
        and ``locate``.

        Returns
        -------
        dict of ndarray, shape (n, 3)
            ``P``; ``Pu``, ``Pv`` with ``derivatives >= 1``; ``Puu``, ``Puv``, ``Pvv`` with 2:
            derivatives of f o F_b with respect to the face's own (u, v).
        """
        kw = {"chunk": chunk, "out": out, "backend": backend, "threads": threads}
        if self.kind == "natural":
            return surface.evaluate(f, u, v, derivatives, **kw)
        st = _state(surface)
        alpha = self.alphas(surface)
        idx, q, s, t, k = active_points(st.corner_valence, f, u, v, self.kind)
        if idx.size == 0:
            return surface.evaluate(f, u, v, derivatives, **kw)
        res = blend_points(q, s, t, k, self.kind, alpha, derivatives)
        u2, v2 = u.copy(), v.copy()
        u2[idx], v2[idx] = res["u"], res["v"]
        R = surface.evaluate(f, u2, v2, derivatives, **kw)
        if derivatives >= 1:
            _chain_rule(R, idx, res["J"], res.get("H"), derivatives)
        m = res["local"].max(axis=1)
        # near a corner at 1, u = 1 - s loses the relative precision of s: evaluate those points
        # in the corner's own frame (the mesh with its faces' vertex lists rotated)
        for qq in (1, 2, 3):
            sel = np.flatnonzero((q == qq) & (m < _NEAR))
            if sel.size:
                _eval_in_corner_frame(surface, qq, f[idx[sel]], idx[sel], sel, res, R, derivatives, backend)
        if derivatives >= 1:
            self._fix_corner_limits(surface, f[idx], idx, q, m, res, R, derivatives)
        return R

    def basis_on(self, surface: LimitSurface, f: np.ndarray, u: np.ndarray, v: np.ndarray,
                 derivatives: int = 0) -> dict[str, Any]:
        """The basis rows of f o F_b at checked points: what ``surface.basis(..., parameterization=self)`` returns.

        The natural rows at F_b(t) (:meth:`~ccproof.evaluate.surface.LimitSurface.basis`) and the chain
        rule on them (the rows are linear in the control points, so the chain rule of
        :meth:`evaluate_on` applies row by row). Points whose preimage F_b(t) is within 2^-30 of an
        extraordinary corner (where :meth:`evaluate_on` substitutes limit values) are refused.

        Raises
        ------
        CCProofError
            A point that close to an extraordinary corner (names the point).
        """
        if self.kind == "natural":
            return surface.basis(f, u, v, derivatives)
        import scipy.sparse as sp

        st = _state(surface)
        idx, q, s, t, k = active_points(st.corner_valence, f, u, v, self.kind)
        if idx.size == 0:
            return surface.basis(f, u, v, derivatives)
        res = blend_points(q, s, t, k, self.kind, self.alphas(surface), derivatives)
        near = np.flatnonzero(res["local"].max(axis=1) < _DEEP)
        if near.size:
            i = int(idx[near[0]])
            raise CCProofError(f"point {i}: (face {int(f[i])}, u = {float(u[i])!r}, v = {float(v[i])!r}) maps within "
                               "2^-30 of an extraordinary corner: no basis rows there (use evaluate)")
        u2, v2 = u.copy(), v.copy()
        u2[idx], v2[idx] = res["u"], res["v"]
        W = surface.basis(f, u2, v2, derivatives)
        if derivatives == 0:
            return W
        n = f.size
        J = np.zeros((n, 2, 2))
        J[:, 0, 0] = J[:, 1, 1] = 1.0
        J[idx] = res["J"]

        def d(x):
            return sp.diags(x, format="csr")

        out = {"P": W["P"]}
        if derivatives >= 2:
            H = np.zeros((n, 2, 2, 2))
            H[idx] = res["H"]
            for key, i, j in (("Duu", 0, 0), ("Duv", 0, 1), ("Dvv", 1, 1)):
                out[key] = (d(J[:, 0, i] * J[:, 0, j]) @ W["Duu"] + d(J[:, 0, i] * J[:, 1, j] + J[:, 1, i] * J[:, 0, j])
                            @ W["Duv"] + d(J[:, 1, i] * J[:, 1, j]) @ W["Dvv"] + d(H[:, 0, i, j]) @ W["Du"]
                            + d(H[:, 1, i, j]) @ W["Dv"]).tocsr()
        out["Du"] = (d(J[:, 0, 0]) @ W["Du"] + d(J[:, 1, 0]) @ W["Dv"]).tocsr()
        out["Dv"] = (d(J[:, 0, 1]) @ W["Du"] + d(J[:, 1, 1]) @ W["Dv"]).tocsr()
        return {key: out[key] for key in W}

    def _fix_corner_limits(self, surface: LimitSurface, f: np.ndarray, idx: np.ndarray, q: np.ndarray,
                           m: np.ndarray, res: dict[str, Any], R: dict[str, np.ndarray], derivatives: int) -> None:
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
                S = surface if qq == 0 else _rotated(surface, qq)
                scale[q[cand] == qq] = S.locate(f[sel], loc[sel, 0], loc[sel, 1])[3]
        # a point inside a stored layer of side h has max(local) >= h, i.e. m * scale >= 1
        fix = cand[(m[cand] * scale < 1.0) | res["corner"][cand]]
        if fix.size == 0:
            return
        rows = idx[fix]
        if self.kind == "vanishing":
            R["Pu"][rows] = 0.0
            R["Pv"][rows] = 0.0
        else:
            for row, ff, qq in zip(rows.tolist(), f[fix].tolist(), q[fix].tolist()):
                D = corner_derivatives(surface, ff, qq)  # (2, 3): d/ds, d/dt in the corner frame
                A = CORNER_FRAMES[qq]
                R["Pu"][row] = A[0, 0] * D[0] + A[0, 1] * D[1]
                R["Pv"][row] = A[1, 0] * D[0] + A[1, 1] * D[1]
        if derivatives >= 2:
            for key in ("Puu", "Puv", "Pvv"):
                R[key][rows] = np.nan


class _SurfaceState:
    """What the parameterizations derive from one surface (cached, dropped with the surface)."""

    def __init__(self, mesh: QuadMesh) -> None:
        self.mesh = mesh
        self.corner_valence = corner_valence(mesh)
        self.kinds = corner_kinds(self.corner_valence)
        self.alphas: dict[Any, dict[int, float]] = {}
        self.rotated: dict[int, LimitSurface] = {}
        self.tangents: dict[tuple[int, int], Any] = {}


_STATES: weakref.WeakKeyDictionary[LimitSurface, _SurfaceState] = weakref.WeakKeyDictionary()
_LOCK = threading.Lock()


def _state(surface: LimitSurface) -> _SurfaceState:
    if not isinstance(surface.mesh, QuadMesh):
        raise CCProofError("the vanishing and characteristic parameterizations need an untagged all-quad mesh "
                           f"(a QuadMesh), not a {type(surface.mesh).__name__}")
    with _LOCK:
        st = _STATES.get(surface)
        if st is None:
            st = _STATES[surface] = _SurfaceState(surface.mesh)
    return st


def corner_valence(mesh: QuadMesh) -> np.ndarray:
    """The valence of every face corner where F_b is not the identity, 0 elsewhere.

    Parameters
    ----------
    mesh : QuadMesh

    Returns
    -------
    ndarray of int64, shape (n_faces, 4)
        The valence of corner i of face f if that vertex is an interior vertex of valence != 4, else
        0 (valence-4 and boundary vertices: the natural parameterization is kept there).

    Examples
    --------
    Every corner of the cube has valence 3:

    >>> from ccproof.mesh.examples import cube
    >>> corner_valence(cube())[0].tolist()
    [3, 3, 3, 3]
    """
    val = np.asarray(mesh.valence, dtype=np.int64)
    code = np.where(mesh.is_boundary_vertex | (val == 4), 0, val)
    return code[mesh.faces]


def corner_kinds(cv: np.ndarray) -> list[int]:
    """The valences (sorted, distinct) of :func:`corner_valence`'s array ``cv`` where F_b acts."""
    return sorted({int(k) for k in np.unique(cv) if k > 0})


def corner_derivatives(surface: LimitSurface, face: int, corner: int) -> np.ndarray:
    """D(f o Phi^-1)(0) at corner ``corner`` of ``face``: rows d/ds, d/dt in the corner frame, (2, 3).

    See :mod:`ccproof.reparam.corner`. Only for interior vertices of valence != 4.
    """
    st = _state(surface)
    key = (int(face), int(corner))
    if key not in st.tangents:
        from ccproof.reparam.corner import corner_tangents

        st.tangents[key] = corner_tangents(st.mesh, *key)
    return st.tangents[key]


def _rotated(surface: LimitSurface, q: int) -> LimitSurface:
    """The same surface with every face's vertex list rotated by q (corner q becomes corner 0)."""
    st = _state(surface)
    if q not in st.rotated:
        mesh = st.mesh
        st.rotated[q] = LimitSurface(QuadMesh(mesh.vertices, np.roll(mesh.faces, -q, axis=1)), progress=False)
    return st.rotated[q]


def _eval_in_corner_frame(surface: LimitSurface, q: int, f: np.ndarray, rows: np.ndarray, sel: np.ndarray,
                          res: dict[str, Any], R: dict[str, np.ndarray], d: int, backend: str | None) -> None:
    """Rows ``rows`` of R (active points ``sel`` of ``res``) evaluated in the frame of corner q."""
    S = _rotated(surface, q)
    G = res["local"][sel]
    Rl = S.evaluate(f, G[:, 0], G[:, 1], d, backend=backend)
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


def named_parameterizations(alpha: float | Mapping[int, float] | None = None) -> dict[str, Parameterization]:
    """The parameterizations ``ccproof.limit_surface`` names on a quad mesh's surface (its ``parameterizations``).

    ``surface.evaluate(..., parameterization="vanishing")`` looks the name up there.

    >>> sorted(named_parameterizations(2.5).items())
    [('characteristic', Parameterization('characteristic')), ('vanishing', Parameterization('vanishing', alpha=2.5))]
    """
    return {"vanishing": Parameterization("vanishing", alpha), "characteristic": Parameterization("characteristic")}


@overload
def limit_surface(mesh: QuadMesh | PolyMesh | str | os.PathLike[str], alpha: float | Mapping[int, float] | None = None,
                  *, progress: bool | None = None, scheme: Literal["catmark"] = "catmark") -> LimitSurface: ...


@overload
def limit_surface(mesh: QuadMesh | PolyMesh | str | os.PathLike[str], alpha: float | Mapping[int, float] | None = None,
                  *, progress: bool | None = None, scheme: Literal["loop"]) -> LoopSurface: ...


def limit_surface(mesh: QuadMesh | PolyMesh | str | os.PathLike[str], alpha: float | Mapping[int, float] | None = None,
                  *, progress: bool | None = None, scheme: str = "catmark") -> LimitSurface | LoopSurface:
    """The limit surface of a mesh: exact evaluation, normals and the parameterizations of bmz04.

    The one entry point for limit surfaces (``ccproof.limit_surface``): the exact evaluator of
    :func:`ccproof.evaluate.natural_limit_surface`, whose ``evaluate(face, u, v, derivatives,
    parameterization=...)`` takes ``"natural"`` (default; docs/evaluate.md) and, on an untagged
    all-quad mesh, ``"vanishing"`` or ``"characteristic"`` (bmz04 section 4, docs/reparam.md): the
    names of the :class:`Parameterization` values this function builds the surface with (its
    ``parameterizations``, with ``alpha``). A :class:`Parameterization` value can be passed instead
    of a name, on any quad mesh's surface. Tagged meshes (triangles, n-gons, creases, corners, holes)
    have the natural parameterization only.

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
    scheme : {"catmark", "loop"}
        The subdivision scheme (:mod:`ccproof.mesh.scheme`). ``"loop"``: the exact Loop evaluator
        :class:`~ccproof.evaluate.loop.LoopSurface` of a triangle mesh (natural parameterization only;
        ``alpha`` is refused).

    Returns
    -------
    LimitSurface or LoopSurface

    Raises
    ------
    CCProofError
        alpha not above -log 2 / log lam(k) for a valence k of an interior extraordinary vertex,
        or alpha given for a tagged mesh.

    Examples
    --------
    >>> from ccproof.mesh.examples import k_regular_disk
    >>> S = limit_surface(k_regular_disk(5, 2))
    >>> r = S.evaluate([0, 1], [0.1, 0.5], [0.2, 0.5], parameterization="characteristic")
    >>> r["P"].shape, r["Pu"].shape
    ((2, 3), (2, 3))
    """
    from ccproof.evaluate.surface import natural_limit_surface
    from ccproof.mesh.polymesh import PolyMesh

    if scheme != "catmark":
        from ccproof.evaluate.loop import loop_limit_surface

        return loop_limit_surface(mesh, scheme=scheme, alpha=alpha)
    if not isinstance(mesh, (QuadMesh, PolyMesh)):
        from ccproof.mesh.io import read_mesh

        poly = read_mesh(mesh)
        if not poly.is_plain_quads and alpha is not None:
            raise CCProofError(f"alpha applies to the parameterizations of plain quad meshes only, not to {mesh}")
        mesh = poly.to_quad_mesh() if poly.is_plain_quads else poly
    if isinstance(mesh, PolyMesh):
        if alpha is not None:
            raise CCProofError("alpha applies to the parameterizations of quad meshes only, not to a PolyMesh")
        return natural_limit_surface(mesh, progress=progress)
    named = named_parameterizations(alpha)
    named["vanishing"]._checked_alphas(corner_kinds(corner_valence(mesh)))  # a bad alpha: an error of this call
    return natural_limit_surface(mesh, progress=progress, parameterizations=named)
