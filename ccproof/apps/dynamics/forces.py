"""Applied forces: springs to points of the limit surface and data forces from point clouds (qmv98 section 3.2).

A spring of stiffness k from a point d0 to the limit-surface point ``s(u0, v0)`` (eq. 27, delta
kernel) has the generalized force ``f_p = k J(u0, v0)^T (d0 - J(u0, v0) p)`` (eq. 21). A set of
springs is stored as the sparse matrix ``J_S`` (one row ``J(u0, v0)`` per spring), the stiffnesses and
the anchor points; :class:`~ccproof.apps.dynamics.integrate.ImplicitIntegrator` moves ``k J^T J``
into the step matrix (semi-implicit).

Range data: every data point pulls the *nearest* point of the limit surface (docs/qmv98.md B7.4, B7.5): the
surface is sampled densely (a grid per face, evaluated through a precomputed sparse sampling matrix),
the nearest samples are found with a k-d tree, and each candidate is refined by a projected
Gauss-Newton iteration on (u, v) inside its face; the closest candidate wins.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from ccproof.errors import CCProofError

__all__ = ["Springs", "ModelNearestPoints", "check_points"]


def check_points(X, name="point cloud"):
    """Validate a point cloud: a finite, non-empty float array of shape (m, 3).

    >>> check_points([[0, 0, float("nan")]])
    Traceback (most recent call last):
    ...
    ccproof.errors.CCProofError: point cloud has a non-finite coordinate at point 0
    """
    X = np.asarray(X, dtype=np.float64)
    if X.size == 0:
        raise CCProofError(f"{name} is empty")
    if X.ndim != 2 or X.shape[1] != 3:
        raise CCProofError(f"{name} must have shape (m, 3), got {X.shape}")
    bad = np.flatnonzero(~np.isfinite(X).all(axis=1))
    if bad.size:
        raise CCProofError(f"{name} has a non-finite coordinate at point {int(bad[0])}")
    return X


class Springs:
    """Springs from anchor points to fixed material points ``(face, u, v)`` of the limit surface.

    Parameters
    ----------
    model : DynamicSurface
    faces, u, v : array_like (m,)
        Attachment points (face parameters).
    anchors : array_like (m, 3)
        The other ends d0.
    stiffness : float or array_like (m,)
        Spring constants k >= 0.
    """

    def __init__(self, model, faces, u, v, anchors, stiffness):
        anchors = check_points(anchors, "spring anchors")
        k = np.broadcast_to(np.asarray(stiffness, dtype=np.float64), (anchors.shape[0],)).copy()
        if not (np.isfinite(k).all() and (k >= 0).all()):
            raise CCProofError("spring stiffness must be finite and >= 0")
        self.model = model
        self.faces = np.asarray(faces)
        self.u = np.asarray(u, dtype=np.float64)
        self.v = np.asarray(v, dtype=np.float64)
        self.jacobian = model.basis(self.faces, self.u, self.v)["P"]
        if self.jacobian.shape[0] != anchors.shape[0]:
            raise CCProofError("one anchor point per attachment point is needed")
        self.anchors = anchors
        self.stiffness = k

    @property
    def count(self):
        return self.anchors.shape[0]

    def rest_force(self):
        """``J_S^T (k d0)``: the part of the spring force that does not depend on p (n, 3)."""
        return np.asarray(self.jacobian.T @ (self.stiffness[:, None] * self.anchors))

    def force(self, P):
        """Explicit generalized spring force ``J_S^T k (d0 - J_S P)`` (n, 3)."""
        return np.asarray(self.jacobian.T @ (self.stiffness[:, None] * (self.anchors - self.jacobian @ P)))

    def matrix(self):
        """``J_S^T diag(k) J_S`` (sparse n x n)."""
        J = self.jacobian
        return (J.T @ J.multiply(self.stiffness[:, None]).tocsr()).tocsr()

    def lengths(self, P):
        """Current spring lengths |d0 - s(u0, v0)| (m,)."""
        return np.linalg.norm(self.anchors - self.jacobian @ P, axis=1)

    def energy(self, P):
        return 0.5 * float(np.sum(self.stiffness * self.lengths(P) ** 2))

    @classmethod
    def to_nearest(cls, model, P, anchors, stiffness, finder=None):
        """Springs attached to the points of the limit surface (state P) nearest to the anchors."""
        anchors = check_points(anchors, "spring anchors")
        finder = ModelNearestPoints(model) if finder is None else finder
        f, u, v, _, _ = finder.query(P, anchors)
        return cls(model, f, u, v, anchors, stiffness)


class ModelNearestPoints:
    """Nearest points of the limit surface of a model to query points (module docstring).

    Parameters
    ----------
    model : DynamicSurface
    per_edge : int
        Samples per face edge for the initial guess.
    candidates : int
        Nearest samples refined per query point (in distinct positions).
    iterations : int
        Gauss-Newton iterations.
    """

    def __init__(self, model, per_edge=6, candidates=2, iterations=6):
        self.model = model
        self.per_edge = int(per_edge)
        self.candidates = int(candidates)
        self.iterations = int(iterations)
        self.sf, self.su, self.sv = model.sample_parameters(self.per_edge)
        self.sample_basis = model.basis(self.sf, self.su, self.sv)["P"]

    def query(self, P, X, previous=None):
        """Nearest limit-surface points to X (m, 3) for the state P.

        Parameters
        ----------
        previous : tuple (faces, u, v), optional
            Earlier attachments, refined as one more candidate (warm start).

        Returns
        -------
        faces, u, v : (m,) the attachment parameters
        points : (m, 3) the limit-surface points
        dist : (m,) their distances to X
        """
        X = check_points(X, "query points")
        P = np.asarray(P, dtype=np.float64)
        S = self.sample_basis @ P
        tree = cKDTree(S)
        kq = min(self.candidates, S.shape[0])
        _, idx = tree.query(X, k=kq)
        idx = idx.reshape(X.shape[0], kq)
        F = [self.sf[idx[:, c]] for c in range(kq)]
        U = [self.su[idx[:, c]] for c in range(kq)]
        V = [self.sv[idx[:, c]] for c in range(kq)]
        if previous is not None:
            F.append(np.asarray(previous[0]))
            U.append(np.asarray(previous[1], dtype=np.float64))
            V.append(np.asarray(previous[2], dtype=np.float64))
        nc = len(F)
        f = np.concatenate(F)
        u = np.concatenate(U)
        v = np.concatenate(V)
        Xr = np.tile(X, (nc, 1))
        f, u, v, pts, d = self._newton(P, Xr, f, u, v)
        d = d.reshape(nc, -1)
        best = np.argmin(d, axis=0)
        m = X.shape[0]
        sel = best * m + np.arange(m)
        return f[sel], u[sel], v[sel], pts[sel], d[best, np.arange(m)]

    def _newton(self, P, X, f, u, v):
        ev = self.model.evaluator(P)
        r = ev.evaluate(f, u, v, 1)
        best_u, best_v, best_p = u.copy(), v.copy(), r["P"]
        best_d = np.linalg.norm(r["P"] - X, axis=1)
        for _ in range(self.iterations):
            res = r["P"] - X
            a = np.einsum("ij,ij->i", r["Pu"], r["Pu"])
            b = np.einsum("ij,ij->i", r["Pu"], r["Pv"])
            c = np.einsum("ij,ij->i", r["Pv"], r["Pv"])
            gu = np.einsum("ij,ij->i", r["Pu"], res)
            gv = np.einsum("ij,ij->i", r["Pv"], res)
            reg = 1e-12 * (a + c) + 1e-300
            det = (a + reg) * (c + reg) - b * b
            ok = det > 0
            det = np.where(ok, det, 1.0)
            du = np.where(ok, -((c + reg) * gu - b * gv) / det, 0.0)
            dv = np.where(ok, -((a + reg) * gv - b * gu) / det, 0.0)
            u = np.clip(u + du, 0.0, 1.0)
            v = np.clip(v + dv, 0.0, 1.0)
            r = ev.evaluate(f, u, v, 1)
            d = np.linalg.norm(r["P"] - X, axis=1)
            better = d < best_d
            best_u[better], best_v[better], best_d[better] = u[better], v[better], d[better]
            best_p[better] = r["P"][better]
        return f, best_u, best_v, best_p, best_d
