"""Local/global ARAP iteration on samples (hsh10 section 3, Appendix; docs/hsh10.md A5, A6, A7).

Energy (Eq. 3): with X = T^0 (N x 2) the texture unknowns, every sample j has
``t_{j,c} = G_c[j] X`` (rows of sparse operators), the isometric frame ``Q_j = (p^_1 p^_2)^-1`` and a
weight ``w_j``; ``grad phi_j = (t_1 t_2) Q_j = X^T H_j`` and

    E(X, R) = sum_j w_j || X^T H_j - R_j ||_F^2.

Local step (Theorem 1): for A = [[a, b], [c, d]] the closest rotation is
``[[a + d, b - c], [c - b, a + d]] / sqrt((a + d)^2 + (c - b)^2)`` (identity in the degenerate
case a = -d, b = c, where every rotation is equally good).

Global step: the normal equations ``L X = B`` with ``L = sum_j w_j H_j H_j^T`` (independent of
R: factorized ONCE per level with SuperLU and reused) and ``B = sum_j w_j H_j R_j^T`` (rebuilt every
iteration, two sparse products). One unknown is pinned (the energy is translation invariant).
If ``L`` restricted to the free unknowns is (numerically) singular, e.g. at level 0 on regular
grids (docs/hsh10.md A6 caution), a proximal term ``mu ||X - X_prev||^2`` is added; it keeps the energy
monotone and the run reports ``regularized=True``.

The same class runs Liu et al.'s triangle ARAP (baselines (a), (d)): one sample per triangle with
the edge vectors as tangents and the area as weight (:func:`triangle_samples`).

>>> import numpy as np
>>> R = closest_rotations(np.array([[[1.0, 2.0], [3.0, 4.0]]]))
>>> np.round(R[0] * np.hypot(5, 1), 12).tolist()
[[5.0, -1.0], [1.0, 5.0]]
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ccproof.apps.arap.samples import SampleSet, isometric_frames

__all__ = ["closest_rotations", "LocalGlobal", "IterationResult", "iterate", "triangle_samples", "lbfgs"]


def closest_rotations(J, previous=None):
    """Theorem 1 of hsh10: the rotation closest to each 2x2 matrix of ``J`` (s, 2, 2).

    The local step of the local/global iteration (hsh10 Appendix, Theorem 1).

    Parameters
    ----------
    J : ndarray, shape (s, 2, 2) float64
    previous : ndarray, shape (s, 2, 2), optional
        The previous rotations, kept where J is degenerate (x = a + d and y = c - b both 0).

    Returns
    -------
    ndarray, shape (s, 2, 2) float64

    Examples
    --------
    A scaling is closest to the identity, a scaled rotation to its rotation:

    >>> import numpy as np
    >>> R = closest_rotations(np.array([[[2.0, 0], [0, 1]], [[0, -3.0], [3, 0]]]))
    >>> (R + 0.0).tolist()
    [[[1.0, 0.0], [0.0, 1.0]], [[0.0, -1.0], [1.0, 0.0]]]
    """
    a, b, c, d = J[:, 0, 0], J[:, 0, 1], J[:, 1, 0], J[:, 1, 1]
    x = a + d
    y = c - b
    nrm = np.hypot(x, y)
    deg = nrm <= 1e-300
    safe = np.where(deg, 1.0, nrm)
    co = np.where(deg, 1.0, x / safe)
    si = np.where(deg, 0.0, y / safe)
    R = np.empty_like(J)
    R[:, 0, 0] = co
    R[:, 0, 1] = -si
    R[:, 1, 0] = si
    R[:, 1, 1] = co
    if previous is not None and deg.any():
        R[deg] = previous[deg]
    return R


@dataclass
class IterationResult:
    """Outcome of :func:`iterate` at one level.

    Parameters
    ----------
    X : ndarray, shape (n_unknowns, 2) float64
    iterations : int
    energies : list of float
        E(X_i, R(X_i)) after each local step (hsh10 Eq. 3).
    seconds : float
    converged : bool
    trace, residuals : list, optional
        Energy after each half step (global, local, ...) and global solve residuals, when traced.

    Examples
    --------
    >>> import numpy as np
    >>> from ccproof.apps.arap.lscm import triangulate_quads
    >>> V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0.0]])
    >>> system = LocalGlobal(*triangle_samples(V, triangulate_quads(V, [[0, 1, 2, 3]])))
    >>> res = iterate(system, 1.3 * V[:, :2])
    >>> res.converged, res.energies[-1] < 1e-20, np.round(res.X, 9).tolist()
    (True, True, [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    """

    X: np.ndarray
    iterations: int
    energies: list
    seconds: float
    converged: bool
    #: energy after each half step (global, local, global, ...) when traced
    trace: list = field(default_factory=list)
    residuals: list = field(default_factory=list)

    @property
    def seconds_per_iteration(self):
        return self.seconds / max(self.iterations, 1)


class LocalGlobal:
    """The fixed-level system: operators H, matrix L (factorized once), local and global steps.

    The global step of hsh10 section 3 (Eq. 3 as a sparse least-squares problem).

    Parameters
    ----------
    p1, p2 : ndarray, shape (s, 3) float64
        Surface tangents.
    G1, G2 : scipy.sparse matrix, shape (s, N)
        Texture rows: the texture tangents are ``G1 @ X``, ``G2 @ X``.
    weight : ndarray, shape (s,) float64
    pin : int, optional
        The pinned unknown.
    factor : bool, optional
        Factorize L now.

    Examples
    --------
    >>> import numpy as np
    >>> V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0.0]])
    >>> system = LocalGlobal(*triangle_samples(V, [[0, 1, 2]]))
    >>> np.round(iterate(system, 2 * V[:, :2]).X, 9).tolist()      # back to the isometry
    [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]
    """

    def __init__(self, p1, p2, G1, G2, weight, pin=0, factor=True):
        t0 = time.perf_counter()
        a, b, c = isometric_frames(p1, p2)
        w = np.asarray(weight, dtype=np.float64)
        good = (w > 1e-14 * w.max()) & (a > 0) & (c > 0)
        self.dropped = int((~good).sum())
        idx = np.flatnonzero(good)
        a, b, c, w = a[idx], b[idx], c[idx], w[idx]
        G1 = sp.csr_matrix(G1)[idx]
        G2 = sp.csr_matrix(G2)[idx]
        Hu = sp.diags(1.0 / a) @ G1  # rows h_{j,1}^T: first column of H_j = [g1 g2] Q_j
        Hv = sp.diags(-b / (a * c)) @ G1 + sp.diags(1.0 / c) @ G2  # rows h_{j,2}^T
        # stacked [Hu; Hv]: one sparse product per direction and iteration
        self.H = sp.vstack([Hu, Hv]).tocsr()
        del Hu, Hv, G1, G2
        self.w = w
        self.w2 = np.concatenate([w, w])[:, None]
        self.weight_sum = float(w.sum())
        self.pin = int(pin)
        self.mu = 0.0
        self.regularized = False
        self.n_samples = idx.size
        if not factor:  # energy evaluation only
            self.build_seconds = time.perf_counter() - t0
            return
        self.L = (self.H.T @ sp.diags(self.w2[:, 0]) @ self.H).tocsc()
        N = self.L.shape[0]
        self.N = N
        self.free = np.setdiff1d(np.arange(N), [self.pin])
        Lff = self.L[self.free][:, self.free].tocsc()
        self.Lfp = self.L[self.free][:, [self.pin]]
        self._factor(Lff)
        self.build_seconds = time.perf_counter() - t0

    def _factor(self, Lff):
        try:  # L is symmetric positive (semi)definite: symmetric ordering, no pivoting (much less fill)
            lu = spla.splu(Lff, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options={"SymmetricMode": True})
            d = np.abs(lu.U.diagonal())
            if d.size and d.min() <= 1e-12 * d.max():
                raise RuntimeError("nearly singular")
            self.lu = lu
        except RuntimeError:
            self.mu = 1e-8 * float(np.abs(Lff.diagonal()).mean() or 1.0)
            self.regularized = True
            self.lu = spla.splu((Lff + self.mu * sp.identity(Lff.shape[0], format="csc")).tocsc(),
                                permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options={"SymmetricMode": True})
        self.Lff = Lff

    def jacobians(self, X):
        """grad phi of every sample, (s, 2, 2): J[:, c, 0] = (Hu X)[:, c], J[:, c, 1] = (Hv X)[:, c]."""
        s = self.w.size
        Y = self.H @ X
        J = np.empty((s, 2, 2))
        J[:, :, 0] = Y[:s]
        J[:, :, 1] = Y[s:]
        return J

    def energy(self, J, R):
        """E(X, R) = sum_j w_j ||J_j - R_j||^2."""
        D = (J - R).reshape(-1, 4)
        return float(self.w @ (D * D).sum(axis=1))

    def rhs(self, R):
        """B = sum_j w_j H_j R_j^T, shape (N, 2)."""
        return self.H.T @ (self.w2 * np.concatenate([R[:, :, 0], R[:, :, 1]]))  # CSC view: no stored copy

    def global_step(self, R, X):
        """Minimize E(., R) (plus the proximal term when regularized); the pinned unknown stays."""
        B = self.rhs(R)
        Xn = np.array(X, dtype=np.float64, copy=True)
        rhs = B[self.free] - self.Lfp @ X[[self.pin]]
        if self.mu:
            rhs = rhs + self.mu * X[self.free]
        Xn[self.free] = self.lu.solve(np.asarray(rhs))
        return Xn

    def residual(self, R, X):
        """||L X - B|| / ||B|| on the free unknowns (without the proximal term)."""
        B = self.rhs(R)
        r = (self.L @ X - B)[self.free]
        nb = np.linalg.norm(B[self.free])
        return float(np.linalg.norm(r) / nb) if nb else float(np.linalg.norm(r))


def iterate(system: LocalGlobal, X0, tol=1e-6, max_iter=200, trace=False, min_iter=1, accel=0):
    """Alternate local and global steps until the relative energy decrease is below ``tol``.

    ``accel`` > 0: Anderson acceleration of the fixed-point map X -> global_step(R(X)) with a history of
    ``accel`` steps, safeguarded by the energy (Peng et al. 2018, "Anderson acceleration for geometry
    optimization and physics simulation"): the accelerated iterate is kept only if its energy
    E(X, R(X)) is below the last accepted one, else the plain local/global step is taken, so the
    energy still decreases monotonically (``trace`` is not recorded then).

    Parameters
    ----------
    system : LocalGlobal
    X0 : ndarray, shape (N, 2) float64
    tol : float, optional
    max_iter, min_iter : int, optional
    trace : bool, optional
    accel : int, optional

    Returns
    -------
    IterationResult
        ``energies[i]`` is E(X_i, R(X_i)) (after each local step); with ``trace`` also the energy
        after every global step (``trace``) and the global solve residuals.

    Examples
    --------
    >>> import numpy as np
    >>> V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0.0]])
    >>> res = iterate(LocalGlobal(*triangle_samples(V, [[0, 1, 2]])), 3 * V[:, :2], accel=2)
    >>> res.converged, round(res.energies[-1], 12)
    (True, 0.0)
    """
    if accel and not trace:
        return _iterate_anderson(system, X0, tol, max_iter, min_iter, int(accel))
    t0 = time.perf_counter()
    X = np.array(X0, dtype=np.float64, copy=True)
    J = system.jacobians(X)
    R = closest_rotations(J)
    E = system.energy(J, R)
    energies = [E]
    tr = [E] if trace else []
    res = []
    converged = False
    it = 0
    while it < max_iter:
        Xn = system.global_step(R, X)
        it += 1
        J = system.jacobians(Xn)
        if trace:
            tr.append(system.energy(J, R))
            res.append(system.residual(R, Xn) if not system.mu else np.nan)
        R = closest_rotations(J, previous=R)
        En = system.energy(J, R)
        if trace:
            tr.append(En)
        energies.append(En)
        X = Xn
        done = En <= 1e-28 * system.weight_sum or (E - En) <= tol * E
        E = En
        if done and it >= min_iter:
            converged = True
            break
    return IterationResult(X, it, energies, time.perf_counter() - t0, converged, tr, res)


def _iterate_anderson(system, X0, tol, max_iter, min_iter, m):
    t0 = time.perf_counter()
    X = np.array(X0, dtype=np.float64, copy=True)
    J = system.jacobians(X)
    R = closest_rotations(J)
    E = system.energy(J, R)
    energies = [E]
    dG, dF = [], []
    g_prev = f_prev = None
    converged = False
    it = 0
    while it < max_iter:
        G = system.global_step(R, X)  # plain step from the accepted iterate
        it += 1
        f = (G - X).ravel()
        g = G.ravel()
        if g_prev is not None:
            dG.append(g - g_prev)
            dF.append(f - f_prev)
            if len(dG) > m:
                dG.pop(0)
                dF.pop(0)
        g_prev, f_prev = g, f
        Xn = G
        if dF:
            Fm = np.stack(dF, axis=1)
            gamma, *_ = np.linalg.lstsq(Fm, f, rcond=None)
            Xa = (g - np.stack(dG, axis=1) @ gamma).reshape(X.shape)
            Ja = system.jacobians(Xa)
            Ra = closest_rotations(Ja, previous=R)
            Ea = system.energy(Ja, Ra)
            if Ea < E:
                Xn, J, R, En = Xa, Ja, Ra, Ea
            else:  # safeguard: the plain step, and a fresh history
                dG.clear()
                dF.clear()
                Xn = None
        if Xn is None or not dF:
            Xn = G
            J = system.jacobians(Xn)
            R = closest_rotations(J, previous=R)
            En = system.energy(J, R)
        energies.append(En)
        X = Xn
        done = En <= 1e-28 * system.weight_sum or (E - En) <= tol * E
        E = En
        if done and it >= min_iter:
            converged = True
            break
    return IterationResult(X, it, energies, time.perf_counter() - t0, converged)


def triangle_samples(V, T):
    """Liu et al. 2008 triangle ARAP as samples: tangents = edge vectors, weight = triangle area.

    Parameters
    ----------
    V : ndarray, shape (n, 3) float64
    T : ndarray, shape (t, 3) int

    Returns
    -------
    p1, p2 : ndarray, shape (t, 3) float64
    G1, G2 : scipy.sparse.csr_matrix, shape (t, n)
        ``G1 X = X[v1] - X[v0]``, ``G2 X = X[v2] - X[v0]``.
    weight : ndarray, shape (t,) float64

    Examples
    --------
    >>> import numpy as np
    >>> p1, p2, G1, G2, w = triangle_samples(np.array([[0, 0, 0], [2, 0, 0], [0, 1, 0.0]]), [[0, 1, 2]])
    >>> p1.tolist(), G2.toarray().tolist(), w.tolist()
    ([[2.0, 0.0, 0.0]], [[-1.0, 0.0, 1.0]], [1.0])
    """
    V = np.asarray(V, dtype=np.float64)
    T = np.asarray(T, dtype=np.int64)
    t, n = T.shape[0], V.shape[0]
    p1 = V[T[:, 1]] - V[T[:, 0]]
    p2 = V[T[:, 2]] - V[T[:, 0]]
    r = np.arange(t)
    G1 = sp.csr_matrix((np.r_[np.ones(t), -np.ones(t)], (np.r_[r, r], np.r_[T[:, 1], T[:, 0]])), shape=(t, n))
    G2 = sp.csr_matrix((np.r_[np.ones(t), -np.ones(t)], (np.r_[r, r], np.r_[T[:, 2], T[:, 0]])), shape=(t, n))
    w = 0.5 * np.linalg.norm(np.cross(p1, p2), axis=1)
    return p1, p2, G1, G2, w


def system_from_samples(samples: SampleSet, A, pin=0):
    """The :class:`LocalGlobal` system of level-k samples with unknown->level operator ``A``.

    Parameters
    ----------
    samples : SampleSet
        :func:`~ccproof.apps.arap.samples.build_samples` of a level.
    A : scipy.sparse matrix, shape (n_k, n_unknowns)
        Level values from the texture unknowns.
    pin : int, optional
        The pinned unknown.

    Returns
    -------
    LocalGlobal

    Examples
    --------
    >>> import scipy.sparse as sp
    >>> from ccproof.mesh.examples import grid
    >>> from ccproof.apps.arap.hierarchy import ChartHierarchy
    >>> from ccproof.apps.arap.samples import build_samples
    >>> L = ChartHierarchy(grid(3, 3), range(9)).level(1)
    >>> S = system_from_samples(build_samples(L, "extended"), sp.identity(L.mesh.n_vertices, format="csr"))
    >>> res = iterate(S, L.mesh.vertices[:, :2])                  # the identity texture is isometric
    >>> res.converged, res.energies[-1] < 1e-20
    (True, True)
    """
    return LocalGlobal(samples.p1, samples.p2, samples.O1 @ A, samples.O2 @ A, samples.weight, pin=pin)


def lbfgs(f, y, max_iter=300, m=10, rtol=1e-9):
    """Minimize ``f`` (value, gradient; +inf outside its domain) from a point of its domain: L-BFGS with
    backtracking (Armijo) line search, which backs off from +inf (a barrier such as a fold); (y, f(y)).

    >>> y, fy = lbfgs(lambda y: (float((y - 3.0) @ (y - 3.0)), 2 * (y - 3.0)), np.zeros(2))
    >>> np.round(y, 6).tolist(), fy < 1e-12
    ([3.0, 3.0], True)
    """
    fy, g = f(y)
    S, Yk = [], []
    for _ in range(max_iter):
        q = g.copy()
        al = []
        for s, t in zip(reversed(S), reversed(Yk)):
            a = (s @ q) / (t @ s)
            al.append(a)
            q -= a * t
        if S:
            q *= (S[-1] @ Yk[-1]) / (Yk[-1] @ Yk[-1])
        else:
            q *= 1e-3 / max(np.abs(q).max(), 1e-300) * max(np.abs(y).max(), 1.0)
        for (s, t), a in zip(zip(S, Yk), reversed(al)):
            b = (t @ q) / (t @ s)
            q += s * (a - b)
        d = -q
        slope = g @ d
        if slope >= 0:
            d, slope, S, Yk = -g, -(g @ g), [], []
        step = 1.0
        for _ in range(40):
            yn = y + step * d
            fn, gn = f(yn)
            if fn <= fy + 1e-4 * step * slope:
                break
            step *= 0.5
        else:
            break
        s, t = yn - y, gn - g
        if s @ t > 1e-300:
            S.append(s)
            Yk.append(t)
            if len(S) > m:
                S.pop(0)
                Yk.pop(0)
        done = fy - fn <= rtol * max(abs(fy), 1.0)
        y, fy, g = yn, fn, gn
        if done:
            break
    return y, fy
