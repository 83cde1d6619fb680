"""A hierarchical space graded toward the extraordinary vertices (local refinement of the subdivision space).

Levels ``j = 0 .. extra`` are the mesh subdivided ``j`` more times (QuadMesh child ``4 f + i`` covers
the quarter of face f at corner i, :mod:`ccproof.mesh.subdivision`). The domain ``Omega_j`` of level j is
the set of its faces within ``rings`` face rings of an extraordinary vertex (nested: children of
``Omega_(j-1)``; ``Omega_0`` every face), so that it shrinks by half per level toward every EV. The space
is Kraft's hierarchical basis: the level-j limit functions whose support lies in ``Omega_j`` but not in
``Omega_(j+1)``. Every function is an exact limit function of its level's control vertex (rows of
:meth:`LimitSurface.basis <ccproof.evaluate.surface.LimitSurface.basis>` of that level's surface, the same
geometric surface at every level), and the quadrature uses the leaves of the refinement (the faces of the
finest level present at each place), with the adaptive rule of :mod:`ccproof.apps.iga.quadrature`.

The surface (geometry) is the limit of the level-0 mesh at every level: the level-j control points are
the level-0 ones subdivided, so the coordinates are in every level's span.

>>> from ccproof.mesh.examples import cube
>>> H = HierarchicalSpace(cube(), extra=1, rings=1)
>>> H.n_dofs, [int(a.sum()) for a in H.active]          # 8 coarse functions replaced near the 8 EVs
(26, [0, 26])
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ccproof.apps.iga.quadrature import cells_rule, extraordinary_corners, quadrature_cells
from ccproof.errors import CCProofError

__all__ = ["HierarchicalSpace", "parent_points", "solve_graded"]

#: corner c_i of a face, and the directions of a child's s and t axes (toward corners i+1 and i-1)
_C = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
_D1 = np.roll(_C, -1, axis=0) - _C
_D2 = np.roll(_C, 1, axis=0) - _C


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


def _face_rings(mesh, rings):
    """Faces within ``rings`` face rings (through shared vertices) of an extraordinary vertex, bool (m,)."""
    F = np.asarray(mesh.faces)
    ev = extraordinary_corners(mesh)
    near_v = np.zeros(mesh.n_vertices, dtype=bool)
    near_v[F[ev]] = True
    near_f = np.zeros(F.shape[0], dtype=bool)
    for _ in range(rings):
        near_f = near_v[F].any(axis=1)
        near_v[F[near_f]] = True
    return near_f


class HierarchicalSpace:
    """Kraft's hierarchical space of limit functions graded toward the EVs (module docstring).

    Parameters
    ----------
    mesh : QuadMesh
        Level 0 (closed).
    extra : int
        Levels of local refinement beyond level 0.
    rings : int
        Face rings around every EV refined at each level.

    Attributes
    ----------
    meshes, surfaces : list
        Per level the subdivided mesh and its limit surface.
    omega : list of bool arrays
        Per level its domain (faces of that level).
    active : list of bool arrays
        Per level its active functions (vertices of that level).
    n_dofs : int
    """

    def __init__(self, mesh, extra, rings=2):
        from ccproof.evaluate import natural_limit_surface
        from ccproof.mesh import subdivide

        if extra < 0 or rings < 1:
            raise CCProofError(f"extra must be >= 0 and rings >= 1, got extra={extra!r}, rings={rings!r}")
        self.meshes = [mesh]
        for _ in range(extra):
            self.meshes.append(subdivide(self.meshes[-1]))
        self.surfaces = [natural_limit_surface(m) for m in self.meshes]
        self.omega = [np.ones(mesh.n_faces, dtype=bool)]
        for m in self.meshes[1:]:
            self.omega.append(_face_rings(m, rings) & np.repeat(self.omega[-1], 4))
        self.omega.append(np.zeros(4 * self.meshes[-1].n_faces, dtype=bool))
        self.active = [self._active(j) for j in range(len(self.meshes))]
        self.n_dofs = int(sum(a.sum() for a in self.active))

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
        covered = self.omega[j + 1].reshape(-1, 4).all(axis=1)
        inside = (sup @ out_j) == 0
        refined = (sup @ (~covered).astype(np.int64)) == 0
        return inside & ~refined

    def leaves(self):
        """Per level the faces that are leaves of the refinement (they tile the surface)."""
        out = []
        mine = np.ones(self.meshes[0].n_faces, dtype=bool)  # faces of this level present in the refinement
        for j in range(len(self.meshes)):
            split = self.omega[j + 1].reshape(-1, 4).any(axis=1)  # a child of this face is refined further
            out.append(mine & ~split)
            mine = np.repeat(mine & split, 4)
        return out

    def quadrature(self, order=4, depth=12):
        """Per level the adaptive rule restricted to its leaves: list of QuadratureRule (level j's faces)."""
        rules = []
        for j, leaf in enumerate(self.leaves()):
            cells = quadrature_cells(self.surfaces[j], "adaptive", depth)
            keep = leaf[cells[0]]
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
        out = {}
        for key, parts in blocks.items():
            parts = parts[::-1] + [sp.csr_matrix((n, int(self.active[k].sum())))
                                   for k in range(j + 1, len(self.meshes))]
            out[key] = sp.hstack(parts, format="csr")
        return out

    def fields(self, order=4, depth=12, curvature=True):
        """Per level: SurfaceFields at the leaves' adaptive rule, with the hierarchical rows as ``W``."""
        from ccproof.apps.iga.assembly import SurfaceFields

        out = []
        for j, rule in enumerate(self.quadrature(order, depth)):
            if rule.face.size == 0:
                continue
            F = SurfaceFields(self.surfaces[j], rule, curvature=curvature)
            F.W = self.rows(j, rule)
            out.append(F)
        return out


def solve_graded(mesh, extra, exact, rings=2):
    """Galerkin solution of ``-Laplace_Gamma u + u = f`` in the graded space: dict ``L2``, ``H1``, ``dofs``."""
    from ccproof.apps.iga.assembly import solve_spd

    H = HierarchicalSpace(mesh, extra, rings)
    Fs = H.fields()
    A = sum(F.stiffness() + F.mass() for F in Fs)
    b = sum(F.load(exact.screened_poisson_rhs(F)) for F in Fs)
    c = solve_spd(A, b)
    e2 = h2 = 0.0
    for F in H.fields(order=6, depth=14, curvature=False):
        l2, h1 = F.errors(c, exact)
        e2, h2 = e2 + l2 * l2, h2 + h1 * h1
    return {"L2": float(np.sqrt(e2)), "H1": float(np.sqrt(h2)), "dofs": H.n_dofs}
