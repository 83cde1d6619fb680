"""A hierarchical space graded toward the extraordinary vertices (local refinement of the subdivision space).

Near an extraordinary vertex (EV) of valence n the uniform space is deficient: its functions on the EV's
ring reproduce linear functions but not quadratic ones, and that ring shrinks like ``lam^L`` (lam the
subdominant eigenvalue, :func:`ccproof.reparam.quadrant.subdominant_lambda`) while the mesh size is
``2^-L``. The L2 and H1 errors there are ``lam^(3L)`` and ``lam^(2L)``, slower than the regular
``2^(-4L)``, ``2^(-3L)`` at every valence but 4 (rates 3 log2(1/lam), 2 log2(1/lam): 3.86 / 2.57 at
valence 3, 2.59 / 1.72 at 5, 2.36 / 1.57 at 6). Refining ``s`` more levels around the EV shrinks its ring
to ``lam^(L+s)``; its own errors fall at the regular rates when ``(L + s) log2(1/lam)`` is at least
``4L / 3`` (L2) and ``3L / 2`` (H1): :func:`graded_levels`. The regular faces a fixed number of rings
around it keep the EV's rates too, so the refined region must also be wide on the first extra levels
(a fixed fraction of a level-0 face, narrowing level by level): :func:`graded_rings`.

Levels ``j = 0 .. max s`` are the mesh subdivided ``j`` more times, level ``j > 0`` only *locally*: the
faces within a few rings of the EVs graded that deep are cut out of level ``j - 1`` and subdivided
(QuadMesh child ``4 k + i`` covers the quarter of kept face k at corner i,
:mod:`ccproof.mesh.subdivision`), with a margin so that every face used is exactly a face of the uniform
level-j mesh (same patch, same control points). The domain ``Omega_j`` of level j is the set of its faces
within ``rings`` face rings of those EVs (a number per EV and level, :func:`graded_rings`; children of
``Omega_(j-1)``). The space is Kraft's hierarchical
basis: the level-j limit functions whose support lies in ``Omega_j`` but not in the faces whose children
all lie in ``Omega_(j+1)``. Every function is an exact limit function of its level's control vertex (rows
of :meth:`LimitSurface.basis <ccproof.evaluate.surface.LimitSurface.basis>` of that level's surface, the
same geometric surface at every level), so the space is nested in the uniform space of the finest level;
the quadrature is the adaptive rule on the leaves of the refinement. With ``rings >= 5`` the faces of
the second ring of level j get all their level-j functions (a function's support is two face rings
around its vertex), so each dyadic ring around the EV is resolved at its own level.

With ``vertices`` the space is graded toward given vertices instead, boundary vertices included (a
boundary EV, whose ring's height contracts by a measured ``mu``: ``lam=mu`` in :func:`graded_levels` and
:func:`graded_rings`), and :func:`solve_graded` takes a ``region`` of an open mesh with the natural
boundary condition (docs/iga.md, the fans).

>>> from ccproof.mesh.examples import cube
>>> H = HierarchicalSpace(cube(), extra=1, rings=1)
>>> H.n_dofs, [int(a.sum()) for a in H.active]          # 8 coarse functions replaced near the 8 EVs
(26, [0, 26])
>>> graded_levels(3, 4), graded_levels(5, 4), graded_levels(6, 4), graded_levels(4, 4)
(2, 4, 5, 0)
"""

from __future__ import annotations

import math

import numpy as np
import scipy.sparse as sp

from ccproof.apps.iga.quadrature import cells_rule, quadrature_cells
from ccproof.errors import CCProofError
from ccproof.reparam.quadrant import subdominant_lambda

__all__ = ["HierarchicalSpace", "parent_points", "solve_graded", "graded_levels", "graded_rings"]

#: corner c_i of a face, and the directions of a child's s and t axes (toward corners i+1 and i-1)
_C = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
_D1 = np.roll(_C, -1, axis=0) - _C
_D2 = np.roll(_C, 1, axis=0) - _C


