"""Open surfaces: the boundary curve, its quadrature, Dirichlet (strong or Nitsche) and Neumann (natural) data.

Under OpenSubdiv's ``VTX_BOUNDARY_EDGE_ONLY`` rules (the rules of :class:`~ccproof.mesh.QuadMesh`), a boundary
vertex and a boundary edge point depend on boundary vertices only (crease rule ``(3/4) V + (1/8)(e0 + e1)``
and edge midpoints), also at a corner with one face. So the limit boundary is the uniform cubic B-spline
curve of every boundary loop of control vertices, and the *trace space* of the discrete space on the
boundary is spanned exactly by the boundary vertices' limit functions: the periodic cubic B-splines of the
loop, in the face parameter of the boundary edges (one knot span per boundary edge). The interior vertices'
functions vanish on the boundary.

Dirichlet data ``u = g`` are therefore imposed **strongly** on this space: the boundary coefficients are the
L2 projection of g onto the trace space (:func:`dirichlet_lift`, a banded system on the loop), and the
interior coefficients solve the Galerkin system with those fixed. No penalty parameter is needed and the
discrete problem stays symmetric positive definite. Neumann data ``grad u . m = g`` (m the outward conormal)
are natural: the load gets ``int_boundary g phi_i ds``.

Every function of this space has a zero second derivative across a regular boundary (the net's ghost row
``2 B - I``), which limits the rates to h^2.5 (L2) and h^1.5 (H1) for a solution with ``u_nn != 0`` there.
Solving on a *region* of a larger mesh (one ring of ghost faces outside,
:func:`ccproof.apps.iga.convergence.open_study_mesh`) frees that derivative; the trace is then no longer
spanned by a subset of the vertices, and Dirichlet data are imposed by **Nitsche's** method
(:meth:`BoundaryFields.nitsche`).

Faces and their boundary sides: side i of a face runs from its corner i to corner i + 1 (corners at
(0,0), (1,0), (1,1), (0,1)), counter-clockwise around the face seen from its normal ``P_u x P_v``, so the
outward conormal is ``m = t x n`` (t the unit tangent along the side, n the unit normal).

>>> import numpy as np
>>> from ccproof.mesh.examples import grid
>>> from ccproof.evaluate import natural_limit_surface
>>> S = natural_limit_surface(grid(2, 2))
>>> from ccproof.apps.iga.assembly import SurfaceFields
>>> from ccproof.apps.iga.quadrature import surface_quadrature
>>> B = BoundaryFields(S, boundary_quadrature(S, order=4))
>>> A = SurfaceFields(S, surface_quadrature(S, order=4, kind="adaptive")).area    # rounded corners: 11/3
>>> round(float(B.ds @ np.einsum("ij,ij->i", B.P, B.conormal)) / 2, 12), round(A, 12)   # divergence theorem
(3.666666666667, 3.666666666667)
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import scipy.sparse as sp

from ccproof.errors import CCProofError

__all__ = ["BoundaryRule", "boundary_sides", "boundary_vertices", "boundary_quadrature", "BoundaryFields",
           "dirichlet_lift", "solve_open_screened_poisson", "BOUNDARY_CONDITIONS"]

BOUNDARY_CONDITIONS = ("dirichlet", "neumann")

#: start corner and direction (du, dv) of side i of a face
_START = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
_DIR = np.roll(_START, -1, axis=0) - _START


class BoundaryRule(NamedTuple):
    """Points ``(face, u, v)`` on boundary sides, parameter weights ``weight`` (sum: the number of sides)
    and the side's parameter direction ``(du, dv)`` (all shape (n,))."""

    face: np.ndarray
    u: np.ndarray
    v: np.ndarray
    weight: np.ndarray
    du: np.ndarray
    dv: np.ndarray


