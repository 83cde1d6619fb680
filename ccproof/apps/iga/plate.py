"""Kirchhoff plate bending on the flat open mesh, clamped: ``Delta^2 w = f`` on the unit square, ``w = 0``
and ``grad w . m = 0`` on its boundary.

The space is the ghost-ring space of :func:`ccproof.apps.iga.convergence.open_study_mesh` built directly at
mesh size ``1 / n``: the ``(n + 2) x (n + 2)`` grid shifted by one ghost row on every side, the region its
``n x n`` inner faces. Every region face is a regular bicubic patch of the uniform lattice, so the region's
limit is exactly the unit square and its functions are the tensor-product cubic B-splines on it. Clamping
is imposed strongly: per direction, the conditions ``s(0) = s'(0) = 0`` on the B-spline coefficients
``c_-1, c_0, c_1`` of the three functions at the edge are ``c_-1 = c_1``, ``c_0 = -c_1 / 2`` (and the mirror
image at 1), so the clamped space is the tensor product of the two 1D spaces (:func:`clamped_square`).

The bending energy is ``int nabla^2 w : nabla^2 v`` (Poisson ratio 0; for clamped plates every ratio gives
the same solution), the covariant Hessian ``nabla^2 phi_ab = phi_ab - Gamma^c_ab phi_c`` from the basis's
second-derivative rows and the metric (:func:`hessian_rows`), contracted with the inverse metric
(``|H|^2 = tr(G H G H)``, written as the Frobenius norm of ``L^T H L`` for ``G = L L^T``).

Manufactured solution ``w = sin^2(pi x) sin^2(pi y)`` (clamped on the square), ``f = Delta^2 w`` in closed form.

>>> r = solve_clamped_plate(4)
>>> r["dofs"], r["L2"] < 1e-2
(9, True)
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ccproof.errors import CCProofError

__all__ = ["clamped_square", "hessian_rows", "solve_clamped_plate", "SIN2"]


def _clamped_1d(n):
    """(n + 3, n - 1): coefficients ``c_-1 .. c_(n+1)`` from the free ones ``c_1 .. c_(n-1)``."""
    T = sp.lil_matrix((n + 3, n - 1))
    for k in range(1, n):
        T[k + 1, k - 1] = 1.0
    T[0, 0], T[1, 0] = 1.0, -0.5  # c_-1 = c_1, c_0 = -c_1 / 2
    T[n + 2, n - 2], T[n + 1, n - 2] = 1.0, -0.5  # c_(n+1) = c_(n-1), c_n = -c_(n-1) / 2
    return T.tocsr()


def clamped_square(n):
    """The ghost grid of the unit square at mesh size 1/n, its region and the clamped space.

    Returns
    -------
    mesh : QuadMesh
        ``grid(n + 2, n + 2)`` shifted by one cell and scaled by 1/n (vertex ``i + (n + 3) j`` at
        ``((i - 1)/n, (j - 1)/n)``).
    region : bool (n_faces,)
        The ``n x n`` faces over the unit square.
    T : CSR (n_vertices, (n - 1)^2)
        Coefficients of the clamped functions (columns) in the vertices' functions.

    >>> M, region, T = clamped_square(4)
    >>> M.n_vertices, int(region.sum()), T.shape
    (49, 16, (49, 9))
    """
    from ccproof.mesh import QuadMesh
    from ccproof.mesh.examples import grid

    if int(n) < 2:
        raise CCProofError(f"the clamped square needs n >= 2 faces per side, got n={n!r}")
    n = int(n)
    g = grid(n + 2, n + 2)
    V = (np.asarray(g.vertices) - [1.0, 1.0, 0.0]) / n
    V[:, 2] = 0.0
    i = np.arange(n + 2)
    inner = (i >= 1) & (i <= n)
    region = (inner[None, :] & inner[:, None]).ravel()  # face i + (n + 2) j
    T1 = _clamped_1d(n)
    return QuadMesh(V, g.faces), region, sp.kron(T1, T1, format="csr")  # vertex i + (n + 3) j: j slow


def hessian_rows(surface, fields, rule):
    """Rows ``(R11, R12, R22)`` (CSR, n_points x n_vertices) with ``sum R11^2 + 2 R12^2 + R22^2 = |nabla^2 phi|^2``
    at every point: the covariant Hessian in an orthonormal frame of the tangent plane (``L^T H L``,
    ``g^-1 = L L^T``), from the basis's second derivatives and the metric of ``fields`` (same rule)."""
    f, u, v, _ = rule
    W = surface.basis(f, u, v, 2)
    r = surface.evaluate(f, u, v, 2)
    G = fields.Ginv
    Pd = (r["Pu"], r["Pv"])
    second = {(0, 0): ("Duu", r["Puu"]), (0, 1): ("Duv", r["Puv"]), (1, 1): ("Dvv", r["Pvv"])}
    H = {}
    for (a, b), (name, Pab) in second.items():  # H_ab = phi_ab - Gamma^c_ab phi_c, Gamma^c_ab = g^cd P_ab . P_d
        t = [np.einsum("ij,ij->i", Pab, P) for P in Pd]
        gu = G[:, 0, 0] * t[0] + G[:, 0, 1] * t[1]
        gv = G[:, 1, 0] * t[0] + G[:, 1, 1] * t[1]
        H[a, b] = [(np.ones(f.size), W[name]), (-gu, W["Du"]), (-gv, W["Dv"])]
    L = np.linalg.cholesky(G)  # G = L L^T
    out = []
    for p, q in ((0, 0), (0, 1), (1, 1)):  # (L^T H L)_pq = sum_ab L_ap L_bq H_ab
        terms = []
        for (a, b), parts in H.items():
            w = L[:, a, p] * L[:, b, q] + (L[:, b, p] * L[:, a, q] if a != b else 0.0)
            terms += [(w * c, B) for c, B in parts]
        out.append(fields._scaled(terms))
    return tuple(out)