def graded_levels(valence, level, margin=1, lam=None, orders=(3, 2)):
    """Extra levels ``s`` around an EV of ``valence`` on a mesh of uniform ``level`` L (h ~ 2^-L) so that
    its ring's errors ``lam^(3(L+s))`` (L2) and ``lam^(2(L+s))`` (H1) fall like the regular ``2^(-4L)`` and
    ``2^(-3L)``: ``ceil(L (max(4 / (3 a), 3 / (2 a)) - 1)) + margin`` with ``a = log2(1/lam)``; 0 at valence 4.

    With ``lam`` (a boundary EV's cross-boundary contraction, docs/iga.md) the errors are ``lam^(p L)``,
    ``lam^(q L)`` for ``orders = (p, q)`` (``(4, 3)`` for a solution with no quadratic part at the vertex).

    >>> [graded_levels(5, L, 0) for L in range(6)]
    [0, 1, 2, 3, 3, 4]
    """
    if valence == 4 and lam is None:
        return 0
    a = -math.log2(subdominant_lambda(valence) if lam is None else float(lam))
    p, q = orders
    return max(0, math.ceil(level * (max(4 / (p * a), 3 / (q * a)) - 1) - 1e-12)) + int(margin)


def graded_rings(valence, level, j, rings=5, width=0.5, lam=None):
    """Face rings of level ``L + j`` refined around an EV of ``valence`` on a mesh of uniform ``level`` L:
    ``max(rings, ceil(width 2^L 2^(-j (1/g - 1))))``, g = ``1 - log2(1/lam) / 3``.

    Why (the module docstring's error model, continued): on a regular face near the EV the solution in
    the face's own coordinates has fourth derivatives ``~ rho^(2a - 4)`` (rho the distance to the EV in the
    level-0 parameter, a = log2(1/lam)), so the faces at a *fixed* number of rings around the EV keep the
    EV's rates, not only its one-ring. A mesh size ``h(rho) = 2^-L rho^g`` gives L2 and H1 errors
    ``2^(-4L)``, ``2^(-3L)`` for ``g > 1 - 3a/4`` and ``g > 1 - 2a/3``, and a bounded share of extra
    dofs for ``g < 1``; g = 1 - a/3 is between. Level ``L + j`` is then needed for
    ``rho <= 2^(-j/g)``: ``2^(L + j - j/g)`` of its rings, times ``width`` (rho where the grading starts,
    in level-0 faces), and at least ``rings``.

    ``lam`` replaces the subdominant eigenvalue (a boundary EV's cross-boundary contraction).

    >>> [graded_rings(5, 5, j) for j in range(1, 6)], [graded_rings(3, 5, j) for j in (1, 2)]
    ([13, 10, 7, 6, 5], [10, 6])
    """
    a = -math.log2(subdominant_lambda(valence) if lam is None else float(lam))
    g = 1 - a / 3
    return max(int(rings), math.ceil(width * 2.0 ** (level - j * (1 / g - 1)) - 1e-9))


def parent_points(f, s, t):
    """Points of child faces (level j + 1) as points of their parents (level j): ``(f // 4, u, v)``.

    >>> import numpy as np
    >>> [round(float(x), 3) for x in np.concatenate(parent_points(np.array([5]), np.array([0.5]),
    ...                                                            np.array([0.25]))[1:])]
    [0.875, 0.25]
    """
    i = f % 4
    uv = _C[i] + 0.5 * s[:, None] * _D1[i] + 0.5 * t[:, None] * _D2[i]
    return f // 4, uv[:, 0], uv[:, 1]


def _face_rings(mesh, vertices, rings):
    """Faces within ``rings`` face rings (through shared vertices) of ``vertices``, bool (m,)."""
    F = np.asarray(mesh.faces)
    near_v = np.zeros(mesh.n_vertices, dtype=bool)
    near_v[np.asarray(vertices, dtype=np.int64)] = True
    near_f = np.zeros(F.shape[0], dtype=bool)
    for _ in range(rings):
        near_f = near_v[F].any(axis=1)
        near_v[F[near_f]] = True
    return near_f


def _local_child(mesh, keep):
    """Subdivide the faces ``keep`` (bool) of ``mesh`` only: ``(child mesh, kept face ids, vertex map)``;
    the child's vertex points keep the (compacted) indices of their vertices (``vertex map``, -1 if unused)."""
    from ccproof.mesh import QuadMesh, subdivide

    ids = np.flatnonzero(keep)
    F = np.asarray(mesh.faces)[ids]
    used = np.unique(F)
    vmap = np.full(mesh.n_vertices, -1, dtype=np.int64)
    vmap[used] = np.arange(used.size)
    return subdivide(QuadMesh(np.asarray(mesh.vertices)[used], vmap[F])), ids, vmap


