"""Normal and special elements of a dynamic Catmull-Clark surface (qmv98 sections 2.2-2.4,
3.1; docs/qmv98.md B2, B3, B5).

**Element layout.** Every face of the initial (control) mesh is one of

* a *normal face*: its four vertices are interior and of valence 4. Its limit patch is the bicubic
  B-spline on its 4 x 4 net (the face and its eight neighbours), numbered ``k = 4 i + j`` with ``i``
  along the face parameter ``u`` (corner 0 of the face at net position (1, 1), corner 1 at (2, 1),
  corner 2 at (2, 2), corner 3 at (1, 2); ptex convention of :class:`ccproof.mesh.QuadMesh`);
* a *special face*: its four vertices are interior and exactly one of them is extraordinary (valence
  n != 4). The n faces around that extraordinary vertex (EV) form one *special element* whose control
  set is the EV's two-ring (``d = 6 n + 1`` vertices, ordered as
  :func:`ccproof.algebra.subdivision.two_ring_vertices`: the EV, then sector by sector the grid
  positions (1,0), (2,0), (1,1), (2,1), (1,2), (2,2));
* a face without patch: a face with a boundary vertex (qmv98 Figs. 1-3: boundary faces carry no patch;
  the B-spline convention of docs/qmv98.md B7.7), or a face around an EV whose fan contains such a face.

A face with two or more EVs among its interior vertices is rejected: the paper subdivides the mesh
globally first (qmv98 section 2.4.2); :func:`isolate_extraordinary` does that.

**Special elements (docs/qmv98.md B3, qmv98 eqs. 8-12, 26).** Sector j of an EV is the face whose corner c is the
EV; in it the *sector parameter* (s, t) has the EV at (0, 0), s along the edge to e_j = grid (1, 0),
t along the edge to e_{j+1} = grid (0, 1). One local CC step maps the two-ring to the level-1
*three-ring* (``c = 12 n + 1`` vertices: the EV and the positions 1 <= a <= 3, 0 <= b <= 3 of every
sector) by the matrix ``B`` (c x d) and to the level-1 two-ring by ``C`` (d x d, the matrix of
bmz04 Definition 2). The level-l patches (l >= 1) of sector j are the three regular faces (1,0),
(1,1), (0,1) of the level-l grid; their nets are ``Sel_q B C^(l-1) p`` and they cover
``2^-l <= max(s, t) <= 2^-(l-1)``. Integrated over the face parameter, a level-l patch contributes
``scale(l) W^T T W`` with ``W = Sel_q B C^(l-1)`` and ``T`` the unit-square matrix of the integrand
(:func:`ccproof.apps.dynamics.basis.term_matrix`); the per-level scale is the Jacobian of the map
from the patch square to its ``2^-l`` sub-square: ``4^-l`` for the mass/damping, ``4^l * 4^-l = 1``
for the tension (first derivatives) and ``16^l * 4^-l = 4^l`` for the rigidity (second derivatives)
terms. The mass series is summed exactly through the Stein equation
``X = Z/4 + (1/4) C^T X C`` (``Z = B^T Y B``); the stiffness series is truncated at a level L with
the last increment and the geometric tail estimate reported (it diverges for the rigidity terms when
``4 lambda(n)^2 >= 1``, i.e. n >= 5).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
import scipy.linalg

from ccproof.algebra.subdivision import (
    CENTER,
    canonical,
    level1_stencil,
    two_ring_vertices,
)
from ccproof.algebra.subdivision import (
    subdivision_matrix as ring_subdivision_matrix,
)
from ccproof.apps.dynamics.basis import TERMS, term_matrix
from ccproof.errors import MeshError

__all__ = [
    "ElementLayout",
    "element_layout",
    "isolate_extraordinary",
    "SpecialScheme",
    "special_scheme",
    "SECTOR_FROM_FACE",
    "face_to_sector",
    "sector_derivative_maps",
    "STIFFNESS_TERMS",
    "term_scale",
]

#: the stiffness integrands (every key of TERMS but the mass)
STIFFNESS_TERMS = ("uu1", "vv1", "uu2", "uv2", "vv2")

#: level-l patches of a sector: grid faces (1,0), (1,1), (0,1)
SECTOR_PATCHES = ((1, 0), (1, 1), (0, 1))

#: for every corner c of a face, (s, t) = SECTOR_FROM_FACE[c](u, v) puts that corner at (0, 0)
SECTOR_FROM_FACE = (
    lambda u, v: (u, v),
    lambda u, v: (v, 1.0 - u),
    lambda u, v: (1.0 - u, 1.0 - v),
    lambda u, v: (1.0 - v, u),
)

#: (d/du, d/dv) = R_c (d/ds, d/dt) for the corner c of the EV
_DERIV_MAPS = (
    np.array([[1.0, 0.0], [0.0, 1.0]]),
    np.array([[0.0, -1.0], [1.0, 0.0]]),
    np.array([[-1.0, 0.0], [0.0, -1.0]]),
    np.array([[0.0, 1.0], [-1.0, 0.0]]),
)


def face_to_sector(corner, u, v):
    """Sector parameters (s, t) of face parameters (u, v) when the EV is corner ``corner`` (array).

    Parameters
    ----------
    corner : array_like of int, shape (n,)
        Corner (0..3) of the face at the extraordinary vertex.
    u, v : array_like, shape (n,) float64

    Returns
    -------
    s, t : ndarray, shape (n,) float64

    Examples
    --------
    >>> [x.tolist() for x in face_to_sector([1, 2], [0.25, 0.25], [0.5, 0.5])]
    [[0.5, 0.75], [0.75, 0.5]]
    """
    corner = np.asarray(corner)
    u = np.asarray(u, dtype=np.float64)
    v = np.asarray(v, dtype=np.float64)
    s = np.choose(corner % 4, [u, v, 1.0 - u, 1.0 - v])
    t = np.choose(corner % 4, [v, 1.0 - u, 1.0 - v, u])
    return s, t


def sector_derivative_maps():
    """The four 2 x 2 matrices R_c with (d/du, d/dv) = R_c (d/ds, d/dt) (read-only array (4, 2, 2)).

    The rotations between face and sector parameters of :func:`face_to_sector` (docs/qmv98.md).

    Returns
    -------
    ndarray, shape (4, 2, 2) float64, read-only

    Examples
    --------
    Quarter turns: R_1 is the rotation by 90 degrees, and four of them are the identity:

    >>> import numpy as np
    >>> R = sector_derivative_maps()
    >>> R[1].tolist(), bool(np.array_equal(np.linalg.matrix_power(R[1], 4), np.eye(2)))
    ([[0.0, -1.0], [1.0, 0.0]], True)
    """
    R = np.stack(_DERIV_MAPS)
    R.setflags(write=False)
    return R


def term_scale(term, level):
    """Per-level factor of a special-element patch at local level ``level`` (docs/qmv98.md B3).

    Parameters
    ----------
    term : str
        A key of :data:`~ccproof.apps.dynamics.basis.TERMS`.
    level : int

    Returns
    -------
    float

    Examples
    --------
    >>> term_scale("mass", 2), term_scale("uu1", 2), term_scale("uv2", 2)
    (0.0625, 1.0, 16.0)
    """
    order = sum(TERMS[term])
    return 4.0 ** (-level) * 4.0 ** (level * order)


@dataclass(frozen=True)
class ElementLayout:
    """Which face carries which element (see the module docstring).

    Attributes
    ----------
    normal_faces : int (Nn,)
    normal_nets : int (Nn, 16)
        Vertex of net position ``4 i + j`` (i along u).
    special_ev : int (Ns,)
        The extraordinary vertex of each special element.
    special_valence : int (Ns,)
    special_rings : tuple of int arrays (6 n + 1,)
        The two-ring of each EV (module docstring order).
    special_faces, special_corners : tuple of int arrays (n,)
        Face of sector j and the corner of that face at the EV.
    face_kind : int (m,)
        0: no patch, 1: normal, 2: special.
    face_element : int (m,)
        Index into the normal (kind 1) or special (kind 2) elements; -1 for kind 0.
    face_sector : int (m,)
        Sector j of a special face; -1 otherwise.
    face_corner : int (m,)
        Corner of a special face at its EV; -1 otherwise.
    skipped_ev : int array
        Interior EVs that got no special element (a face of their fan touches the boundary).

    Examples
    --------
    The cube subdivided twice: 8 valence-3 vertices, each with a special element of 3 faces; the
    other 96 - 24 faces are normal:

    >>> from ccproof.apps.dynamics.meshes import paper_initial_model
    >>> lay = element_layout(paper_initial_model())
    >>> lay.special_valence.tolist(), lay.normal_faces.size, lay.normal_nets.shape[1]
    ([3, 3, 3, 3, 3, 3, 3, 3], 72, 16)
    """

    normal_faces: np.ndarray
    normal_nets: np.ndarray
    special_ev: np.ndarray
    special_valence: np.ndarray
    special_rings: tuple
    special_faces: tuple
    special_corners: tuple
    face_kind: np.ndarray
    face_element: np.ndarray
    face_sector: np.ndarray
    face_corner: np.ndarray
    skipped_ev: np.ndarray

    @property
    def n_normal(self):
        return int(self.normal_faces.size)

    @property
    def n_special(self):
        return int(self.special_ev.size)

    @property
    def n_patch_faces(self):
        """Number of faces that carry (part of) a limit surface patch."""
        return int((self.face_kind > 0).sum())


def normal_nets(mesh, faces):
    """4 x 4 nets of normal faces by half-edge walks (each corner of valence 4, interior)."""
    Ff = mesh.faces.reshape(-1)
    tw, nxt, prv = mesh.twin, mesh.halfedges.nxt, mesh.halfedges.prv
    nets = np.empty((faces.size, 16), dtype=np.int64)
    pos = ((1, 1), (2, 1), (2, 2), (1, 2))
    fwd = ((1, 0), (0, 1), (-1, 0), (0, -1))
    left = ((0, 1), (-1, 0), (0, -1), (1, 0))
    for c in range(4):
        h = 4 * faces + c
        t = tw[h]
        x1 = Ff[nxt[nxt[t]]]
        t2 = tw[nxt[t]]
        x3 = Ff[nxt[nxt[t2]]]
        x4 = Ff[prv[t2]]
        (pi, pj), (fi, fj), (li, lj) = pos[c], fwd[c], left[c]
        nets[:, 4 * pi + pj] = Ff[h]
        nets[:, 4 * (pi - li) + (pj - lj)] = x1
        nets[:, 4 * (pi - fi) + (pj - fj)] = x3
        nets[:, 4 * (pi - fi - li) + (pj - fj - lj)] = x4
    return nets


def _two_ring(mesh, ev):
    """Two-ring of an interior EV whose fan faces are all interior (module docstring order)."""
    F = mesh.faces
    Ff = F.reshape(-1)
    tw, nxt, prv = mesh.twin, mesh.halfedges.nxt, mesh.halfedges.prv
    corners = mesh.fan_corners[mesh.fan_ptr[ev] : mesh.fan_ptr[ev + 1]]
    f, c = corners // 4, corners % 4
    p10 = Ff[nxt[corners]]
    p11 = F[f, (c + 2) % 4]
    t = tw[nxt[corners]]
    p20 = Ff[nxt[nxt[t]]]
    p21 = Ff[prv[t]]
    t2 = tw[prv[t]]
    p22 = Ff[nxt[nxt[t2]]]
    p12 = Ff[prv[t2]]
    ring = np.stack([p10, p20, p11, p21, p12, p22], axis=1).reshape(-1)
    return np.r_[ev, ring], f, c


def special_elements(mesh, evs, kind, elem, sector, corner):
    """The special elements of the extraordinary vertices ``evs``, marked in the face arrays (in place).

    Face f of EV ``evs[e]``'s fan gets ``kind[f] = 2``, ``elem[f] = e``, its sector and the corner of the EV.

    Returns
    -------
    dict
        The ``special_*`` fields of :class:`ElementLayout`.
    """
    rings, sfaces, scorners = [], [], []
    for e, ev in enumerate(evs):
        ring, f, c = _two_ring(mesh, ev)
        rings.append(ring)
        sfaces.append(f)
        scorners.append(c)
        kind[f] = 2
        elem[f] = e
        sector[f] = np.arange(f.size)
        corner[f] = c
    return dict(special_ev=np.array(evs, dtype=np.int64),
                special_valence=np.asarray(mesh.valence, dtype=np.int64)[np.array(evs, dtype=np.int64)],
                special_rings=tuple(rings), special_faces=tuple(sfaces), special_corners=tuple(scorners))


def element_layout(mesh):
    """Assign normal and special elements to the faces of ``mesh`` (module docstring).

    Parameters
    ----------
    mesh : ccproof.mesh.QuadMesh

    Returns
    -------
    ElementLayout

    Raises
    ------
    MeshError
        If a face with all vertices interior has two or more extraordinary vertices.

    Examples
    --------
    >>> from ccproof.mesh import subdivide
    >>> from ccproof.mesh.examples import cube
    >>> lay = element_layout(subdivide(subdivide(cube())))
    >>> lay.n_normal, lay.n_special, [int(k) for k in lay.special_valence]
    (72, 8, [3, 3, 3, 3, 3, 3, 3, 3])
    """
    F = mesh.faces
    m = mesh.n_faces
    interior_v = ~mesh.is_boundary_vertex
    is_ev = interior_v & (mesh.valence != 4)
    all_interior = interior_v[F].all(axis=1)
    n_ev = is_ev[F].sum(axis=1)
    bad = np.flatnonzero(all_interior & (n_ev >= 2))
    if bad.size:
        f = int(bad[0])
        evs = [int(v) for v in F[f] if is_ev[v]]
        raise MeshError(
            f"face {f} has {len(evs)} extraordinary vertices {evs}: qmv98 needs isolated extraordinary "
            "vertices; subdivide the mesh globally first (isolate_extraordinary)"
        )
    kind = np.zeros(m, dtype=np.int64)
    elem = np.full(m, -1, dtype=np.int64)
    sector = np.full(m, -1, dtype=np.int64)
    corner = np.full(m, -1, dtype=np.int64)
    normal = np.flatnonzero(all_interior & (n_ev == 0))
    kind[normal] = 1
    elem[normal] = np.arange(normal.size)
    nets = normal_nets(mesh, normal)

    evs, skipped = [], []
    for ev in np.flatnonzero(is_ev):
        fan_faces = mesh.fan_corners[mesh.fan_ptr[ev] : mesh.fan_ptr[ev + 1]] // 4
        (evs if all_interior[fan_faces].all() else skipped).append(int(ev))
    lay = ElementLayout(
        normal_faces=normal,
        normal_nets=nets,
        **special_elements(mesh, evs, kind, elem, sector, corner),
        face_kind=kind,
        face_element=elem,
        face_sector=sector,
        face_corner=corner,
        skipped_ev=np.array(skipped, dtype=np.int64),
    )
    return lay


def isolate_extraordinary(mesh, max_steps=2):
    """Subdivide ``mesh`` globally until no face has two extraordinary vertices (qmv98 section 2.4.2).

    Returns ``(mesh, steps)``.

    Parameters
    ----------
    mesh : QuadMesh
    max_steps : int, optional

    Returns
    -------
    mesh : QuadMesh
    steps : int

    Examples
    --------
    >>> from ccproof.mesh.examples import cube
    >>> m, steps = isolate_extraordinary(cube())
    >>> m.n_vertices, steps
    (26, 1)
    """
    from ccproof.mesh import subdivide

    steps = 0
    while True:
        interior_v = ~mesh.is_boundary_vertex
        is_ev = interior_v & (mesh.valence != 4)
        if not (is_ev[mesh.faces].sum(axis=1) >= 2).any():
            return mesh, steps
        if steps >= max_steps:
            raise MeshError(f"extraordinary vertices still share a face after {steps} global subdivisions")
        mesh = subdivide(mesh)
        steps += 1


# ---------------------------------------------------------------------------- special scheme


def _three_ring_vertices(n):
    return [CENTER] + [(j, a, b) for j in range(n) for a in (1, 2, 3) for b in (0, 1, 2, 3)]


class SpecialScheme:
    """Per-valence data of a special element (module docstring): ``B``, ``C``, patch selections, sums.

    Parameters
    ----------
    n : int
        Valence of the extraordinary vertex (>= 3, != 4 in practice; 4 works as a check).

    Attributes
    ----------
    B : ndarray (12 n + 1, 6 n + 1)
        Level-0 two-ring -> level-1 three-ring (one local CC step, exact weights rounded once).
    C : ndarray (6 n + 1, 6 n + 1)
        Level-0 two-ring -> level-1 two-ring (bmz04 Definition 2).
    select : int ndarray (n, 3, 16)
        Three-ring index of net position ``4 alpha + beta`` of patch q of sector j
        (alpha along s; patches :data:`SECTOR_PATCHES`).
    limit_row : ndarray (6 n + 1,)
        Limit position mask of the EV ``(n^2 v + 4 sum e + sum d) / (n (n + 5))``.

    Examples
    --------
    >>> S = SpecialScheme(5)
    >>> S.C.shape, S.select.shape, round(float(S.limit_row.sum()), 12), round(float(S.limit_row[0]), 12)
    ((31, 31), (5, 3, 16), 1.0, 0.5)
    """

    def __init__(self, n):
        self.n = n = int(n)
        two = two_ring_vertices(n)
        three = _three_ring_vertices(n)
        i2 = {v: i for i, v in enumerate(two)}
        i3 = {v: i for i, v in enumerate(three)}
        self.d, self.c = len(two), len(three)
        B = np.zeros((self.c, self.d))
        for r, vert in enumerate(three):
            for w, src in level1_stencil(n, vert):
                B[r, i2[src]] += float(w)
        self.B = B
        self.C = B[[i3[v] for v in two]]
        Cexact = ring_subdivision_matrix(n, "two_ring")
        if not np.array_equal(self.C, np.array([[float(x) for x in row] for row in Cexact])):
            raise AssertionError("three-ring and two-ring subdivision matrices disagree")  # pragma: no cover
        sel = np.empty((n, 3, 16), dtype=np.int64)
        for j in range(n):
            for q, (a, b) in enumerate(SECTOR_PATCHES):
                for al in range(4):
                    for be in range(4):
                        d_, a2, b2 = canonical(a - 1 + al, b - 1 + be)
                        key = CENTER if (a2, b2) == (0, 0) else ((j + d_) % n, a2, b2)
                        sel[j, q, 4 * al + be] = i3[key]
        self.select = sel
        lr = np.zeros(self.d)
        lr[0] = n * n
        for j in range(n):
            lr[i2[(j, 1, 0)]] += 4
            lr[i2[(j, 1, 1)]] += 1
        self.limit_row = lr / (n * (n + 5))
        # P_l = B C^(l-1) = 1 l^T + Dev_l with Dev_l = B (C - 1 l^T)^(l-1) - [l = 1] 1 l^T: the deviations
        # decay like lam^l, so stiffness increments and deep evaluations suffer no cancellation
        self._chat = self.C - np.outer(np.ones(self.d), self.limit_row)
        self._devs = [B - np.outer(np.ones(self.c), self.limit_row), B @ self._chat]
        # per-sector, per-term three-ring Gram sums Y[t][j] = sum_q Sel^T T Sel
        Y = {}
        for t in TERMS:
            T = term_matrix(t)
            Yt = np.zeros((n, self.c, self.c))
            for j in range(n):
                for q in range(3):
                    s = sel[j, q]
                    np.add.at(Yt[j], (s[:, None], s[None, :]), T)
            Y[t] = Yt
        self._Y = Y
        self._stiff_cache = {}
        self._mass = None

    def level_deviation(self, level):
        """``P_l - 1 l^T`` (c x d) with ``P_l = B C^(l-1)`` and ``l`` the limit row (cached).

        Computed as ``B (C - 1 l^T)^(l-1)`` (l >= 2), which decays like ``lam(n)^l`` without
        cancellation.
        """
        if level < 1:
            raise ValueError(f"level must be >= 1, got {level}")
        while len(self._devs) < level:
            self._devs.append(self._devs[-1] @ self._chat)
        return self._devs[level - 1]

    def level_map(self, level):
        """``P_l = B C^(l-1)`` (c x d), the level-0 two-ring -> level-l three-ring map."""
        return self.level_deviation(level) + self.limit_row[None, :]

    def level_increment(self, term, level, sector=None):
        """Contribution of the level-``level`` patches to the ``term`` matrix (d x d, unit coefficient).

        ``sector=None`` sums the n sectors (valid for the mass and for isotropic material only).
        """
        # the stiffness integrands annihilate constants: use the deviation (no cancellation)
        P = self.level_map(level) if term == "mass" else self.level_deviation(level)
        Y = self._Y[term].sum(axis=0) if sector is None else self._Y[term][sector]
        return term_scale(term, level) * (P.T @ Y @ P)

    def mass_truncated(self, L):
        """``sum_{l=1..L}`` of the unit-density mass increments (d x d)."""
        return sum(self.level_increment("mass", l) for l in range(1, L + 1))

    def mass_exact(self):
        """The infinite unit-density mass sum, from the Stein equation ``X = Z/4 + (1/4) C^T X C``."""
        if self._mass is None:
            Z = self.B.T @ self._Y["mass"].sum(axis=0) @ self.B
            X = scipy.linalg.solve_discrete_lyapunov(0.5 * self.C.T, 0.25 * Z)
            X = 0.5 * (X + X.T)
            X.setflags(write=False)
            self._mass = X
        return self._mass

    def stiffness_truncated(self, L):
        """Per-sector, per-term truncated stiffness sums and their last increments.

        Returns
        -------
        sums : dict term -> ndarray (n, d, d)
            ``sum_{l=1..L}`` of the level increments of each sector, unit coefficient.
        last : dict term -> ndarray (n, d, d)
            The level-L increment.
        prev : dict term -> ndarray (n, d, d)
            The level-(L-1) increment (zeros when L = 1).
        """
        if L < 1:
            raise ValueError(f"truncation level L must be >= 1, got {L}")
        if L not in self._stiff_cache:
            sums, last, prev = {}, {}, {}
            for t in STIFFNESS_TERMS:
                acc = np.zeros((self.n, self.d, self.d))
                inc_prev = np.zeros_like(acc)
                inc = np.zeros_like(acc)
                for lev in range(1, L + 1):
                    P = self.level_deviation(lev)
                    inc_prev = inc
                    inc = term_scale(t, lev) * np.einsum("ca,jce,eb->jab", P, self._Y[t], P, optimize=True)
                    acc = acc + inc
                sums[t], last[t], prev[t] = acc, inc, inc_prev
            self._stiff_cache[L] = (sums, last, prev)
        return self._stiff_cache[L]


@functools.cache
def special_scheme(n):
    """Cached :class:`SpecialScheme` of valence ``n``.

    Parameters
    ----------
    n : int
        Valence, n >= 3.

    Returns
    -------
    SpecialScheme

    Examples
    --------
    >>> S = special_scheme(3)
    >>> S.B.shape, S.C.shape, round(float(S.mass_exact().sum()), 12)     # 1^T M 1 = n (unit density)
    ((37, 19), (19, 19), 3.0)
    """
    return SpecialScheme(n)
