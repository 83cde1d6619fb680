"""Kirchhoff plate bending on the flat open mesh: ``Delta^2 w = f`` on the unit square, clamped (``w = 0``
and ``grad w . m = 0`` on its boundary) or simply supported (``w = 0`` and no bending moment, ``Delta w = 0``).

The space is the ghost-ring space of :func:`ccproof.apps.iga.convergence.open_study_mesh` built directly at
mesh size ``1 / n``: the ``(n + 2) x (n + 2)`` grid shifted by one ghost row on every side, the region its
``n x n`` inner faces. Every region face is a regular bicubic patch of the uniform lattice, so the region's
limit is exactly the unit square and its functions are the tensor-product cubic B-splines on it. The
essential conditions are imposed strongly, per direction on the B-spline coefficients ``c_-1, c_0, c_1`` of
the three functions at an edge (and the mirror image at 1), so the constrained space is the tensor product
of two 1D spaces (:func:`plate_square`): clamped, ``s(0) = s'(0) = 0`` is ``c_-1 = c_1``, ``c_0 = -c_1 / 2``;
simply supported, ``s(0) = 0`` is ``c_-1 = -4 c_0 - c_1``.

The bending energy: clamped, ``int nabla^2 w : nabla^2 v`` (Poisson ratio 0; for a clamped plate every ratio
gives the same solution); simply supported, ``int Delta w Delta v`` (ratio 1), whose natural condition is
``Delta w = 0``. The covariant Hessian ``nabla^2 phi_ab = phi_ab - Gamma^c_ab phi_c`` comes from the basis's
second-derivative rows and the metric (:func:`hessian_rows`), contracted with the inverse metric
(``|H|^2 = tr(G H G H)``, written as the Frobenius norm of ``L^T H L`` for ``G = L L^T``).

Manufactured solutions, ``f = Delta^2 w`` in closed form (:class:`PlateSolution`):
``w = sin^2(pi x) sin^2(pi y)`` (clamped) and ``w = sin(pi x) sin(pi y)`` (simply supported).

>>> r = solve_plate(4)
>>> r["dofs"], r["L2"] < 1e-2
(9, True)
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ccproof.errors import CCProofError

__all__ = ["plate_square", "hessian_rows", "solve_plate", "PlateSolution", "SUPPORTS"]

SUPPORTS = ("clamped", "simple")


def _constrained_1d(n, support):
    """Coefficients ``c_-1 .. c_(n+1)`` from the free ones: ``c_1 .. c_(n-1)`` (clamped, (n + 3, n - 1)) or
    ``c_0 .. c_n`` (simply supported, (n + 3, n + 1))."""
    if support == "clamped":
        T = sp.lil_matrix((n + 3, n - 1))
        for k in range(1, n):
            T[k + 1, k - 1] = 1.0
        T[0, 0], T[1, 0] = 1.0, -0.5  # c_-1 = c_1, c_0 = -c_1 / 2
        T[n + 2, n - 2], T[n + 1, n - 2] = 1.0, -0.5  # c_(n+1) = c_(n-1), c_n = -c_(n-1) / 2
        return T.tocsr()
    T = sp.lil_matrix((n + 3, n + 1))
    for k in range(n + 1):
        T[k + 1, k] = 1.0
    T[0, 0], T[0, 1] = -4.0, -1.0  # c_-1 = -4 c_0 - c_1
    T[n + 2, n], T[n + 2, n - 1] = -4.0, -1.0  # c_(n+1) = -4 c_n - c_(n-1)
    return T.tocsr()


def plate_square(n, support="clamped"):
    """The ghost grid of the unit square at mesh size 1/n, its region and the constrained space.

    Returns
    -------
    mesh : QuadMesh
        ``grid(n + 2, n + 2)`` shifted by one cell and scaled by 1/n (vertex ``i + (n + 3) j`` at
        ``((i - 1)/n, (j - 1)/n)``).
    region : bool (n_faces,)
        The ``n x n`` faces over the unit square.
    T : CSR (n_vertices, (n - 1)^2 or (n + 1)^2)
        Coefficients of the clamped or simply supported functions (columns) in the vertices' functions.

    >>> M, region, T = plate_square(4)
    >>> M.n_vertices, int(region.sum()), T.shape, plate_square(4, "simple")[2].shape
    (49, 16, (49, 9), (49, 25))
    """
    from ccproof.mesh import QuadMesh
    from ccproof.mesh.examples import grid

    if support not in SUPPORTS:
        raise CCProofError(f"unknown plate support {support!r}; use one of {', '.join(SUPPORTS)}")
    if int(n) < 2:
        raise CCProofError(f"the plate square needs n >= 2 faces per side, got n={n!r}")
    n = int(n)
    g = grid(n + 2, n + 2)
    V = (np.asarray(g.vertices) - [1.0, 1.0, 0.0]) / n
    V[:, 2] = 0.0
    i = np.arange(n + 2)
    inner = (i >= 1) & (i <= n)
    region = (inner[None, :] & inner[:, None]).ravel()  # face i + (n + 2) j
    T1 = _constrained_1d(n, support)
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
        out.append(fields.combine(terms))
    return tuple(out)


class PlateSolution:
    """``w = s(x) s(y)`` with ``s = sin^2(pi x)`` (``"clamped"``) or ``sin(pi x)`` (``"simple"``): value,
    gradient, Hessian (n, 2, 2) and ``Delta^2 w`` at points (n, 3)."""

    def __init__(self, support="clamped"):
        self.support = support

    def _s(self, x):
        """s and its derivatives of orders 1, 2, 4."""
        if self.support == "simple":
            c, s = np.cos(np.pi * x), np.sin(np.pi * x)
            return s, np.pi * c, -np.pi**2 * s, np.pi**4 * s
        c, s = np.cos(2 * np.pi * x), np.sin(2 * np.pi * x)
        return (1 - c) / 2, np.pi * s, 2 * np.pi**2 * c, -8 * np.pi**4 * c

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


def solve_plate(n, support="clamped", order=4, error_order=6):
    """Galerkin solution of the plate ``Delta^2 w = f`` on the unit square at mesh size 1/n for the
    manufactured :class:`PlateSolution` of ``support`` (module docstring).

    Returns
    -------
    dict
        ``c`` (n_vertices,), errors ``L2``, ``H1`` (seminorm), ``H2`` (``||nabla^2 (w_h - w)||``), ``dofs``
        (the constrained space's dimension).
    """
    from ccproof.apps.iga.assembly import SurfaceFields, solve_spd
    from ccproof.apps.iga.quadrature import surface_quadrature
    from ccproof.evaluate import natural_limit_surface

    M, region, T = plate_square(n, support)
    S = natural_limit_surface(M)
    w = PlateSolution(support)

    def fields(k):
        Q = surface_quadrature(S, k, "plain")
        Q = type(Q)(*(a[region[Q.face]] for a in Q))
        F = SurfaceFields(S, Q)
        return F, hessian_rows(S, F, Q)

    F, R = fields(order)
    D = sp.diags(F.dA)
    if support == "clamped":
        K = R[0].T @ D @ R[0] + 2 * (R[1].T @ D @ R[1]) + R[2].T @ D @ R[2]
    else:
        Lap = (R[0] + R[2]).tocsr()
        K = Lap.T @ D @ Lap
    b = F.load(w.bilaplacian(F.P))
    c = T @ solve_spd((T.T @ K @ T).tocsr(), T.T @ b)
    F, R = fields(error_order)
    L2, H1 = F.errors(c, w)
    # the exact Hessian in the same orthonormal frame: the Cartesian one (the plane z = 0, frame L^T)
    J = np.stack([F.Pu[:, :2], F.Pv[:, :2]], 2)  # columns P_u, P_v in the plane
    E = np.einsum("nia,nap->nip", J, np.linalg.cholesky(F.Ginv))  # the orthonormal frame in x, y
    He = np.einsum("nip,nij,njq->npq", E, w.hessian(F.P), E)
    e2 = sum(k * (R[i] @ c - He[:, p, q]) ** 2 for i, (p, q, k) in enumerate(((0, 0, 1), (0, 1, 2), (1, 1, 1))))
    return {"c": c, "L2": L2, "H1": H1, "H2": float(np.sqrt(F.dA @ e2)), "dofs": int(T.shape[1])}