class SIN2:
    """``w = sin^2(pi x) sin^2(pi y)``: value, gradient, Hessian (n, 2, 2) and ``Delta^2 w`` at points (n, 3)."""

    @staticmethod
    def _s(x):
        c, s = np.cos(2 * np.pi * x), np.sin(2 * np.pi * x)
        return (1 - c) / 2, np.pi * s, 2 * np.pi**2 * c, -8 * np.pi**4 * c  # s, s', s'', s''''

    def value(self, X):
        return self._s(X[:, 0])[0] * self._s(X[:, 1])[0]

    def gradient(self, X):
        sx, sy = self._s(X[:, 0]), self._s(X[:, 1])
        return np.stack([sx[1] * sy[0], sx[0] * sy[1], np.zeros(X.shape[0])], 1)

    def hessian(self, X):
        sx, sy = self._s(X[:, 0]), self._s(X[:, 1])
        H = np.empty((X.shape[0], 2, 2))
        H[:, 0, 0], H[:, 1, 1] = sx[2] * sy[0], sx[0] * sy[2]
        H[:, 0, 1] = H[:, 1, 0] = sx[1] * sy[1]
        return H

    def bilaplacian(self, X):
        sx, sy = self._s(X[:, 0]), self._s(X[:, 1])
        return sx[3] * sy[0] + 2 * sx[2] * sy[2] + sx[0] * sy[3]


def solve_clamped_plate(n, order=4, error_order=6):
    """Galerkin solution of the clamped plate ``Delta^2 w = f`` on the unit square at mesh size 1/n for
    ``w = sin^2(pi x) sin^2(pi y)`` (module docstring).

    Returns
    -------
    dict
        ``c`` (n_vertices,), errors ``L2``, ``H1`` (seminorm), ``H2`` (``||nabla^2 (w_h - w)||``), ``dofs``
        (the clamped space's dimension).
    """
    from ccproof.apps.iga.assembly import SurfaceFields, solve_spd
    from ccproof.apps.iga.quadrature import surface_quadrature
    from ccproof.evaluate import natural_limit_surface

    M, region, T = clamped_square(n)
    S = natural_limit_surface(M)
    w = SIN2()

    def fields(k):
        Q = surface_quadrature(S, k, "plain")
        Q = type(Q)(*(a[region[Q.face]] for a in Q))
        F = SurfaceFields(S, Q)
        return F, hessian_rows(S, F, Q)

    F, R = fields(order)
    D = sp.diags(F.dA)
    K = R[0].T @ D @ R[0] + 2 * (R[1].T @ D @ R[1]) + R[2].T @ D @ R[2]
    b = F.load(w.bilaplacian(F.P))
    c = T @ solve_spd((T.T @ K @ T).tocsr(), T.T @ b)
    F, R = fields(error_order)
    L2, H1 = F.errors(c, _Ambient(w))
    # the exact Hessian in the same orthonormal frame: the Cartesian one (the plane z = 0, frame L^T)
    Hx = w.hessian(F.P)
    J = np.stack([F.Pu[:, :2], F.Pv[:, :2]], 2)  # columns P_u, P_v in the plane
    L = np.linalg.cholesky(F.Ginv)
    E = np.einsum("nia,nap->nip", J, L)  # the orthonormal frame's vectors in x, y
    He = np.einsum("nip,nij,njq->npq", E, Hx, E)
    e2 = sum(k * (R[i] @ c - He[:, p, q]) ** 2 for i, (p, q, k) in enumerate(((0, 0, 1), (0, 1, 2), (1, 1, 1))))
    return {"c": c, "L2": L2, "H1": H1, "H2": float(np.sqrt(F.dA @ e2)), "dofs": int(T.shape[1])}


class _Ambient:
    """:class:`~ccproof.apps.iga.assembly.SurfaceFields.errors` takes value and gradient only."""

    def __init__(self, w):
        self.value, self.gradient = w.value, w.gradient
