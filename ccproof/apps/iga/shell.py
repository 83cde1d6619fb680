"""A linear Kirchhoff-Love thin shell on Catmull-Clark limit surfaces (membrane and bending).

The reference surface is the limit surface ``X = W_P X_c`` of a control mesh and the displacement field is
in the same space, ``u = sum_i phi_i c_i`` with a vector ``c_i`` per control vertex (isoparametric:
Cirak, Ortiz, Schroeder 2000; the a_ab / b_ab formulation of Kiendl, Bletzinger, Linhard, Wuechner 2009).
With the covariant base vectors ``a_a = X_,a``, the metric ``a_ab = a_a . a_b``, the unit normal ``a_3`` and
the curvature ``b_ab = a_a,b . a_3``, the linearized strains of a displacement u are

* membrane: ``eps_ab = (a_a . u_,b + a_b . u_,a) / 2`` (the change of ``a_ab / 2``);
* bending: ``kappa_ab = a_3 . (u_,ab - Gamma^c_ab u_,c)``, ``Gamma^c_ab = a^c . a_a,b`` (the change of
  ``b_ab``: ``delta a_3 = -(a_3 . u_,c) a^c``, so ``delta b_ab = u_,ab . a_3 - (a_3 . u_,c)(a^c . a_a,b)``),

the normal component of the covariant Hessian of u, whose rows are those of
:func:`ccproof.apps.iga.plate.hessian_rows` times the normal. Both are written in the orthonormal tangent
frame ``e_p = L_ap a_a`` (``a^-1 = L L^T``), where for a displacement ``e_k phi_i`` (component k of vertex i)
``E_pq = (e_p^k d_q phi_i + e_q^k d_p phi_i) / 2`` and ``K_pq = n^k (L^T H L)_pq``. The energy of an
isotropic material (Young's modulus E, Poisson's ratio nu, thickness t) is

``U = 1/2 int (E t / (1 - nu^2)) eps : H : eps + (E t^3 / (12 (1 - nu^2))) kappa : H : kappa dA``

with ``e : H : e = nu tr(e)^2 + (1 - nu) |e|^2`` in that frame, i.e. the plane-stress matrix
``[[1, nu, 0], [nu, 1, 0], [0, 0, (1 - nu) / 2]]`` on ``(E_11, E_22, 2 E_12)``. A rigid motion
``u = w + omega x X`` has zero strains at every point (``K @ rigid = 0``, tested).

The stiffness is assembled sparse on a quadrature rule (:mod:`ccproof.apps.iga.quadrature`) with dofs
ordered component-major (dof ``k n + i``, n the number of control vertices); loads per area or at points.
Displacement conditions are a sparse map ``c = T c_free`` of the free coefficients (:func:`solve_shell`).
The benchmarks (:mod:`ccproof.apps.iga.shell_benchmarks`) use the ghost-ring space of
:func:`ccproof.apps.iga.plate.plate_square`'s kind, where a condition ``u_k = 0`` on a knot line is the exact
linear condition ``c_-1 + 4 c_0 + c_1 = 0`` on the three rows of coefficients across it.

>>> import numpy as np
>>> from ccproof.mesh.examples import cube
>>> from ccproof.evaluate import natural_limit_surface
>>> from ccproof.apps.iga.quadrature import surface_quadrature
>>> S = natural_limit_surface(cube())
>>> F = ShellFields(S, surface_quadrature(S, 3, "adaptive", 6))
>>> K = F.stiffness(ShellMaterial(1.0, 0.3, 0.1))
>>> R = rigid_motions(np.asarray(S.mesh.vertices))
>>> K.shape, bool(abs(K @ R).max() < 1e-12 * abs(K).max() * abs(R).max())
((24, 24), True)
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import scipy.sparse as sp

from ccproof.errors import CCProofError

__all__ = ["ShellMaterial", "ShellFields", "rigid_motions", "point_load", "solve_shell", "restrict_rule"]


class ShellMaterial(NamedTuple):
    """Isotropic linear elastic shell: Young's modulus ``E``, Poisson's ratio ``nu``, thickness ``t``."""

    E: float
    nu: float
    t: float

    @property
    def membrane(self):
        """Membrane stiffness ``E t / (1 - nu^2)``."""
        return self.E * self.t / (1.0 - self.nu**2)

    @property
    def bending(self):
        """Bending stiffness ``E t^3 / (12 (1 - nu^2))``."""
        return self.E * self.t**3 / (12.0 * (1.0 - self.nu**2))

    def plane_stress(self):
        """The 3 x 3 matrix on ``(E_11, E_22, 2 E_12)`` in an orthonormal frame (without the stiffness)."""
        nu = self.nu
        return np.array([[1.0, nu, 0.0], [nu, 1.0, 0.0], [0.0, 0.0, 0.5 * (1.0 - nu)]])


def restrict_rule(rule, region):
    """The points of ``rule`` on the faces ``region`` (bool per face; None: all)."""
    if region is None:
        return rule
    keep = np.asarray(region)[rule.face]
    return type(rule)(*(a[keep] for a in rule))


class ShellFields:
    """Strain rows of the displacement space at the points of a quadrature rule (natural parameterization).

    Attributes
    ----------
    fields : SurfaceFields
        The surface at the points (``P``, ``dA``, ``normal``, rows ``W``).
    membrane, bending : tuple of three CSR (n_points, 3 n_vertices)
        Rows of ``(E_11, E_22, 2 E_12)`` and ``(K_11, K_22, 2 K_12)`` in the orthonormal frame (module
        docstring), dof ``k n + i``.
    n_vertices : int
    """

    def __init__(self, surface, rule):
        from ccproof.apps.iga.assembly import SurfaceFields
        from ccproof.apps.iga.plate import hessian_rows

        F = SurfaceFields(surface, rule, curvature=True)
        self.fields = F
        self.n_vertices = F.W["P"].shape[1]
        L = np.linalg.cholesky(F.Ginv)  # a^-1 = L L^T, the frame hessian_rows uses
        e = [L[:, 0, p, None] * F.Pu + L[:, 1, p, None] * F.Pv for p in (0, 1)]  # orthonormal tangent frame
        d = [F.combine([(L[:, 0, p], F.W["Du"]), (L[:, 1, p], F.W["Dv"])]) for p in (0, 1)]

        def vector(terms):  # rows of sum_j diag(a_j^k) B_j for the three components k, side by side
            return sp.hstack([F.combine([(a[:, k], B) for a, B in terms]) for k in range(3)], format="csr")

        self.membrane = (vector([(e[0], d[0])]), vector([(e[1], d[1])]), vector([(e[0], d[1]), (e[1], d[0])]))
        R11, R12, R22 = hessian_rows(surface, F, rule)
        n = F.normal
        self.bending = (vector([(n, R11)]), vector([(n, R22)]), vector([(2.0 * n, R12)]))

    def _energy_matrix(self, rows, factor, material):
        D = material.plane_stress()
        w = self.fields.dA * factor
        K = None
        for s in range(3):
            Ts = sum(D[s, t] * rows[t] for t in range(3) if D[s, t] != 0.0)
            Ks = rows[s].T @ sp.diags(w) @ Ts
            K = Ks if K is None else K + Ks
        return K.tocsr()

    def membrane_stiffness(self, material):
        """``int (E t / (1 - nu^2)) eps(u) : H : eps(v) dA`` as a sparse (3 n, 3 n) matrix."""
        return self._energy_matrix(self.membrane, material.membrane, material)

    def bending_stiffness(self, material):
        """``int (E t^3 / (12 (1 - nu^2))) kappa(u) : H : kappa(v) dA`` as a sparse (3 n, 3 n) matrix."""
        return self._energy_matrix(self.bending, material.bending, material)

    def stiffness(self, material):
        """Membrane plus bending stiffness (sparse, symmetric positive semidefinite)."""
        return (self.membrane_stiffness(material) + self.bending_stiffness(material)).tocsr()

    def load(self, force):
        """``int f . phi_i e_k dA`` for a force per area ``force`` (3,) or (n_points, 3), dof ``k n + i``."""
        f = np.broadcast_to(np.asarray(force, dtype=np.float64), self.fields.P.shape)
        P, dA = self.fields.W["P"], self.fields.dA
        return np.concatenate([P.T @ (dA * f[:, k]) for k in range(3)])


def rigid_motions(X):
    """The six rigid motions of control points X (n, 3) as columns (3 n, 6), dof ``k n + i``: translations
    along x, y, z and the infinitesimal rotations ``e_j x X``. The limit surface is isoparametric, so
    these coefficients give the rigid motions of the limit surface itself."""
    X = np.asarray(X, dtype=np.float64)
    n = X.shape[0]
    out = np.zeros((3 * n, 6))
    for k in range(3):
        out[k * n:(k + 1) * n, k] = 1.0
    for j in range(3):
        r = np.cross(np.eye(3)[j], X)
        for k in range(3):
            out[k * n:(k + 1) * n, 3 + j] = r[:, k]
    return out


def point_load(surface, face, u, v, force):
    """The load vector (3 n,) of point forces ``force`` (m, 3) at the points ``(face, u, v)`` (m each) of the
    limit surface: ``force . phi_i(point) e_k``."""
    P = surface.basis(np.atleast_1d(face), np.atleast_1d(u), np.atleast_1d(v), 0)["P"]
    f = np.atleast_2d(np.asarray(force, dtype=np.float64))
    return np.concatenate([P.T @ f[:, k] for k in range(3)])


def solve_shell(K, b, T):
    """``c = T (T^T K T)^-1 T^T b``: the displacement coefficients (3 n,) on the constrained space of the
    columns of T (sparse (3 n, m)); a sparse LU factorization (the shell's stiffness is too ill-conditioned
    for unpreconditioned iterations at small thickness).

    Raises
    ------
    CCProofError
        If the constrained stiffness is singular (a rigid motion left free): the factorization fails or
        its solution leaves a relative residual above 1e-8.
    """
    from scipy.sparse.linalg import splu

    A = (T.T @ K @ T).tocsc()
    try:
        lu = splu(A)
    except RuntimeError as exc:
        raise CCProofError(f"the constrained shell stiffness is singular ({exc}): fix the rigid motions") from exc
    rhs = T.T @ b
    y = lu.solve(rhs)
    scale = np.linalg.norm(rhs)
    res = np.linalg.norm(A @ y - rhs) / scale if np.isfinite(y).all() else np.inf
    if not res <= 1e-8:
        raise CCProofError(f"the constrained shell stiffness is singular (relative residual {res:.3g}): "
                           "fix the rigid motions")
    return T @ y
