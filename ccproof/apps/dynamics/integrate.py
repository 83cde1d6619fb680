"""Implicit time integration of ``M p'' + D p' + K p = f_p`` (qmv98 section 3.3, eqs. 29-32; docs/qmv98.md B5).

With the central differences (29), (30) at ``t + dt``, the paper's scheme (31) is::

    (2M + D dt + 2 dt^2 K) p(t+dt) = 2 dt^2 f_p(t+dt) + (D dt - 2M) p(t-dt) + 4M p(t)

and for a massless model (32)::

    (D + 2 dt K) p(t+dt) = 2 dt f_p(t+dt) + D p(t-dt)

(backward Euler with step ``2 dt`` on the even and the odd steps separately). Both are first-order
accurate and dissipative; their fixed point is the equilibrium ``K p = f_p``. Every step solves one
symmetric positive definite system for the three coordinates at once by conjugate gradients with a
Jacobi (diagonal) preconditioner (:func:`pcg`), either on the assembled sparse matrix or element by
element (``matrix_free=True``).

Springs (:class:`ccproof.apps.dynamics.forces.Springs`) are treated semi-implicitly: their force
``k J^T (d - J p(t+dt))`` is split into ``k J^T J`` (added to the system matrix with the same factor as
K) and ``k J^T d`` (added to ``f_p``), with the attachment points fixed during the step.

>>> import numpy as np
>>> sysm = MatrixSystem(M=[[1.0]], D=[[0.5]], K=[[4.0]])
>>> integ = ImplicitIntegrator(sysm, dt=0.1, P=np.array([[1.0]]))
>>> for _ in range(50):
...     _ = integ.step()
>>> round(float(integ.P[0, 0]), 3)        # scheme (31) at T = 5; exact -0.269 (error 0.159, docs/qmv98.md B5)
-0.11
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ccproof.errors import CCProofError

__all__ = ["pcg", "MatrixSystem", "ModelSystem", "ImplicitIntegrator", "StepInfo"]


def pcg(apply, B, diag, X0=None, tol=1e-10, maxiter=None):
    """Jacobi-preconditioned conjugate gradients for ``A X = B`` with several right-hand sides.

    The columns are independent CG runs carried out in lockstep (A is shared).

    Parameters
    ----------
    apply : callable
        ``apply(X) -> A X`` for X of shape (n, k).
    B : ndarray (n, k)
    diag : ndarray (n,)
        Diagonal of A (positive).
    X0 : ndarray (n, k), optional
        Starting guess (default 0).
    tol : float
        Stop when ``||B - A X|| <= tol ||B||`` for every column.
    maxiter : int, optional
        Default ``10 n``.

    Returns
    -------
    X : ndarray (n, k)
    info : dict
        ``iterations`` and ``residual`` (the largest relative residual ``||B - A X|| / ||B||``,
        recomputed from X at the end).

    >>> A = np.array([[4.0, 1.0], [1.0, 3.0]])
    >>> X, info = pcg(lambda X: A @ X, np.array([[1.0], [2.0]]), np.diag(A))
    >>> np.round(X[:, 0], 12).tolist(), info["residual"] < 1e-10
    ([0.090909090909, 0.636363636364], True)
    """
    B = np.asarray(B, dtype=np.float64)
    vec = B.ndim == 1
    if vec:
        B = B[:, None]
    n = B.shape[0]
    if np.any(diag <= 0) or not np.all(np.isfinite(diag)):
        raise CCProofError("the system matrix has a non-positive diagonal entry: it is not positive definite")
    maxiter = 10 * n + 10 if maxiter is None else int(maxiter)
    X = np.zeros_like(B) if X0 is None else np.array(X0, dtype=np.float64).reshape(B.shape)
    bnorm = np.linalg.norm(B, axis=0)
    bnorm = np.where(bnorm > 0, bnorm, 1.0)
    R = B - apply(X)
    inv = 1.0 / diag[:, None]
    Z = R * inv
    Pd = Z.copy()
    rz = np.sum(R * Z, axis=0)
    it = 0
    while it < maxiter:
        if np.all(np.linalg.norm(R, axis=0) <= tol * bnorm):
            break
        AP = apply(Pd)
        pap = np.sum(Pd * AP, axis=0)
        if np.any(pap < 0):
            raise CCProofError("conjugate gradients met a negative curvature: the matrix is not positive definite")
        alpha = np.divide(rz, pap, out=np.zeros_like(rz), where=pap > 0)
        X += alpha * Pd
        R -= alpha * AP
        Z = R * inv
        rz_new = np.sum(R * Z, axis=0)
        beta = np.divide(rz_new, rz, out=np.zeros_like(rz), where=rz > 0)
        Pd = Z + beta * Pd
        rz = rz_new
        it += 1
    res = float(np.max(np.linalg.norm(B - apply(X), axis=0) / bnorm))
    return (X[:, 0] if vec else X), {"iterations": it, "residual": res}


class MatrixSystem:
    """``M, D, K`` given as matrices (dense or sparse): the generic system of :class:`ImplicitIntegrator`.

    Parameters
    ----------
    M, D, K : array_like or scipy.sparse matrix, shape (n, n)
        Mass, damping and stiffness matrices of ``M p'' + D p' + K p = f_p`` (qmv98 section 3.3).

    Examples
    --------
    >>> s = MatrixSystem(M=[[1.0]], D=[[0.5]], K=[[4.0]])
    >>> np.round(s.assemble(2.0, 0.1, 0.02).toarray(), 12).tolist()      # 2 * 1 + 0.1 * 0.5 + 0.02 * 4
    [[2.13]]
    """

    def __init__(self, M, D, K):
        self.M, self.D, self.K = (sp.csr_matrix(np.asarray(X, dtype=np.float64) if not sp.issparse(X) else X)
                                  for X in (M, D, K))
        n = self.M.shape[0]
        for name, X in (("M", self.M), ("D", self.D), ("K", self.K)):
            if X.shape != (n, n):
                raise CCProofError(f"{name} must be square of size {n}, got {X.shape}")
        self.n_vertices = n

    def assemble(self, cM, cD, cK):
        return (cM * self.M + cD * self.D + cK * self.K).tocsr()

    def apply(self, X, cM, cD, cK):
        return cM * (self.M @ X) + cD * (self.D @ X) + cK * (self.K @ X)

    def diagonal(self, cM, cD, cK):
        return cM * self.M.diagonal() + cD * self.D.diagonal() + cK * self.K.diagonal()

    def mass_apply(self, X):
        return self.M @ X

    def damping_apply(self, X):
        return self.D @ X


class ModelSystem:
    """Adapter of a :class:`~ccproof.apps.dynamics.model.DynamicSurface` (``M = mu M1, D = gamma M1``).

    The system ``M p'' + D p' + K p = f_p`` of qmv98 section 3.3 with the model's assembled or
    element-by-element operators.

    Parameters
    ----------
    model : DynamicSurface

    Examples
    --------
    With mu = gamma = 1 (the default material) the mass and the damping operators agree:

    >>> import numpy as np
    >>> from ccproof.apps.dynamics.meshes import paper_initial_model
    >>> from ccproof.apps.dynamics.model import DynamicSurface
    >>> m = DynamicSurface(paper_initial_model())
    >>> s = ModelSystem(m)
    >>> one = np.ones((s.n_vertices, 1))
    >>> bool(np.allclose(s.mass_apply(one).sum(), s.damping_apply(one).sum())), s.n_vertices
    (True, 98)
    """

    def __init__(self, model):
        self.model = model
        self.n_vertices = model.n_vertices
        self.mu = model.material.mu
        self.gamma = model.material.gamma

    def _c(self, cM, cD):
        return cM * self.mu + cD * self.gamma

    def assemble(self, cM, cD, cK):
        return self.model.assemble(self._c(cM, cD), cK)

    def apply(self, X, cM, cD, cK):
        return self.model.matvec(X, self._c(cM, cD), cK)

    def diagonal(self, cM, cD, cK):
        return self.model.diagonal(self._c(cM, cD), cK)

    def mass_apply(self, X):
        return self.model.matvec(X, self.mu, 0.0)

    def damping_apply(self, X):
        return self.model.matvec(X, self.gamma, 0.0)


@dataclass
class StepInfo:
    """What one implicit step did.

    Parameters
    ----------
    iterations : int
        CG iterations.
    residual : float
        Relative CG residual.
    displacement : float
        Max |p(t+dt) - p(t)| over the control points.

    Examples
    --------
    >>> import numpy as np
    >>> I = ImplicitIntegrator(MatrixSystem(M=[[1.0]], D=[[0.0]], K=[[1.0]]), 0.01, P=np.array([[1.0]]))
    >>> info = I.step()
    >>> info.iterations, info.residual < 1e-12
    (1, True)
    """

    iterations: int
    residual: float
    displacement: float  # max |p(t+dt) - p(t)| over the control points


class ImplicitIntegrator:
    """The implicit schemes (31) (``scheme="inertial"``) and (32) (``scheme="massless"``).

    Parameters
    ----------
    system : DynamicSurface, MatrixSystem or ModelSystem
    dt : float > 0
    P : ndarray (n, k)
        State at time t (default: the model's control points).
    P_prev : ndarray (n, k), optional
        State at time t - dt (default: P, i.e. starting at rest).
    scheme : "inertial" or "massless"
    tol : float
        Relative CG tolerance per step.
    matrix_free : bool
        Element-by-element products instead of the assembled matrix.
    copies : array_like of int, shape (n,), optional
        Rows of the state that are one point (the copies of one vertex of a non-manifold file,
        :func:`ccproof.apps.control_file.read_control_mesh`): ``copies[i]`` is the label of row i, the
        labels ``0 .. r-1``. The state is then ``P = E Y`` (``E`` the 0/1 (n, r) matrix of the labels) and
        each step solves ``E^T A E Y = E^T b`` for the r free points (forces, stiffness and mass pulled
        back by ``E^T``), so the copies move together. None (default): every row is free.

    Attributes
    ----------
    P, P_prev : the current and the previous state; ``t`` the time; ``history`` list of StepInfo.

    Examples
    --------
    The oscillator x'' + x = 0 from x = 1 at rest: after t = 0.1 the first-order scheme is within
    1e-3 of cos(0.1):

    >>> import math
    >>> import numpy as np
    >>> I = ImplicitIntegrator(MatrixSystem(M=[[1.0]], D=[[0.0]], K=[[1.0]]), 0.01, P=np.array([[1.0]]))
    >>> for _ in range(10):
    ...     _ = I.step()
    >>> round(I.t, 12), abs(float(I.P[0, 0]) - math.cos(0.1)) < 1e-3
    (0.1, True)
    """

    def __init__(self, system, dt, P=None, P_prev=None, scheme="inertial", tol=1e-10, matrix_free=False,
                 copies=None):
        from ccproof.apps.dynamics.model import DynamicSurface

        if isinstance(system, DynamicSurface):
            system = ModelSystem(system)
        try:
            dt = float(dt)
        except (TypeError, ValueError):
            raise CCProofError(f"time step dt must be a number, got {dt!r}") from None
        if not (math.isfinite(dt) and dt > 0):
            raise CCProofError(f"time step dt must be finite and > 0, got {dt!r}")
        if scheme not in ("inertial", "massless"):
            raise CCProofError(f"scheme must be 'inertial' (eq. 31) or 'massless' (eq. 32), got {scheme!r}")
        if not (tol > 0):
            raise CCProofError(f"CG tolerance must be > 0, got {tol!r}")
        self.system = system
        self.dt = dt
        self.scheme = scheme
        self.tol = float(tol)
        self.matrix_free = bool(matrix_free)
        if P is None:
            P = system.model.vertices if isinstance(system, ModelSystem) else np.zeros((system.n_vertices, 1))
        self.P = np.array(P, dtype=np.float64)
        if self.P.ndim != 2 or self.P.shape[0] != system.n_vertices:
            raise CCProofError(f"state must have shape ({system.n_vertices}, k), got {self.P.shape}")
        if not np.isfinite(self.P).all():
            raise CCProofError("the initial state has non-finite entries")
        self.P_prev = self.P.copy() if P_prev is None else np.array(P_prev, dtype=np.float64).reshape(self.P.shape)
        self.t = 0.0
        self.history = []
        if scheme == "inertial":
            self._c = (2.0, dt, 2.0 * dt * dt)  # (cM, cD, cK)
        else:
            self._c = (0.0, 1.0, 2.0 * dt)
        self._A = None
        self._diag = None
        self._E = None
        if copies is not None:
            lab = np.asarray(copies, dtype=np.int64).reshape(-1)
            n = self.P.shape[0]
            if lab.shape[0] != n or (lab < 0).any():
                raise CCProofError(f"copies must be {n} labels >= 0")
            r = int(lab.max()) + 1 if n else 0
            self._E = sp.csr_matrix((np.ones(n), (np.arange(n), lab)), shape=(n, r))
            used, self._first = np.unique(lab, return_index=True)  # the first row of every label
            if used.size != r:
                raise CCProofError("copies: every label 0 .. max must be used")

    def _base(self):
        if self.matrix_free:
            if self._diag is None:
                self._diag = self.system.diagonal(*self._c)
        elif self._A is None:
            self._A = self.system.assemble(*self._c)
            self._diag = self._A.diagonal()
        return self._A, self._diag

    def system_operator(self, springs=None):
        """``(apply, diag)`` of the step matrix, springs included."""
        A, diag = self._base()
        cK = self._c[2]
        if self.matrix_free:
            def base_apply(X):
                return self.system.apply(X, *self._c)
        else:
            def base_apply(X):
                return A @ X
        if springs is None or springs.count == 0:
            return base_apply, diag
        if not self.matrix_free:
            At = (A + cK * springs.matrix()).tocsr()
            return (lambda X: At @ X), At.diagonal()
        Js, JsT, kw = springs.jacobian, springs.jacobian.T.tocsr(), springs.stiffness

        def apply(X):
            return base_apply(X) + cK * (JsT @ (kw[:, None] * (Js @ X)))

        d = diag + cK * np.asarray(Js.multiply(Js).T @ kw).reshape(-1)
        return apply, d

    def _reduced_operator(self, springs):
        """``(apply, diag)`` of ``E^T A E`` (the step matrix on the free points, ``copies``)."""
        E, ET = self._E, self._E.T.tocsr()
        if not self.matrix_free:
            A, _ = self._base()
            if springs is not None and springs.count:
                A = A + self._c[2] * springs.matrix()
            Ar = (ET @ A @ E).tocsr()
            return (lambda Y: Ar @ Y), Ar.diagonal()
        apply, diag = self.system_operator(springs)
        # Jacobi preconditioner: the copies' diagonals summed (the coupling between copies left out)
        return (lambda Y: ET @ apply(E @ Y)), np.asarray(ET @ diag).reshape(-1)

    def step(self, force=None, springs=None):
        """Advance one step; ``force`` (n, k) is the generalized force f_p(t+dt), ``springs`` a Springs."""
        P, Pp = self.P, self.P_prev
        dt = self.dt
        F = np.zeros_like(P) if force is None else np.asarray(force, dtype=np.float64).reshape(P.shape)
        if springs is not None and springs.count:
            F = F + springs.rest_force()
        if self.scheme == "inertial":
            rhs = 2 * dt * dt * F + dt * self.system.damping_apply(Pp) - 2 * self.system.mass_apply(Pp) \
                + 4 * self.system.mass_apply(P)
        else:
            rhs = 2 * dt * F + self.system.damping_apply(Pp)
        X0 = 2 * P - Pp  # linear extrapolation as the starting guess
        if self._E is None:
            apply, diag = self.system_operator(springs)
            Pn, info = pcg(apply, rhs, diag, X0=X0, tol=self.tol)
        else:
            apply, diag = self._reduced_operator(springs)
            E = self._E
            Y, info = pcg(apply, np.asarray(E.T @ rhs), diag, X0=X0[self._first], tol=self.tol)
            Pn = np.asarray(E @ Y)
        if not info["residual"] <= 10 * self.tol:
            warnings.warn(f"CG stopped at relative residual {info['residual']:.2e} > {self.tol:.1e} "
                          f"after {info['iterations']} iterations", RuntimeWarning, stacklevel=2)
        disp = float(np.max(np.linalg.norm(Pn - P, axis=1))) if P.size else 0.0
        self.P_prev, self.P = P, Pn
        self.t += dt
        si = StepInfo(info["iterations"], info["residual"], disp)
        self.history.append(si)
        return si