def _cut_out(mesh, vertices, rings, tries=4):
    """:func:`_local_child` of the faces within ``rings`` rings of ``vertices``; where the regions around
    two vertices touch at a single vertex (a non-manifold cut), one ring more (up to ``tries`` times)."""
    from ccproof.errors import MeshError

    for k in range(tries - 1):
        try:
            return _local_child(mesh, _face_rings(mesh, vertices, rings + k))
        except MeshError:
            continue
    return _local_child(mesh, _face_rings(mesh, vertices, rings + tries - 1))


def _ev_levels(mesh, extra):
    """Interior vertices of valence != 4 and their extra levels (``extra``: int, or dict valence -> int)."""
    val = np.asarray(mesh.valence)
    ev = np.flatnonzero((val != 4) & ~np.asarray(mesh.is_boundary_vertex))
    if isinstance(extra, dict):
        s = np.array([int(extra.get(int(val[v]), 0)) for v in ev], dtype=np.int64)
    else:
        s = np.full(ev.size, int(extra), dtype=np.int64)
    if (s < 0).any():
        raise CCProofError(f"extra levels must be >= 0, got {extra!r}")
    return ev, s


def _ev_rings(mesh, ev, s, rings):
    """Per EV its rings at levels 1 .. max(s) (``rings``: int, or dict valence -> list), int (len(ev), max s)."""
    depth = int(s.max(initial=0))
    if not isinstance(rings, dict):
        if int(rings) < 1:
            raise CCProofError(f"rings must be >= 1, got rings={rings!r}")
        return np.full((ev.size, depth), int(rings), dtype=np.int64)
    val = np.asarray(mesh.valence)[ev]
    out = np.ones((ev.size, depth), dtype=np.int64)
    for i, (n, k) in enumerate(zip(val.tolist(), s.tolist())):
        r = list(rings.get(n, ()))[:k]
        if len(r) < k or min(r, default=1) < 1:
            raise CCProofError(f"rings for valence {n}: {k} levels of >= 1 ring needed, got {rings.get(n)!r}")
        out[i, :k] = r
    return out


