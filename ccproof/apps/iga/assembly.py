"""Mass, stiffness (Laplace-Beltrami) and load of scalar problems on closed limit surfaces, with the metric.

The discrete space is spanned by the limit functions of the control vertices: ``u_h = sum_i c_i phi_i``
with ``phi_i`` the limit surface of the indicator vector of vertex i, i.e. ``u_h(face, u, v) = W["P"] c`` for
the basis rows W of :meth:`ccproof.evaluate.surface.LimitSurface.basis` (the surface itself is
``W["P"] X``: isoparametric). On a quadrature rule (:mod:`ccproof.apps.iga.quadrature`) with parameter
weights ``w_q``, area element ``J_q = |P_u x P_v|`` and inverse metric ``G_q = g^-1`` (``g_ab = P_a . P_b``):

* mass ``M = W_P^T diag(w J) W_P``;
* stiffness ``K = sum_ab W_a^T diag(w J G^ab) W_b`` (a, b in u, v): ``c^T K c = int |grad_Gamma u_h|^2``;
* load ``b = W_P^T (w J f(P))``.

The problem ``-Laplace_Gamma u + u = f`` on a closed surface is ``(K + M) c = b``.

>>> from ccproof.mesh.examples import torus
>>> from ccproof.evaluate import natural_limit_surface
>>> from ccproof.apps.iga.quadrature import surface_quadrature
>>> S = natural_limit_surface(torus())
>>> F = SurfaceFields(S, surface_quadrature(S, order=4, kind="plain"))
>>> M, K = F.mass(), F.stiffness()
>>> M.shape, round(float(M.sum()) / F.area, 12), round(float(abs(K.sum(axis=1)).max()), 12)  # 1^T M 1 = area
((48, 48), 1.0, 0.0)
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ccproof.errors import CCProofError

__all__ = ["SurfaceFields", "AmbientFunction", "solve_screened_poisson", "solve_spd"]


class SurfaceFields:
    """The surface and the basis rows at the points of a quadrature rule (one parameterization).

    Parameters
    ----------
    surface : LimitSurface
    rule : QuadratureRule
    parameterization : str or parameterization value
        Passed to ``basis`` and ``evaluate`` (``"natural"``, or ``"characteristic"`` on a surface of
        :func:`ccproof.limit_surface`).
    curvature : bool
        Also the normal and the mean curvature ``kappa = div_Gamma n`` at the points (second derivatives).

    Attributes
    ----------
    W : dict of CSR (n_points, n_vertices)
        ``"P"``, ``"Du"``, ``"Dv"``.
    P, Pu, Pv : ndarray (n_points, 3)
    dA : ndarray (n_points,)
        ``w_q |P_u x P_v|``: the points' area weights.
    Ginv : ndarray (n_points, 2, 2)
        Inverse metric.
    normal, kappa : ndarray (n_points, 3), (n_points,)
        With ``curvature=True``: unit normal ``P_u x P_v / |.|`` and ``kappa = -g^ab (P_ab . n)``
        (2/R on a sphere of radius R with the outward normal).
    area : float
    """

    def __init__(self, surface, rule, parameterization="natural", curvature=False):
        f, u, v, w = rule
        d = 2 if curvature else 1
        self.W = surface.basis(f, u, v, 1, parameterization=parameterization)
        r = surface.evaluate(f, u, v, d, parameterization=parameterization)
        self.P, self.Pu, self.Pv = r["P"], r["Pu"], r["Pv"]
        g11 = np.einsum("ij,ij->i", self.Pu, self.Pu)
        g12 = np.einsum("ij,ij->i", self.Pu, self.Pv)
        g22 = np.einsum("ij,ij->i", self.Pv, self.Pv)
        det = g11 * g22 - g12 * g12
        if not (det > 0).all():
            i = int(np.flatnonzero(~(det > 0))[0])
            raise CCProofError(f"quadrature point {i} (face {int(f[i])}, u = {float(u[i])!r}, v = {float(v[i])!r}): "
                               "degenerate metric (a point at an extraordinary corner?)")
        self.dA = w * np.sqrt(det)
        self.Ginv = np.stack([np.stack([g22, -g12], -1), np.stack([-g12, g11], -1)], -2) / det[:, None, None]
        self.area = float(self.dA.sum())
        if curvature:
            n = np.cross(self.Pu, self.Pv)
            self.normal = n / np.linalg.norm(n, axis=1)[:, None]
            II = [[np.einsum("ij,ij->i", r[k], self.normal) for k in row] for row in (("Puu", "Puv"), ("Puv", "Pvv"))]
            G = self.Ginv
            self.kappa = -(G[:, 0, 0] * II[0][0] + 2 * G[:, 0, 1] * II[0][1] + G[:, 1, 1] * II[1][1])

    def combine(self, terms):
        """``sum_k diag(c_k) B_k`` for ``terms = [(c_k, B_k)]`` as one CSR matrix (directly on the data where
        the rows share one sparsity pattern, as the basis rows of one surface do)."""
        B0 = terms[0][1]
        reps = np.diff(B0.indptr)
        data = np.zeros(B0.nnz)
        for c, B in terms:
            if B.nnz != B0.nnz or not (np.array_equal(B.indptr, B0.indptr) and np.array_equal(B.indices, B0.indices)):
                return sum(sp.diags(c) @ B for c, B in terms).tocsr()  # rows of other origins: general sum
            data += np.repeat(c, reps) * B.data
        return sp.csr_matrix((data, B0.indices.copy(), B0.indptr.copy()), shape=B0.shape)

    def mass(self):
        """``W_P^T diag(dA) W_P`` (sparse, symmetric)."""
        P = self.W["P"]
        return (P.T @ self.combine([(self.dA, P)])).tocsr()

    def stiffness(self):
        """``sum_ab W_a^T diag(dA G^ab) W_b``: the Laplace-Beltrami stiffness (sparse, symmetric)."""
        Du, Dv = self.W["Du"], self.W["Dv"]
        G, w = self.Ginv, self.dA
        E = sp.vstack([self.combine([(w * G[:, 0, 0], Du), (w * G[:, 0, 1], Dv)]),
                       self.combine([(w * G[:, 1, 0], Du), (w * G[:, 1, 1], Dv)])], format="csr")
        return (sp.vstack([Du, Dv], format="csr").T @ E).tocsr()

    def load(self, values):
        """``W_P^T (dA values)`` for the values (n_points,) of f at the points."""
        return self.W["P"].T @ (self.dA * np.asarray(values, dtype=np.float64))

    def surface_gradient(self, c):
        """``grad_Gamma u_h`` (n_points, 3) of the coefficients c (n_vertices,)."""
        a, b = self.W["Du"] @ c, self.W["Dv"] @ c
        G = self.Ginv
        ga, gb = G[:, 0, 0] * a + G[:, 0, 1] * b, G[:, 1, 0] * a + G[:, 1, 1] * b
        return ga[:, None] * self.Pu + gb[:, None] * self.Pv

    def errors(self, c, exact):
        """``(L2, H1 seminorm)`` errors of ``u_h = W_P c`` against an :class:`AmbientFunction` (this rule)."""
        e = self.W["P"] @ c - exact.value(self.P)
        n = np.cross(self.Pu, self.Pv)
        n /= np.linalg.norm(n, axis=1)[:, None]
        gu = exact.gradient(self.P)
        gu -= np.einsum("ij,ij->i", gu, n)[:, None] * n
        ge = self.surface_gradient(c) - gu
        return float(np.sqrt(self.dA @ (e * e))), float(np.sqrt(self.dA @ np.einsum("ij,ij->i", ge, ge)))


class AmbientFunction:
    """A smooth function of R^3 restricted to the surface: ``u(x) = sin(a x) cos(b y) exp(c z)``.

    Its Laplace-Beltrami operator at surface points with unit normal n and ``kappa = div_Gamma n``:
    ``Laplace_Gamma u = tr(H) - n^T H n - kappa (grad u . n)`` (H the ambient Hessian), so the right-hand
    side ``f = -Laplace_Gamma u + u`` of a manufactured solution is exact at every point where the
    surface's second derivatives are.

    >>> u = AmbientFunction(1.0, 1.0, 0.0)
    >>> import numpy as np
    >>> x = np.array([[0.3, 0.2, 0.0]])
    >>> bool(np.allclose(u.hessian(x)[0].trace(), -2 * u.value(x)[0]))
    True
    """

    def __init__(self, a=1.0, b=1.0, c=0.5):
        self.a, self.b, self.c = float(a), float(b), float(c)

    def value(self, X):
        x, y, z = X.T
        return np.sin(self.a * x) * np.cos(self.b * y) * np.exp(self.c * z)

    def gradient(self, X):
        a, b, c = self.a, self.b, self.c
        x, y, z = X.T
        sx, cx, sy, cy, ez = np.sin(a * x), np.cos(a * x), np.sin(b * y), np.cos(b * y), np.exp(c * z)
        return np.stack([a * cx * cy * ez, -b * sx * sy * ez, c * sx * cy * ez], axis=1)

    def hessian(self, X):
        a, b, c = self.a, self.b, self.c
        x, y, z = X.T
        sx, cx, sy, cy, ez = np.sin(a * x), np.cos(a * x), np.sin(b * y), np.cos(b * y), np.exp(c * z)
        H = np.empty((X.shape[0], 3, 3))
        H[:, 0, 0] = -a * a * sx * cy * ez
        H[:, 1, 1] = -b * b * sx * cy * ez
        H[:, 2, 2] = c * c * sx * cy * ez
        H[:, 0, 1] = H[:, 1, 0] = -a * b * cx * sy * ez
        H[:, 0, 2] = H[:, 2, 0] = a * c * cx * cy * ez
        H[:, 1, 2] = H[:, 2, 1] = -b * c * sx * sy * ez
        return H

    def laplace_beltrami(self, fields):
        """``Laplace_Gamma u`` at the points of ``fields`` (made with ``curvature=True``)."""
        X, n = fields.P, fields.normal
        H = self.hessian(X)
        return np.trace(H, axis1=1, axis2=2) - np.einsum("ni,nij,nj->n", n, H, n) \
            - fields.kappa * np.einsum("ij,ij->i", self.gradient(X), n)

    def screened_poisson_rhs(self, fields):
        """``f = -Laplace_Gamma u + u`` at the points of ``fields`` (made with ``curvature=True``)."""
        return -self.laplace_beltrami(fields) + self.value(fields.P)


def solve_spd(A, b, rtol=1e-13):
    """``A^-1 b`` for a symmetric positive definite sparse A: conjugate gradients on the Jacobi-scaled
    system (``D A D``, ``D = diag(A)^-1/2``), to a relative residual ``rtol``.

    >>> import scipy.sparse as sp
    >>> A = sp.csr_matrix(np.array([[4.0, 1.0], [1.0, 3.0]]))
    >>> np.round(solve_spd(A, np.array([1.0, 2.0])) * 11, 10).tolist()
    [1.0, 7.0]
    """
    from scipy.sparse.linalg import cg

    d = 1.0 / np.sqrt(A.diagonal())
    D = sp.diags(d)
    y, info = cg((D @ A @ D).tocsr(), d * b, rtol=rtol, maxiter=20 * A.shape[0] + 100)
    if info != 0:
        raise CCProofError(f"conjugate gradients did not reach rtol={rtol} in {info} iterations")
    return d * y


def solve_screened_poisson(surface, rule, exact, parameterization="natural", error_rule=None):
    """Galerkin solution of ``-Laplace_Gamma u + u = f`` for the manufactured solution ``exact``.

    Parameters
    ----------
    surface : LimitSurface
        Closed (no boundary conditions are imposed).
    rule : QuadratureRule
        For the matrices and the load.
    exact : AmbientFunction
    parameterization : str or parameterization value
    error_rule : QuadratureRule, optional
        For the errors (default: ``rule``); a finer rule keeps the measured error that of the solution.

    Returns
    -------
    dict
        ``c`` (n_vertices,) coefficients, ``L2``, ``H1`` (seminorm) errors, ``dofs``.
    """
    F = SurfaceFields(surface, rule, parameterization, curvature=True)
    c = solve_spd(F.stiffness() + F.mass(), F.load(exact.screened_poisson_rhs(F)))
    E = F if error_rule is None else SurfaceFields(surface, error_rule, parameterization)
    L2, H1 = E.errors(c, exact)
    return {"c": c, "L2": L2, "H1": H1, "dofs": int(c.size)}
