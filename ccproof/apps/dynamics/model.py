"""The dynamic Catmull-Clark surface: generalized coordinates, global matrices, limit evaluation (qmv98 2.4-3.1).

The generalized coordinates are the control points ``p`` of the initial mesh (qmv98 eq. 15,
``s = J p``). ccproof stores them as an ``(n, 3)`` array ``P``; the paper's interleaved vector is
``P.reshape(-1)`` and every paper matrix is ``X_scalar (x) I_3`` of the scalar ``n x n`` matrices
built here (the three coordinates never couple).

Global matrices (qmv98 eqs. 18-20) are sums of element matrices: normal elements (16 x 16,
analytic, :mod:`ccproof.apps.dynamics.basis`) and special elements (``(6n+1) x (6n+1)``,
:mod:`ccproof.apps.dynamics.elements`). With constant densities the mass and damping matrices
are ``mu M1`` and ``gamma M1`` with the unit-density mass ``M1``; the special-element part of ``M1`` is
the exact infinite sum, the stiffness is truncated at the level ``levels`` (``L``).

Two products with any combination ``c_m M1 + c_k K``: the assembled :mod:`scipy.sparse` matrix
(:meth:`DynamicSurface.assemble`) and the element-by-element product without a global matrix
(:meth:`DynamicSurface.matvec`, the paper's choice "in the interest of time").

>>> from ccproof.apps.dynamics.meshes import paper_initial_model
>>> model = DynamicSurface(paper_initial_model())
>>> model.n_vertices, model.layout.n_normal, model.layout.n_special
(98, 72, 8)
>>> import numpy as np
>>> M1 = model.assemble(c_mass=1.0, c_stiff=0.0)
>>> round(float(M1.sum()), 12)       # 1^T M1 1 = total parametric area = number of faces
96.0
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, replace

import numpy as np
import scipy.sparse as sp

from ccproof.apps.dynamics.basis import basis_1d, patch_rows, term_matrix
from ccproof.apps.dynamics.elements import (
    STIFFNESS_TERMS,
    element_layout,
    face_to_sector,
    sector_derivative_maps,
    special_scheme,
)
from ccproof.errors import CCProofError

__all__ = ["Material", "DynamicSurface", "LimitEvaluator", "MAX_EVAL_LEVEL"]

#: the key of the basis rows of every evaluated quantity (LimitSurface.basis's keys)
_ROW_KEY = {"P": "P", "Pu": "Du", "Pv": "Dv", "Puu": "Duu", "Puv": "Duv", "Pvv": "Dvv"}

#: deepest local level used by the evaluation; below 2^-MAX_EVAL_LEVEL the EV limit point is returned
MAX_EVAL_LEVEL = 60


@dataclass(frozen=True)
class Material:
    """Constant material densities of qmv98 eqs. (18)-(20).

    Parameters
    ----------
    mu : float
        Mass density (eq. 18).
    gamma : float
        Damping density (eq. 19).
    a11, a22 : float
        Tension along u and v (eq. 20).
    b11, b12, b22 : float
        Rigidity; ``b12`` multiplies ``J_uv^T J_uv`` once (the isotropic thin plate is
        ``b11 = b22 = b, b12 = 2 b``).

    All must be finite and >= 0.

    >>> Material(mu=-1)
    Traceback (most recent call last):
    ...
    ccproof.errors.CCProofError: material parameter mu must be finite and >= 0, got -1
    """

    mu: float = 1.0
    gamma: float = 1.0
    a11: float = 1.0
    a22: float = 1.0
    b11: float = 1.0
    b12: float = 2.0
    b22: float = 1.0

    def __post_init__(self):
        for name, val in asdict(self).items():
            try:
                ok = math.isfinite(float(val)) and float(val) >= 0
            except (TypeError, ValueError):
                ok = False
            if not ok:
                raise CCProofError(f"material parameter {name} must be finite and >= 0, got {val!r}")

    def term_coefficients(self, swap=False):
        """Coefficients of the stiffness integrands of :data:`~ccproof.apps.dynamics.basis.TERMS`.

        ``swap=True`` exchanges the u and v roles (a special-element sector whose s axis is the
        face's v axis, i.e. the EV at an odd corner).
        """
        if swap:
            return {"uu1": self.a22, "vv1": self.a11, "uu2": self.b22, "uv2": self.b12, "vv2": self.b11}
        return {"uu1": self.a11, "vv1": self.a22, "uu2": self.b11, "uv2": self.b12, "vv2": self.b22}

    def refined(self):
        """Densities for the model rebuilt on the CC-subdivided mesh with the *same* energies.

        Every child face gets its own unit domain, so the same densities would make the mass
        4 times, the rigidity energy 1/4 of the coarse one (docs/qmv98.md B4): mu, gamma / 4, b * 4.
        """
        return replace(self, mu=self.mu / 4, gamma=self.gamma / 4, b11=4 * self.b11, b12=4 * self.b12,
                       b22=4 * self.b22)


def _check_points(faces, u, v, n_faces):
    faces = np.atleast_1d(np.asarray(faces))
    u = np.atleast_1d(np.asarray(u, dtype=np.float64))
    v = np.atleast_1d(np.asarray(v, dtype=np.float64))
    if not np.issubdtype(faces.dtype, np.integer):
        raise CCProofError("face ids must be integers")
    faces, u, v = np.broadcast_arrays(faces.astype(np.int64), u, v)
    if not (np.isfinite(u).all() and np.isfinite(v).all()):
        raise CCProofError("parameters (u, v) must be finite")
    if ((u < 0) | (u > 1) | (v < 0) | (v > 1)).any():
        raise CCProofError("parameters (u, v) must lie in [0, 1]^2")
    if ((faces < 0) | (faces >= n_faces)).any():
        raise CCProofError(f"face ids must lie in [0, {n_faces})")
    return faces.reshape(-1), u.reshape(-1), v.reshape(-1)


def _rows_to_csr(groups, key, shape):
    """The CSR matrix of the rows ``key`` of ``groups`` (points, vertex ids, rows dict; every point in one group),
    written in place (no triplet arrays: a fine model's bases were 3 times their size while built); the same
    matrix as from the triplets (entries of a row in the group's order, then duplicates summed, indices sorted).
    The group's rows of ``key`` are dropped once placed."""
    m, n = shape
    length = np.zeros(m, dtype=np.int64)
    for pts, ids, _ in groups:
        length[pts] = ids.shape[1]
    indptr = np.zeros(m + 1, dtype=np.int64)
    np.cumsum(length, out=indptr[1:])
    nnz = int(indptr[-1])
    itype = np.int32 if max(nnz, n) < 2**31 else np.int64
    data = np.empty(nnz, dtype=groups[0][2][key].dtype)
    indices = np.empty(nnz, dtype=itype)
    for pts, ids, rows in groups:
        w = ids.shape[1]
        at = (indptr[pts][:, None] + np.arange(w)).reshape(-1)
        data[at] = rows.pop(key).reshape(-1)
        indices[at] = ids.reshape(-1)
    M = sp.csr_matrix((data, indices, indptr.astype(itype)), shape=(m, n))
    M.sum_duplicates()
    return M


class DynamicSurface:
    """Finite-element model of a dynamic Catmull-Clark surface on a control mesh (qmv98 sections 2-3).

    Parameters
    ----------
    mesh : ccproof.mesh.QuadMesh
        The initial mesh; extraordinary vertices must be isolated (no face with two of them).
        ``mesh.vertices`` is only the default state; the dynamics work on separate arrays ``P``.
    material : Material, optional
    levels : int
        Truncation level L of the special-element stiffness sums (the mass is exact).
    face_swap : bool array (m,), optional
        Faces whose tension/rigidity directions are exchanged (``a11 <-> a22``, ``b11 <-> b22``).
        :meth:`refine` sets it so that the child faces, whose parameters
        :func:`ccproof.mesh.subdivide` rotates by a quarter turn at odd corners, keep the directions
        of their parent; irrelevant for isotropic material (``a11 = a22``, ``b11 = b22``).

    Attributes
    ----------
    layout : ccproof.apps.dynamics.elements.ElementLayout

    Examples
    --------
    The limit surface of the cube with corners (+-1, +-1, +-1) (twice subdivided: the same surface)
    passes through the limit point (-1/2, -1/2, -1/2) of a corner (mask (n^2 v + 4 sum e + sum d) /
    (n (n + 5)), n = 3) and (0, 0, -68/81) of a face centre (one step by hand, then the regular mask):

    >>> import numpy as np
    >>> from ccproof.apps.dynamics.meshes import paper_initial_model
    >>> m = DynamicSurface(paper_initial_model())
    >>> f = np.repeat(np.arange(96), 4)
    >>> P = m.evaluator().evaluate(f, np.tile([0, 1, 0, 1.0], 96), np.tile([0, 0, 1, 1.0], 96))["P"]
    >>> [bool(np.isclose(P, x).all(axis=1).any()) for x in ([-0.5, -0.5, -0.5], [0, 0, -68 / 81])]
    [True, True]
    """

    def __init__(self, mesh, material=None, levels=8, face_swap=None):
        if material is None:
            material = Material()
        if not isinstance(material, Material):
            raise CCProofError(f"material must be a Material, got {type(material).__name__}")
        if int(levels) != levels or levels < 1:
            raise CCProofError(f"truncation level must be an integer >= 1, got {levels!r}")
        self.mesh = mesh
        self.material = material
        self.levels = int(levels)
        from ccproof.apps.control_mesh import TaggedQuadMesh
        from ccproof.apps.dynamics.tagged import tagged_layout

        if isinstance(mesh, TaggedQuadMesh):
            self.layout, self.tagged_faces = tagged_layout(mesh)
        else:
            self.layout, self.tagged_faces = element_layout(mesh), np.zeros(0, dtype=np.int64)
        self._tagged = None
        if face_swap is None:
            face_swap = np.zeros(mesh.n_faces, dtype=bool)
        face_swap = np.asarray(face_swap, dtype=bool)
        if face_swap.shape != (mesh.n_faces,):
            raise CCProofError(f"face_swap must have shape ({mesh.n_faces},), got {face_swap.shape}")
        self.face_swap = face_swap
        if self.layout.n_patch_faces == 0:
            raise CCProofError("the mesh has no face with a limit patch (every face touches the boundary or is a "
                               "hole)")
        self._pattern = None
        self._special_cache = None

    # ------------------------------------------------------------------ basics
    @property
    def n_vertices(self):
        return self.mesh.n_vertices

    @property
    def vertices(self):
        """The mesh's control points (the default state), (n, 3)."""
        return np.array(self.mesh.vertices)

    def normal_element_matrices(self, swap=False):
        """Unit mass and material stiffness of a normal element (16 x 16 each)."""
        coef = self.material.term_coefficients(swap=swap)
        K = sum(c * term_matrix(t) for t, c in coef.items())
        return term_matrix("mass"), K

    def _nets_t(self):
        if getattr(self, "_nets_transposed", None) is None:
            self._nets_transposed = np.ascontiguousarray(self.layout.normal_nets.T)
        return self._nets_transposed

    def _normal_swap(self):
        return self.face_swap[self.layout.normal_faces]

    def tagged_elements(self):
        """The :class:`~ccproof.apps.dynamics.tagged.TaggedElement` of every tagged face (built once)."""
        if self._tagged is None:
            from ccproof.apps.control_mesh import tags_of
            from ccproof.apps.dynamics.tagged import TaggedElement

            es, vs = tags_of(self.mesh)
            self._tagged = [TaggedElement(self.mesh, f, es, vs, self.levels) for f in self.tagged_faces.tolist()]
        return self._tagged

    def _tagged_coefficients(self, f):
        return lambda swap: self.material.term_coefficients(swap=bool(swap) ^ bool(self.face_swap[f]))

    def special_element_matrices(self):
        """Per special element, then per tagged element: ``(control set, unit mass, material stiffness)``.

        Special elements: the EV's two-ring, the mass exact (Stein), the stiffness of levels 1..L; tagged
        elements (:mod:`ccproof.apps.dynamics.tagged`): the face's two-ring, the mass to rounding, the
        stiffness to depth L.
        """
        if self._special_cache is None:
            out = []
            lay = self.layout
            for e in range(lay.n_special):
                n = int(lay.special_valence[e])
                S = special_scheme(n)
                sums, _, _ = S.stiffness_truncated(self.levels)
                K = np.zeros((S.d, S.d))
                for j, (f, c) in enumerate(zip(lay.special_faces[e], lay.special_corners[e])):
                    coef = self.material.term_coefficients(swap=bool(c % 2) ^ bool(self.face_swap[f]))
                    for t in STIFFNESS_TERMS:
                        if coef[t]:
                            K += coef[t] * sums[t][j]
                out.append((lay.special_rings[e], S.mass_exact(), K))
            for el in self.tagged_elements():
                M, K = el.matrices(self._tagged_coefficients(el.face))
                out.append((el.ids, M, K))
            self._special_cache = out
        return self._special_cache

    # ------------------------------------------------------------------ assembly
    def _coo_indices(self):
        if self._pattern is None:
            lay = self.layout
            nets = lay.normal_nets
            r = [np.repeat(nets, 16, axis=1).reshape(-1)]
            c = [np.tile(nets, (1, 16)).reshape(-1)]
            for ring, _, _ in self.special_element_matrices():
                r.append(np.repeat(ring, ring.size))
                c.append(np.tile(ring, ring.size))
            self._pattern = (np.concatenate(r), np.concatenate(c))
        return self._pattern

    def assemble(self, c_mass=0.0, c_stiff=1.0):
        """Sparse ``c_mass M1 + c_stiff K`` (n x n CSR), summed element by element.

        ``M1`` is the unit-density mass (``M = mu M1``, ``D = gamma M1``), ``K`` the stiffness of
        the material.
        """
        rows, cols = self._coo_indices()
        vals = [self._normal_combined(c_mass, c_stiff).reshape(-1)]
        for _, Ms, Ks in self.special_element_matrices():
            vals.append((c_mass * Ms + c_stiff * Ks).reshape(-1))
        n = self.n_vertices
        return sp.coo_matrix((np.concatenate(vals), (rows, cols)), shape=(n, n)).tocsr()

    def _normal_combined(self, c_mass, c_stiff):
        """Element matrices ``c_mass M1_e + c_stiff K_e`` of every normal element, (Nn, 16, 16)."""
        sw = self._normal_swap()
        out = np.empty((sw.size, 16, 16))
        for flag in (False, True):
            sel = np.flatnonzero(sw == flag)
            if sel.size:
                Mn, Kn = self.normal_element_matrices(swap=flag)
                out[sel] = c_mass * Mn + c_stiff * Kn
        return out

    def diagonal(self, c_mass=0.0, c_stiff=1.0):
        """Diagonal of ``c_mass M1 + c_stiff K`` from the element matrices (no global matrix)."""
        n = self.n_vertices
        d = np.zeros(n)
        if self.layout.n_normal:
            Ke = self._normal_combined(c_mass, c_stiff)
            d += np.bincount(self.layout.normal_nets.reshape(-1),
                             weights=np.diagonal(Ke, axis1=1, axis2=2).reshape(-1), minlength=n)
        for ring, Ms, Ks in self.special_element_matrices():
            np.add.at(d, ring, np.diag(c_mass * Ms + c_stiff * Ks))
        return d

    def mass_matrix(self):
        """``M = mu M1`` (sparse)."""
        return self.assemble(self.material.mu, 0.0)

    def damping_matrix(self):
        """``D = gamma M1`` (sparse)."""
        return self.assemble(self.material.gamma, 0.0)

    def stiffness_matrix(self):
        """``K`` (sparse), special elements truncated at level L."""
        return self.assemble(0.0, 1.0)

    def matvec(self, X, c_mass=0.0, c_stiff=1.0):
        """Matrix-free ``(c_mass M1 + c_stiff K) X`` element by element (X: (n,) or (n, k))."""
        X = np.asarray(X, dtype=np.float64)
        vec = X.ndim == 1
        X2 = X[:, None] if vec else X
        n = self.n_vertices
        Y = np.zeros_like(X2)
        lay = self.layout
        if lay.n_normal:
            sw = self._normal_swap()
            kk = X2.shape[1]
            for flag in (False, True):
                if sw.any() == sw.all():  # one element matrix for all normal elements
                    if flag != bool(sw[0]):
                        continue
                    netsT = self._nets_t()
                else:
                    netsT = lay.normal_nets[sw == flag].T
                if not netsT.size:
                    continue
                # (16, E): one GEMM for all elements and columns
                Mn, Kn = self.normal_element_matrices(swap=flag)
                Ye = ((c_mass * Mn + c_stiff * Kn) @ X2[netsT].reshape(16, -1)).reshape(16, -1, kk)
                flat = netsT.reshape(-1)
                for k in range(kk):
                    Y[:, k] += np.bincount(flat, weights=Ye[:, :, k].reshape(-1), minlength=n)
        for ring, Ms, Ks in self.special_element_matrices():
            np.add.at(Y, ring, (c_mass * Ms + c_stiff * Ks) @ X2[ring])
        return Y[:, 0] if vec else Y

    def energy(self, P):
        """Elastic energy ``1/2 tr(P^T K P)`` of the state P (n, 3)."""
        P = np.asarray(P, dtype=np.float64)
        return 0.5 * float(np.sum(P * self.matvec(P)))

    # ------------------------------------------------------------------ truncation report
    def truncation_report(self, P=None):
        """How much of each special element's stiffness series the truncation at level L keeps.

        For every special element: the valence n, the per-level ratios of the tension (lam^2) and
        rigidity (4 lam^2) series, the Frobenius norms of the truncated stiffness and of its level-L
        increment, and the geometric estimate of the neglected tail (``inf`` when the rigidity
        series diverges, n >= 5). With ``P`` the same numbers are given as energies
        ``1/2 tr(P_e^T X P_e)`` of the element's ring.

        Then one record per tagged element: ``{"face", "levels", "stiffness": {...}}`` with the same numbers for
        its whole stiffness, the ratio measured between its last two depth increments (no closed form).
        """
        from ccproof.algebra.specialize import subdominant_eigenvalue

        out = []
        lay = self.layout
        for e in range(lay.n_special):
            n = int(lay.special_valence[e])
            S = special_scheme(n)
            sums, last, _ = S.stiffness_truncated(self.levels)
            lam = subdominant_eigenvalue(n, "float")
            rec = {"ev": int(lay.special_ev[e]), "valence": n, "levels": self.levels}
            for group, terms, ratio in (("tension", ("uu1", "vv1"), lam**2), ("rigidity", ("uu2", "uv2", "vv2"),
                                                                                4 * lam**2)):
                tot = np.zeros((S.d, S.d))
                inc = np.zeros((S.d, S.d))
                for j, (f, c) in enumerate(zip(lay.special_faces[e], lay.special_corners[e])):
                    coef = self.material.term_coefficients(swap=bool(c % 2) ^ bool(self.face_swap[f]))
                    for t in terms:
                        tot += coef[t] * sums[t][j]
                        inc += coef[t] * last[t][j]
                if P is not None:
                    Pe = np.asarray(P, dtype=np.float64)[lay.special_rings[e]]
                    a = 0.5 * float(np.sum(Pe * (tot @ Pe)))
                    b = 0.5 * float(np.sum(Pe * (inc @ Pe)))
                else:
                    a, b = float(np.linalg.norm(tot)), float(np.linalg.norm(inc))
                tail = b * ratio / (1 - ratio) if ratio < 1 else math.inf
                rec[group] = {"ratio": ratio, "truncated": a, "last_level": b, "tail_estimate": tail}
            out.append(rec)
        for el in self.tagged_elements():
            K, last, ratio = el.truncation(self._tagged_coefficients(el.face), P)
            tail = last * ratio / (1 - ratio) if ratio < 1 else math.inf
            out.append({"face": el.face, "levels": self.levels,
                        "stiffness": {"ratio": ratio, "truncated": K, "last_level": last, "tail_estimate": tail}})
        return out

    # ------------------------------------------------------------------ evaluation
    def _rows(self, faces, u, v, derivatives):
        """Shape-function rows grouped by element type: list of (points, vertex ids, rows dict)."""
        lay = self.layout
        kind = lay.face_kind[faces]
        if (kind == 0).any():
            f = int(faces[np.flatnonzero(kind == 0)[0]])
            raise CCProofError(f"face {f} carries no limit patch (it touches the boundary or is a hole)")
        groups = []
        nrm = np.flatnonzero(kind == 1)
        if nrm.size:
            rows = patch_rows(u[nrm], v[nrm], derivatives)
            groups.append((nrm, lay.normal_nets[lay.face_element[faces[nrm]]], rows))
        spc = np.flatnonzero(kind == 2)
        if spc.size:
            groups += self._special_rows(spc, faces[spc], u[spc], v[spc], derivatives)
        groups += self._tagged_rows(np.flatnonzero(kind == 3), faces, u, v, derivatives)
        return groups

    def _tagged_rows(self, pts, faces, u, v, derivatives):
        groups = []
        els = self.tagged_elements()
        el_of = self.layout.face_element[faces[pts]]
        for e in np.unique(el_of).tolist():
            g = pts[el_of == e]
            rows = els[e].rows(u[g], v[g], derivatives)
            groups.append((g, np.broadcast_to(els[e].ids, (g.size, els[e].ids.size)), rows))
        return groups

    def _special_locate(self, faces, u, v):
        """Element, sector, local level, patch and patch parameter of points on special faces."""
        lay = self.layout
        elem = lay.face_element[faces]
        corner = lay.face_corner[faces]
        sector = lay.face_sector[faces]
        s, t = face_to_sector(corner, u, v)
        m = np.maximum(s, t)
        with np.errstate(divide="ignore"):
            lev = np.where(m > 0, np.floor(-np.log2(np.where(m > 0, m, 1.0))) + 1, MAX_EVAL_LEVEL + 1)
        lev = lev.astype(np.int64)
        # guard the floor against rounding: the level-l patches cover 2^-l <= m <= 2^-(l-1)
        lev = np.where((lev <= MAX_EVAL_LEVEL) & (m * 2.0**lev < 1.0), lev + 1, lev)
        lev = np.where((lev > 1) & (lev <= MAX_EVAL_LEVEL) & (m * 2.0 ** (lev - 1) > 1.0), lev - 1, lev)
        deep = lev > MAX_EVAL_LEVEL
        scale = np.ldexp(1.0, np.minimum(lev, MAX_EVAL_LEVEL))
        xs, ys = s * scale, t * scale
        a = np.minimum(np.floor(xs), 1.0)
        b = np.minimum(np.floor(ys), 1.0)
        q = np.where(a == 1, np.where(b == 1, 1, 0), 2)  # (1,0) -> 0, (1,1) -> 1, (0,1) -> 2
        x = np.clip(xs - a, 0.0, 1.0)
        y = np.clip(ys - b, 0.0, 1.0)
        return elem, sector, corner, lev, deep, q, x, y, scale

    @staticmethod
    def _to_face_derivatives(loc, corner, scale, derivatives, out, idx):
        """Patch-parameter derivatives -> face-parameter derivatives (level scale and sector rotation)."""
        out["P"][idx] = loc["P"]
        if derivatives < 1:
            return
        R = sector_derivative_maps()[corner]
        sc = scale.reshape((-1,) + (1,) * (loc["P"].ndim - 1))
        Ps, Pt = loc["Pu"] * sc, loc["Pv"] * sc

        def r(i, j):
            return R[:, i, j].reshape(sc.shape)

        out["Pu"][idx] = r(0, 0) * Ps + r(0, 1) * Pt
        out["Pv"][idx] = r(1, 0) * Ps + r(1, 1) * Pt
        if derivatives < 2:
            return
        s2 = sc * sc
        H = {(0, 0): loc["Puu"] * s2, (0, 1): loc["Puv"] * s2, (1, 1): loc["Pvv"] * s2}
        H[(1, 0)] = H[(0, 1)]
        for name, (r1, r2) in (("Puu", (0, 0)), ("Puv", (0, 1)), ("Pvv", (1, 1))):
            acc = 0.0
            for a1 in range(2):
                for a2 in range(2):
                    acc = acc + r(r1, a1) * r(r2, a2) * H[(a1, a2)]
            out[name][idx] = acc

    def _special_rows(self, pts, faces, u, v, derivatives):
        lay = self.layout
        elem, sector, corner, lev, deep, q, x, y, scale = self._special_locate(faces, u, v)
        valence = lay.special_valence[elem]
        names = ["P"] + (["Pu", "Pv"] if derivatives >= 1 else []) + (["Puu", "Puv", "Pvv"] if derivatives >= 2 else [])
        groups = []
        for n in np.unique(valence):
            S = special_scheme(int(n))
            sel_n = np.flatnonzero(valence == n)
            ring_ids = np.stack([lay.special_rings[e] for e in elem[sel_n]])
            out = {k: np.zeros((sel_n.size, S.d)) for k in names}
            lv = lev[sel_n]
            dp = deep[sel_n]
            if dp.any():
                out["P"][dp] = S.limit_row
            for level in np.unique(lv[~dp]):
                idx = np.flatnonzero((lv == level) & ~dp)
                g = sel_n[idx]
                pr = patch_rows(x[g], y[g], derivatives)
                # deviation from the limit point (decays like lam^level, no cancellation); the patch
                # rows of P sum to 1 and those of the derivatives to 0, so only P gets the limit row
                T = S.level_deviation(int(level))[S.select[sector[g], q[g]]]  # (g, 16, d)
                loc = {k: np.einsum("gk,gkd->gd", pr[k], T) for k in pr}
                loc["P"] += S.limit_row[None, :]
                self._to_face_derivatives(loc, corner[g], scale[g], derivatives, out, idx)
            groups.append((pts[sel_n], ring_ids, out))
        return groups

    def basis(self, faces, u, v, derivatives=0):
        """Rows of ``J`` (and of its derivatives) at points: dict name -> CSR (m, n).

        ``basis(...)["P"] @ P`` is the limit surface at the points (qmv98 eq. 15, scalar form), ``["Du"] @ P``
        its ``evaluate(...)["Pu"]``, and so on (``"Dv"``, ``"Duu"``, ``"Duv"``, ``"Dvv"``): the keys of the public
        operator :meth:`ccproof.evaluate.surface.LimitSurface.basis`. The
        model's own rows (its special elements, tagged quad meshes); on an untagged QuadMesh they equal the
        public operator's (tested).
        """
        faces, u, v = _check_points(faces, u, v, self.mesh.n_faces)
        groups = self._rows(faces, u, v, derivatives)
        return {_ROW_KEY[k]: _rows_to_csr(groups, k, (faces.size, self.n_vertices)) for k in list(groups[0][2])} \
            if groups else {}

    def evaluate(self, faces, u, v, derivatives=0, P=None):
        """Limit surface (and derivatives in the face parameter) at points: dict name -> (m, 3).

        For many evaluations with the same state use :meth:`evaluator`.
        """
        return self.evaluator(P).evaluate(faces, u, v, derivatives)

    def evaluator(self, P=None):
        """A :class:`LimitEvaluator` of the limit surface of the state P (default: the mesh's vertices)."""
        return LimitEvaluator(self, self.vertices if P is None else P)

    # ------------------------------------------------------------------ multilevel
    def refine(self, P=None, rescale=True):
        """Rebuild the model on the CC-subdivided mesh (qmv98 section 3.4; docs/qmv98.md B4).

        Parameters
        ----------
        P : ndarray (n, 3), optional
            Current state (default: the mesh's vertices).
        rescale : bool
            Use :meth:`Material.refined` so that the energies of a given limit surface are
            unchanged (default); ``False`` keeps the densities per unit face domain.

        Returns
        -------
        model : DynamicSurface
            On ``subdivide(mesh)`` with control points ``A P``.
        A : scipy.sparse.csr_matrix
            The global subdivision matrix (``q = A p``, qmv98 section 2.5.1).
        """
        from ccproof.apps.control_mesh import TaggedQuadMesh, subdivide_control, tagged_step
        from ccproof.mesh import subdivide, subdivision_matrix

        mesh = self.mesh if P is None else self.mesh.with_vertices(P)
        if isinstance(mesh, TaggedQuadMesh):  # the tagged step, tags carried
            A, step = tagged_step(mesh)[0], subdivide_control
        else:
            A, step = subdivision_matrix(mesh), subdivide
        mat = self.material.refined() if rescale else self.material
        # child 4 f + i of face f is rotated by i quarter turns (ccproof.mesh.subdivision)
        swap = np.repeat(self.face_swap, 4) ^ np.tile(np.array([False, True, False, True]), mesh.n_faces)
        return DynamicSurface(step(mesh), mat, self.levels, face_swap=swap), A



def _contract(bu, bv, N, derivatives):
    """Tensor-product evaluation of 4 x 4 nets N (g, 4, 4, 3) (first index along u)."""
    T = [(b[:, None, None, :] @ N)[:, :, 0, :] for b in bv]  # contract along v: (g, 4, 3)

    def c(b, t):
        return (b[:, None, :] @ t)[:, 0, :]

    out = {"P": c(bu[0], T[0])}
    if derivatives >= 1:
        out["Pu"] = c(bu[1], T[0])
        out["Pv"] = c(bu[0], T[1])
    if derivatives >= 2:
        out["Puu"] = c(bu[2], T[0])
        out["Puv"] = c(bu[1], T[1])
        out["Pvv"] = c(bu[0], T[2])
    return out


class LimitEvaluator:
    """Evaluation of the limit surface of one state P with the patch nets cached.

    The nets of the normal faces are gathered once; for the special elements the level-l three-ring
    positions ``(P_l - 1 l^T) P_ring`` are computed once per level that is asked for (qmv98 section
    2.4; docs/qmv98.md). Made by :meth:`DynamicSurface.evaluator`.

    Parameters
    ----------
    model : DynamicSurface
    P : ndarray, shape (n_vertices, 3) float64
        The state (control points).

    Examples
    --------
    A translated state gives the translated surface:

    >>> import numpy as np
    >>> from ccproof.apps.dynamics.meshes import paper_initial_model
    >>> m = DynamicSurface(paper_initial_model())
    >>> f, u, v = np.array([0, 5]), np.array([0.3, 0.0]), np.array([0.6, 0.0])
    >>> a = LimitEvaluator(m, m.vertices).evaluate(f, u, v)["P"]
    >>> b = LimitEvaluator(m, m.vertices + [1.0, 2.0, 3.0]).evaluate(f, u, v)["P"]
    >>> bool(np.allclose(b - a, [1.0, 2.0, 3.0]))
    True
    """

    def __init__(self, model, P):
        P = np.asarray(P, dtype=np.float64)
        if P.shape != (model.n_vertices, 3):
            raise CCProofError(f"control points must have shape ({model.n_vertices}, 3), got {P.shape}")
        if not np.isfinite(P).all():
            raise CCProofError("control points must be finite")
        self.model = model
        self.P = P
        lay = model.layout
        self._normal = P[lay.normal_nets].reshape(-1, 4, 4, 3)
        self._groups = {}
        for n in np.unique(lay.special_valence):
            elems = np.flatnonzero(lay.special_valence == n)
            PR = P[np.stack([lay.special_rings[e] for e in elems])]  # (E, d, 3)
            S = special_scheme(int(n))
            self._groups[int(n)] = (elems, PR, np.einsum("d,edk->ek", S.limit_row, PR), {})
        self._slot = np.full(lay.n_special, -1, dtype=np.int64)
        for elems, *_ in self._groups.values():
            self._slot[elems] = np.arange(elems.size)

    def _level_positions(self, n, level):
        elems, PR, _, cache = self._groups[n]
        if level not in cache:
            cache[level] = np.einsum("cd,edk->eck", special_scheme(n).level_deviation(level), PR)
        return cache[level]

    def evaluate(self, faces, u, v, derivatives=0):
        """Limit surface (and derivatives in the face parameter) at points: dict name -> (m, 3)."""
        if derivatives not in (0, 1, 2):
            raise CCProofError(f"derivatives must be 0, 1 or 2, got {derivatives!r}")
        model = self.model
        faces, u, v = _check_points(faces, u, v, model.mesh.n_faces)
        lay = model.layout
        kind = lay.face_kind[faces]
        if (kind == 0).any():
            f = int(faces[np.flatnonzero(kind == 0)[0]])
            raise CCProofError(f"face {f} carries no limit patch (it touches the boundary or is a hole)")
        names = ["P"] + (["Pu", "Pv"] if derivatives >= 1 else []) + (["Puu", "Puv", "Pvv"] if derivatives >= 2 else [])
        out = {k: np.zeros((faces.size, 3)) for k in names}
        nrm = np.flatnonzero(kind == 1)
        if nrm.size:
            loc = _contract(basis_1d(u[nrm], derivatives), basis_1d(v[nrm], derivatives),
                            self._normal[lay.face_element[faces[nrm]]], derivatives)
            for k in names:
                out[k][nrm] = loc[k]
        spc = np.flatnonzero(kind == 2)
        if spc.size:
            self._special(faces[spc], u[spc], v[spc], derivatives, out, spc)
        for g, ids, rows in model._tagged_rows(np.flatnonzero(kind == 3), faces, u, v, derivatives):
            Pe = self.P[ids[0]]
            for k in names:
                out[k][g] = rows[k] @ Pe
        return out

    def _special(self, faces, u, v, derivatives, out, pts):
        model = self.model
        lay = model.layout
        elem, sector, corner, lev, deep, q, x, y, scale = model._special_locate(faces, u, v)
        valence = lay.special_valence[elem]
        for n in np.unique(valence):
            n = int(n)
            S = special_scheme(n)
            limit = self._groups[n][2]
            sel_n = np.flatnonzero(valence == n)
            dp = deep[sel_n]
            if dp.any():
                g = sel_n[dp]
                out["P"][pts[g]] = limit[self._slot[elem[g]]]
            lv = lev[sel_n]
            for level in np.unique(lv[~dp]):
                g = sel_n[(lv == level) & ~dp]
                Q = self._level_positions(n, int(level))
                nets = Q[self._slot[elem[g]][:, None], S.select[sector[g], q[g]]].reshape(-1, 4, 4, 3)
                loc = _contract(basis_1d(x[g], derivatives), basis_1d(y[g], derivatives), nets, derivatives)
                loc["P"] += limit[self._slot[elem[g]]]
                model._to_face_derivatives(loc, corner[g], scale[g], derivatives, out, pts[g])