class HierarchicalSpace:
    """Kraft's hierarchical space of limit functions graded toward the EVs (module docstring).

    Parameters
    ----------
    mesh : QuadMesh
        Level 0 (closed, or open with ``vertices``).
    extra : int or dict
        Levels of local refinement beyond level 0 around every EV, or per valence (``{5: 4, 3: 2}``;
        valences not listed: 0); an int with ``vertices``.
    rings : int or dict
        Face rings around every EV that make up its domain at each level, or per valence the list of them
        for levels 1, 2, ... (:func:`graded_rings`).
    vertices : int array, optional
        Grade toward these vertices (boundary vertices too: a boundary extraordinary vertex) instead of
        the interior vertices of valence != 4.

    Attributes
    ----------
    meshes, surfaces : list
        Per level the (local) mesh and its limit surface.
    kept : list of int arrays
        Per level j the faces of level j subdivided into level j + 1 (child ``4 k + i`` of ``kept[j][k]``).
    omega : list of bool arrays
        Per level its domain (faces of that level).
    active : list of bool arrays
        Per level its active functions (vertices of that level).
    n_dofs : int
    """

    def __init__(self, mesh, extra, rings=5, vertices=None):
        from ccproof.evaluate import natural_limit_surface

        if vertices is None:
            ev, s = _ev_levels(mesh, extra)
        else:
            ev = np.asarray(vertices, dtype=np.int64).reshape(-1)
            s = np.full(ev.size, int(extra), dtype=np.int64)
            if (s < 0).any() or ((ev < 0) | (ev >= mesh.n_vertices)).any():
                raise CCProofError(f"vertices must be vertices of the mesh and extra >= 0, got {vertices!r}, {extra!r}")
        R = _ev_rings(mesh, ev, s, rings)
        self.meshes, self.kept, self.omega = [mesh], [], [np.ones(mesh.n_faces, dtype=bool)]
        for j in range(1, int(s.max(initial=0)) + 1):
            ev, s, R = ev[s >= j], s[s >= j], R[s >= j]
            margin = (int(R[:, j - 1].max()) + 5) // 2  # level-(j-1) rings cut out: 2 margin >= rings + 4
            child, ids, vmap = _cut_out(self.meshes[-1], ev, margin)
            ev = vmap[ev]
            parent = ids[np.arange(child.n_faces) // 4]
            near = np.zeros(child.n_faces, dtype=bool)
            for r in np.unique(R[:, j - 1]):
                near |= _face_rings(child, ev[R[:, j - 1] == r], int(r))
            self.omega.append(near & self.omega[-1][parent])
            self.meshes.append(child)
            self.kept.append(ids)
        self.kept.append(np.zeros(0, dtype=np.int64))
        self.surfaces = [natural_limit_surface(m) for m in self.meshes]
        self.active = [self._active(j) for j in range(len(self.meshes))]
        self.n_dofs = int(sum(a.sum() for a in self.active))

    def _children_in_omega(self, j):
        """Per face of level j, how many of its children lie in ``Omega_(j+1)``."""
        m = self.meshes[j].n_faces
        if j + 1 >= len(self.meshes):
            return np.zeros(m, dtype=np.int64)
        inside = np.flatnonzero(self.omega[j + 1])
        return np.bincount(self.kept[j][inside // 4], minlength=m)

    def _support(self, j):
        """Faces x vertices (CSR bool) of level j: which functions are nonzero on which faces."""
        S = self.surfaces[j]
        m = self.meshes[j].n_faces
        W = S.basis(np.arange(m), np.full(m, 0.5), np.full(m, 0.5))["P"]
        return sp.csr_matrix((np.ones(W.nnz, dtype=bool), W.indices, W.indptr), shape=W.shape)

    def _active(self, j):
        """Level-j functions with support in Omega_j and not in Omega_(j+1) (every child face inside)."""
        sup = self._support(j).T.tocsr()  # vertices x faces
        out_j = (~self.omega[j]).astype(np.int64)
        covered = self._children_in_omega(j) == 4
        inside = (sup @ out_j) == 0
        refined = (sup @ (~covered).astype(np.int64)) == 0
        return inside & ~refined

    def leaves(self):
        """Per level the faces that are leaves of the refinement (they tile the surface)."""
        out = []
        mine = np.ones(self.meshes[0].n_faces, dtype=bool)  # faces of this level present in the refinement
        for j in range(len(self.meshes)):
            split = self._children_in_omega(j) > 0  # a child of this face is refined further
            out.append(mine & ~split)
            if j + 1 < len(self.meshes):
                mine = (mine & split)[self.kept[j][np.arange(self.meshes[j + 1].n_faces) // 4]]
        return out

    def regions(self, region):
        """Per level its faces whose level-0 ancestor is in ``region`` (bool per level-0 face)."""
        out = [np.asarray(region, dtype=bool)]
        for j in range(1, len(self.meshes)):
            out.append(out[-1][self.kept[j - 1][np.arange(self.meshes[j].n_faces) // 4]])
        return out

    def quadrature(self, order=4, depth=12, region=None):
        """Per level the adaptive rule restricted to its leaves (and to ``region``, bool per level-0 face):
        list of QuadratureRule (level j's faces)."""
        rules = []
        inside = self.regions(np.ones(self.meshes[0].n_faces, dtype=bool) if region is None else region)
        for j, leaf in enumerate(self.leaves()):
            cells = quadrature_cells(self.surfaces[j], "adaptive", depth)
            keep = (leaf & inside[j])[cells[0]]
            rules.append(cells_rule(tuple(a[keep] for a in cells), order))
        return rules

    def rows(self, j, rule):
        """Basis rows (dict ``P``, ``Du``, ``Dv`` of CSR, points x n_dofs) of the hierarchical space at a
        rule of level j, derivatives with respect to level j's face parameter (chain rule through the
        parents: ``d(u_k, v_k) / d(s_j, t_j)``, a product of ``[d1 d2] / 2`` per level)."""
        f, u, v = rule.face, rule.u, rule.v
        n = f.size
        J = np.zeros((n, 2, 2))
        J[:, 0, 0] = J[:, 1, 1] = 1.0
        blocks = {"P": [], "Du": [], "Dv": []}
        for k in range(j, -1, -1):  # level k's functions at the points written on level k's faces
            cols = np.flatnonzero(self.active[k])
            W = {key: M[:, cols] for key, M in self.surfaces[k].basis(f, u, v, 1).items()}
            blocks["P"].append(W["P"])
            for b, key in ((0, "Du"), (1, "Dv")):
                blocks[key].append((sp.diags(J[:, 0, b]) @ W["Du"] + sp.diags(J[:, 1, b]) @ W["Dv"]).tocsr())
            if k:
                i = f % 4
                M = 0.5 * np.stack([_D1[i], _D2[i]], axis=-1)  # d(u, v)/d(s, t) of the child step
                J = M @ J
                f, u, v = parent_points(f, u, v)
                f = self.kept[k - 1][f]
        out = {}
        for key, parts in blocks.items():
            parts = parts[::-1] + [sp.csr_matrix((n, int(self.active[k].sum())))
                                   for k in range(j + 1, len(self.meshes))]
            out[key] = sp.hstack(parts, format="csr")
        return out

    def fields(self, order=4, depth=12, curvature=True, region=None):
        """Per level: SurfaceFields at the leaves' adaptive rule (in ``region``), the hierarchical rows as ``W``."""
        from ccproof.apps.iga.assembly import SurfaceFields

        out = []
        for j, rule in enumerate(self.quadrature(order, depth, region)):
            if rule.face.size == 0:
                continue
            F = SurfaceFields(self.surfaces[j], rule, curvature=curvature)
            F.W = self.rows(j, rule)
            out.append(F)
        return out


def solve_graded(mesh, extra, exact, rings=5, vertices=None, region=None):
    """Galerkin solution of ``-Laplace_Gamma u + u = f`` in the graded space: dict ``L2``, ``H1``, ``dofs``
    and ``leaves`` (per level the L2 and H1 errors on its leaves; ``extra``, ``rings`` and ``vertices`` as
    in :class:`HierarchicalSpace`).

    On an open mesh (``region``: the faces solved on, bool per level-0 face; every function nonzero there
    is a dof) the boundary condition is the natural one, ``grad u . m = g`` on the region's boundary, and
    its load ``int f phi + int_boundary g phi`` is taken in the form Green's identity gives it for the
    manufactured u, ``int (u phi + grad u . grad phi)`` (no boundary rule on the leaves needed): the
    solution is the H1 projection of u, as the Neumann problem's Galerkin solution is."""
    from ccproof.apps.iga.assembly import solve_spd

    H = HierarchicalSpace(mesh, extra, rings, vertices)
    Fs = H.fields(region=region)
    A = sum(F.stiffness() + F.mass() for F in Fs).tocsr()
    b = sum(F.load(exact.screened_poisson_rhs(F)) if region is None else _h1_load(F, exact) for F in Fs)
    c = np.zeros(A.shape[0])
    free = np.flatnonzero(A.diagonal() > 0)
    c[free] = solve_spd(A[free][:, free].tocsr(), b[free])
    leaves = [tuple(float(e) for e in F.errors(c, exact))
              for F in H.fields(order=6, depth=14, curvature=False, region=region)]
    e2, h2 = (np.asarray(leaves) ** 2).sum(axis=0)
    return {"L2": float(np.sqrt(e2)), "H1": float(np.sqrt(h2)), "dofs": int(free.size), "leaves": leaves}


def _h1_load(F, exact):
    """``int (u phi_i + grad u . grad_Gamma phi_i)`` at the rule of the SurfaceFields F."""
    g = exact.gradient(F.P)
    pu, pv = np.einsum("ij,ij->i", F.Pu, g), np.einsum("ij,ij->i", F.Pv, g)
    G = F.Ginv
    return (F.W["P"].T @ (F.dA * exact.value(F.P)) + F.W["Du"].T @ (F.dA * (G[:, 0, 0] * pu + G[:, 0, 1] * pv))
            + F.W["Dv"].T @ (F.dA * (G[:, 1, 0] * pu + G[:, 1, 1] * pv)))