def boundary_sides(mesh, region=None):
    """The boundary sides ``(faces, sides)`` of a QuadMesh, or of the faces ``region`` (bool (m,)) of it:
    side i of face f joins its corners i, i + 1 and belongs to no other face (of the region).

    >>> import numpy as np
    >>> from ccproof.mesh.examples import grid
    >>> f, s = boundary_sides(grid(2, 1))
    >>> list(zip(f.tolist(), s.tolist()))
    [(0, 0), (0, 2), (0, 3), (1, 0), (1, 1), (1, 2)]
    >>> f, s = boundary_sides(grid(3, 3), region=np.arange(9) == 4)    # the middle face alone
    >>> f.tolist(), s.tolist()
    ([4, 4, 4, 4], [0, 1, 2, 3])
    """
    F = np.asarray(mesh.faces)
    faces = np.arange(F.shape[0]) if region is None else np.flatnonzero(region)
    F = F[faces]
    a, b = F.reshape(-1), np.roll(F, -1, axis=1).reshape(-1)
    key = np.minimum(a, b).astype(np.int64) * (int(F.max(initial=0)) + 1) + np.maximum(a, b)
    _, inv, cnt = np.unique(key, return_inverse=True, return_counts=True)
    h = np.flatnonzero(cnt[inv] == 1)
    return faces[h // 4], h % 4


def boundary_vertices(mesh):
    """Indices of the boundary vertices (those whose limit functions span the trace space)."""
    return np.flatnonzero(np.asarray(mesh.is_boundary_vertex))


def boundary_quadrature(surface, order=4, region=None):
    """``order``-point Gauss-Legendre rule on every boundary side of ``surface`` (a QuadMesh surface), or
    of its faces ``region`` (:func:`boundary_sides`).

    The trace of the surface and of every basis function on a side is one cubic polynomial in the side's
    parameter (a span of the boundary loop's uniform cubic B-spline), so ``order >= 4`` integrates
    products of two traces exactly against a polynomial line element's square; the line element
    ``|P_t|`` itself is a square root (not polynomial) away from straight sides.

    Raises
    ------
    CCProofError
        A closed surface (no boundary side), an order below 1.
    """
    if int(order) < 1:
        raise CCProofError(f"order must be >= 1, got {order!r}")
    f, s = boundary_sides(surface.mesh, region)
    if f.size == 0:
        raise CCProofError("the surface is closed: it has no boundary side")
    x, w = np.polynomial.legendre.leggauss(int(order))
    x, w = 0.5 * (x + 1.0), 0.5 * w
    uv = _START[s][:, None, :] + x[None, :, None] * _DIR[s][:, None, :]
    d = np.repeat(_DIR[s], x.size, axis=0)
    return BoundaryRule(np.repeat(f, x.size), uv[..., 0].ravel(), uv[..., 1].ravel(), np.tile(w, f.size),
                        d[:, 0], d[:, 1])


class BoundaryFields:
    """The surface and the basis rows at the points of a :class:`BoundaryRule`.

    Attributes
    ----------
    W : dict of CSR (n_points, n_vertices)
        ``"P"``, ``"Du"``, ``"Dv"``.
    P : ndarray (n_points, 3)
    tangent : ndarray (n_points, 3)
        ``P_t = du P_u + dv P_v`` along the side (the boundary loop's direction).
    ds : ndarray (n_points,)
        ``w |P_t|``: the points' length weights.
    normal, conormal : ndarray (n_points, 3)
        Unit normal ``P_u x P_v / |.|`` and outward unit conormal ``t x n``.
    length : float
    """

    def __init__(self, surface, rule):
        f, u, v, w, du, dv = rule
        self.W = surface.basis(f, u, v, 1)
        r = surface.evaluate(f, u, v, 1)
        self.P = r["P"]
        self.tangent = du[:, None] * r["Pu"] + dv[:, None] * r["Pv"]
        speed = np.linalg.norm(self.tangent, axis=1)
        n = np.cross(r["Pu"], r["Pv"])
        nn = np.linalg.norm(n, axis=1)
        bad = np.flatnonzero(~((speed > 0) & (nn > 0)))
        if bad.size:
            i = int(bad[0])
            raise CCProofError(f"boundary point {i} (face {int(f[i])}, u = {float(u[i])!r}, v = {float(v[i])!r}): "
                               "degenerate tangent or normal")
        self.ds = w * speed
        self.speed = speed
        self.normal = n / nn[:, None]
        self.conormal = np.cross(self.tangent / speed[:, None], self.normal)
        self.length = float(self.ds.sum())
        g = np.einsum("nai,nbi->nab", np.stack([r["Pu"], r["Pv"]], 1), np.stack([r["Pu"], r["Pv"]], 1))
        # the conormal derivative of phi: grad_Gamma phi . m = (Du phi, Dv phi) g^-1 (P_u . m, P_v . m)
        pm = np.stack([np.einsum("ij,ij->i", r["Pu"], self.conormal), np.einsum("ij,ij->i", r["Pv"], self.conormal)], 1)
        self._dm = np.linalg.solve(g, pm[..., None])[..., 0]

    def conormal_rows(self):
        """CSR rows (n_points, n_vertices) of ``grad_Gamma phi_i . m`` at the points."""
        a, b = self._dm[:, 0], self._dm[:, 1]
        return (sp.diags(a) @ self.W["Du"] + sp.diags(b) @ self.W["Dv"]).tocsr()

    def nitsche(self, values, penalty=40.0):
        """Nitsche's terms for ``u = g`` (``values`` at the points): the symmetric matrix
        ``-int (d_m u v + u d_m v) + int (penalty / h) u v`` and its load ``-int g d_m v + int (penalty / h) g v``,
        h the side's length scale ``|P_t|`` at the point (the side is the parameter interval [0, 1])."""
        P, D = self.W["P"], self.conormal_rows()
        ds, pen = sp.diags(self.ds), sp.diags(self.ds * penalty / self.speed)
        N = -(P.T @ ds @ D) - (D.T @ ds @ P) + P.T @ pen @ P
        g = np.asarray(values, dtype=np.float64)
        return N.tocsr(), -(D.T @ (self.ds * g)) + P.T @ (self.ds * penalty / self.speed * g)

    def mass(self):
        """``W_P^T diag(ds) W_P``: the boundary mass matrix (sparse, symmetric; nonzero on the boundary
        vertices only)."""
        P = self.W["P"]
        return (P.T @ sp.diags(self.ds) @ P).tocsr()

    def load(self, values):
        """``W_P^T (ds values)``: ``int_boundary g phi_i ds`` for the values (n_points,) of g."""
        return self.W["P"].T @ (self.ds * np.asarray(values, dtype=np.float64))


def dirichlet_lift(fields, values, vertices):
    """Boundary coefficients: the L2 projection of the data g (``values`` at the rule's points) onto the
    trace space spanned by ``vertices``' functions, as a full coefficient vector (zero elsewhere).

    Raises
    ------
    CCProofError
        If a basis function outside ``vertices`` is nonzero on the boundary (not a trace space basis).
    """
    P = fields.W["P"]
    inside = np.setdiff1d(np.arange(P.shape[1]), vertices)
    leak = abs(P[:, inside]).max() if inside.size else 0.0
    if leak > 1e-12:
        raise CCProofError(f"an interior vertex's function is {leak:.3g} on the boundary: the boundary "
                           "vertices do not span the trace space")
    from ccproof.apps.iga.assembly import solve_spd

    Mb = fields.mass()[vertices][:, vertices]
    c = np.zeros(P.shape[1])
    c[vertices] = solve_spd(Mb.tocsr(), fields.load(values)[vertices])
    return c


def solve_open_screened_poisson(surface, rule, exact, bc="dirichlet", boundary_order=6, error_rule=None,
                                region=None, penalty=40.0):
    """Galerkin solution of ``-Laplace_Gamma u + u = f`` on an open surface with the data of ``exact``.

    Parameters
    ----------
    surface : LimitSurface
        On a QuadMesh with a boundary (natural parameterization).
    rule : QuadratureRule
        For the matrices and the load (its points outside ``region`` are left out).
    exact : AmbientFunction
        The manufactured solution: f from it, and g = u (``"dirichlet"``) or ``g = grad u . m``
        (``"neumann"``, m the outward conormal) on the boundary.
    bc : {"dirichlet", "neumann"}
    boundary_order : int
        Gauss points per boundary side.
    error_rule : QuadratureRule, optional
        For the errors (default: ``rule``; restricted to ``region`` too).
    region : bool array (n_faces,), optional
        Solve on these faces only, with every limit function nonzero there
        (:func:`ccproof.apps.iga.convergence.open_study_mesh`: a ring of ghost vertices outside the region
        frees the normal second derivative at its boundary).
        Dirichlet data are then imposed by Nitsche's method (the trace is no longer spanned by a subset
        of the vertices); without a region, strongly (:func:`dirichlet_lift`).
    penalty : float
        Nitsche's penalty (times 1/h).

    Returns
    -------
    dict
        ``c`` (n_vertices,), ``L2``, ``H1`` (seminorm) errors, ``dofs`` (free coefficients).
    """
    from ccproof.apps.iga.assembly import SurfaceFields, solve_spd

    if bc not in BOUNDARY_CONDITIONS:
        raise CCProofError(f"unknown boundary condition {bc!r}; use one of {', '.join(BOUNDARY_CONDITIONS)}")
    rule, error_rule = (_restrict(r, region) for r in (rule, rule if error_rule is None else error_rule))
    F = SurfaceFields(surface, rule, curvature=True)
    B = BoundaryFields(surface, boundary_quadrature(surface, boundary_order, region))
    A = (F.stiffness() + F.mass()).tocsr()
    b = F.load(exact.screened_poisson_rhs(F))
    active = np.flatnonzero(F.W["P"].getnnz(axis=0) > 0)
    fixed = np.zeros(0, dtype=np.int64)
    c = np.zeros(A.shape[0])
    if bc == "neumann":
        b = b + B.load(np.einsum("ij,ij->i", exact.gradient(B.P), B.conormal))
    elif region is not None:
        N, bn = B.nitsche(exact.value(B.P), penalty)
        A, b = (A + N).tocsr(), b + bn
    else:
        fixed = boundary_vertices(surface.mesh)
        c = dirichlet_lift(B, exact.value(B.P), fixed)
    free = np.setdiff1d(active, fixed)
    r = b - A @ c
    c[free] = solve_spd(A[free][:, free].tocsr(), r[free])
    E = SurfaceFields(surface, error_rule)
    L2, H1 = E.errors(c, exact)
    return {"c": c, "L2": L2, "H1": H1, "dofs": int(free.size)}


def _restrict(rule, region):
    if region is None:
        return rule
    keep = np.asarray(region)[rule.face]
    return type(rule)(*(a[keep] for a in rule))
