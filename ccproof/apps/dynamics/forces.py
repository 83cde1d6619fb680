"""Applied forces: springs to points of the limit surface and data forces from point clouds (qmv98 section 3.2).

A spring of stiffness k from a point d0 to the limit-surface point ``s(u0, v0)`` (eq. 27, delta
kernel) has the generalized force ``f_p = k J(u0, v0)^T (d0 - J(u0, v0) p)`` (eq. 21). A set of
springs is stored as the sparse matrix ``J_S`` (one row ``J(u0, v0)`` per spring), the stiffnesses and
the anchor points; :class:`~ccproof.apps.dynamics.integrate.ImplicitIntegrator` moves ``k J^T J``
into the step matrix (semi-implicit).

Range data: every data point pulls the *nearest* point of the limit surface (docs/qmv98.md B7.4, B7.5),
found by the package's global closest-point search (:mod:`ccproof.evaluate.closest`: bounding cylinders
of sampled cells, a bounding-volume hierarchy, projected Newton descents) on the exact evaluator
:class:`ccproof.evaluate.LimitSurface` of the current state (:class:`ModelClosestPoints`). The FEM
model and the evaluator share the face parameter of :class:`ccproof.mesh.QuadMesh` (face ``f``, its
corner i at (0,0), (1,0), (1,1), (0,1)), so the answer ``(face, u, v)`` is the attachment point of
the model as it is.
"""

from __future__ import annotations

import math

import numpy as np

from ccproof.errors import CCProofError

__all__ = ["Springs", "SurfaceToDataSprings", "ModelClosestPoints", "closest_cells", "check_points"]


def check_points(X, name="point cloud"):
    """Validate a point cloud: a finite, non-empty float array of shape (m, 3).

    Parameters
    ----------
    X : array_like, shape (m, 3)
    name : str, optional
        Used in the messages.

    Returns
    -------
    ndarray, shape (m, 3) float64

    Examples
    --------
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

    Notes
    -----
    The springs of qmv98 section 3.2 (eq. 27 with a delta kernel; generalized force eq. 21): energy
    sum_i k_i/2 |x(face_i, u_i, v_i) - d0_i|^2.

    Examples
    --------
    A spring of constant 3 stretched to length 2 stores 3/2 * 2^2 = 6:

    >>> import numpy as np
    >>> from ccproof.apps.dynamics.meshes import paper_initial_model
    >>> from ccproof.apps.dynamics.model import DynamicSurface
    >>> m = DynamicSurface(paper_initial_model())
    >>> x = m.evaluator().evaluate(np.array([0]), np.array([0.5]), np.array([0.5]))["P"][0]
    >>> s = Springs(m, [0], [0.5], [0.5], [x + [0, 0, -2.0]], 3.0)
    >>> s.count, s.lengths(m.vertices).round(12).tolist(), round(float(s.energy(m.vertices)), 12)
    (1, [2.0], 6.0)
    """

    def __init__(self, model, faces, u, v, anchors, stiffness, jacobian=None):
        anchors = check_points(anchors, "spring anchors")
        k = np.broadcast_to(np.asarray(stiffness, dtype=np.float64), (anchors.shape[0],)).copy()
        if not (np.isfinite(k).all() and (k >= 0).all()):
            raise CCProofError("spring stiffness must be finite and >= 0")
        self.model = model
        self.faces = np.asarray(faces)
        self.u = np.asarray(u, dtype=np.float64)
        self.v = np.asarray(v, dtype=np.float64)
        # the rows J(face, u, v) of fixed attachment points may be given (computed once, e.g. by the caller)
        self.jacobian = model.basis(self.faces, self.u, self.v)["P"] if jacobian is None else jacobian.tocsr()
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

    def pulling(self):
        """The springs with a constant > 0 (None if there is none): the same force, matrix and energy (the others
        add exact zeros), on fewer rows (a fit's surface -> data springs leave most samples at 0: their rows were
        most of a step's memory).

        >>> import numpy as np
        >>> from ccproof.apps.dynamics.meshes import paper_initial_model
        >>> from ccproof.apps.dynamics.model import DynamicSurface
        >>> m = DynamicSurface(paper_initial_model())
        >>> s = Springs(m, [0, 1], [0.5, 0.5], [0.5, 0.5], [[0, 0, 9.0], [1, 0, 0.0]], [0.0, 2.0])
        >>> p = s.pulling()
        >>> p.count, bool(np.allclose(p.force(m.vertices), s.force(m.vertices)))
        (1, True)
        >>> Springs(m, [0], [0.5], [0.5], [[0, 0, 9.0]], 0.0).pulling() is None
        True
        """
        keep = np.flatnonzero(self.stiffness > 0)
        if keep.size == self.count:
            return self
        if keep.size == 0:
            return None
        return Springs(self.model, self.faces[keep], self.u[keep], self.v[keep], self.anchors[keep],
                       self.stiffness[keep], jacobian=self.jacobian[keep])

    @classmethod
    def stacked(cls, first, second):
        """One set of springs holding the springs of ``first`` and then those of ``second`` (same model).

        >>> import numpy as np
        >>> from ccproof.apps.dynamics.meshes import paper_initial_model
        >>> from ccproof.apps.dynamics.model import DynamicSurface
        >>> m = DynamicSurface(paper_initial_model())
        >>> a = Springs(m, [0], [0.5], [0.5], [[0, 0, 9.0]], 1.0)
        >>> b = Springs(m, [1, 2], [0.5, 0.5], [0.5, 0.5], [[0, 0, 9.0], [1, 0, 0.0]], 2.0)
        >>> ab = Springs.stacked(a, b)
        >>> ab.count, bool(np.isclose(ab.energy(m.vertices), a.energy(m.vertices) + b.energy(m.vertices)))
        (3, True)
        """
        import scipy.sparse as sp

        if first.model is not second.model:
            raise CCProofError("springs of two different models cannot be stacked")
        return cls(first.model, np.concatenate([first.faces, second.faces]), np.concatenate([first.u, second.u]),
                   np.concatenate([first.v, second.v]), np.concatenate([first.anchors, second.anchors]),
                   np.concatenate([first.stiffness, second.stiffness]),
                   jacobian=sp.vstack([first.jacobian, second.jacobian], format="csr"))

    @classmethod
    def to_nearest(cls, model, P, anchors, stiffness, finder=None):
        """Springs attached to the points of the limit surface (state P) nearest to the anchors."""
        anchors = check_points(anchors, "spring anchors")
        finder = ModelClosestPoints(model) if finder is None else finder
        f, u, v, _, _ = finder.query(P, anchors)
        return cls(model, f, u, v, anchors, stiffness)


class SurfaceToDataSprings:
    """Springs from the limit surface to the data: the other direction of the data springs.

    The data springs pull, for every data point, the surface point nearest to it; a part of the surface
    that is nearest to no data point (a membrane spanning a concavity, a hole) feels no force from them
    and stays where the tension left it. These springs pull, for every one of ``per_side`` x ``per_side``
    fixed parameter samples of each patch face (the cell centres of a uniform grid), the surface point
    there toward the data point nearest to it (a k-d tree of the data, re-queried at every step): the
    two-way forces of qmv98 section 3.2, where a spring may pull the surface toward the data as well as a
    data point toward the surface. Sample i gets the constant ``total * a_i / A``: its share ``a_i`` of the
    current surface area (``|s_u x s_v|`` at the sample), so a region is pulled in proportion to its area.
    Only samples farther than ``slack`` from every data point are pulled, and only to within ``slack`` of
    their nearest data point (the anchor lies on the segment to it, ``slack`` short of it; the others get
    the constant 0): a surface the data covers lies within about one data spacing of the data everywhere,
    and pulling it onto the discrete points would draw it inward between them (by about spacing^2 / 8R on a
    convex part of radius R), while a region that no data point is near is pulled to the data.

    Parameters
    ----------
    model : DynamicSurface
    X : ndarray, shape (m, 3) float64
        The data points.
    total : float >= 0
        Sum of the spring constants over all samples (those within ``slack`` get 0).
    per_side : int, optional
        Samples per face side (default 4).
    slack : float >= 0, optional
        Distance to the data within which a sample is not pulled (default 0; the fit passes its data
        spacing).

    Examples
    --------
    On the 98-vertex cube model with one data point far above it, every sample is pulled to that point;
    the constants sum to ``total`` and the springs' lengths are the distances of the samples to it less
    the slack:

    >>> import numpy as np
    >>> from ccproof.apps.dynamics.meshes import paper_initial_model
    >>> from ccproof.apps.dynamics.model import DynamicSurface
    >>> m = DynamicSurface(paper_initial_model())
    >>> rev = SurfaceToDataSprings(m, np.array([[0, 0, 10.0]]), 2.0, per_side=2, slack=0.5)
    >>> s, d = rev.springs(m.vertices)
    >>> s.count, round(float(s.stiffness.sum()), 12), bool(np.allclose(s.lengths(m.vertices), d - 0.5))
    (384, 2.0, True)
    """

    def __init__(self, model, X, total, per_side=4, slack=0.0):
        from scipy.spatial import cKDTree

        if not (math.isfinite(total) and total >= 0):
            raise CCProofError(f"the surface -> data spring total must be finite and >= 0, got {total!r}")
        if not (math.isfinite(slack) and slack >= 0):
            raise CCProofError(f"the slack of the surface -> data springs must be finite and >= 0, got {slack!r}")
        if int(per_side) != per_side or per_side < 1:
            raise CCProofError(f"per_side must be an integer >= 1, got {per_side!r}")
        self.model = model
        self.data = check_points(X, "data points")
        self.total = float(total)
        self.slack = float(slack)
        faces = np.flatnonzero(model.layout.face_kind > 0)  # the faces that carry a patch
        g = (np.arange(per_side) + 0.5) / per_side
        uu, vv = np.meshgrid(g, g, indexing="ij")
        self.faces = np.repeat(faces, per_side * per_side)
        self.u = np.tile(uu.ravel(), faces.size)
        self.v = np.tile(vv.ravel(), faces.size)
        rows = model.basis(self.faces, self.u, self.v, derivatives=1)
        self.jacobian, self._du, self._dv = rows["P"], rows["Du"], rows["Dv"]
        self._tree = cKDTree(self.data)

    def springs(self, P):
        """The springs for the state ``P`` (n, 3) and the distances of the samples to their nearest data points.

        Returns
        -------
        Springs, ndarray (k,)
        """
        Y = np.asarray(self.jacobian @ P)
        area = np.linalg.norm(np.cross(np.asarray(self._du @ P), np.asarray(self._dv @ P)), axis=1)
        dist, nearest = self._tree.query(Y)
        D = self.data[nearest]
        total_area = float(area.sum())
        k = self.total * area / total_area if total_area > 0 else np.full(area.size, self.total / area.size)
        pulled = dist > self.slack
        k[~pulled] = 0.0
        anchors = Y.copy()  # the samples within the slack: constant 0, anchored where they are
        anchors[pulled] = D[pulled] + (self.slack / dist[pulled])[:, None] * (Y[pulled] - D[pulled])
        return Springs(self.model, self.faces, self.u, self.v, anchors, k, jacobian=self.jacobian), dist


def closest_cells(n_faces, budget=25_000, most=8):
    """Cells per face side of the closest-point search on a model with ``n_faces`` patch faces: about
    ``budget`` cells in all (the search structure is rebuilt at every correspondence update, so its
    cost and memory stay bounded on fine meshes), at most ``most``, at least 1.

    Parameters
    ----------
    n_faces : int
    budget : int, optional
    most : int, optional

    Returns
    -------
    int

    Examples
    --------
    >>> closest_cells(96), closest_cells(1536), closest_cells(24576)
    (8, 4, 1)
    """
    return int(min(most, max(1, round(math.sqrt(budget / max(int(n_faces), 1))))))


def _evaluated_mesh(mesh):
    """The mesh :class:`~ccproof.evaluate.LimitSurface` evaluates for a control mesh: a tagged one as a
    :class:`~ccproof.mesh.polymesh.PolyMesh` with its creases, corners and holes (all quads: ptex face = face)."""
    from ccproof.apps.control_mesh import TaggedQuadMesh

    if not isinstance(mesh, TaggedQuadMesh):
        return mesh
    from ccproof.mesh.polymesh import PolyMesh

    e = np.flatnonzero(mesh.edge_sharpness > 0)
    v = np.flatnonzero(mesh.vertex_sharpness > 0)
    return PolyMesh(mesh.vertices, mesh.faces, creases=(mesh.edges[e], np.minimum(mesh.edge_sharpness[e], 10.0)),
                    corners=(v, np.minimum(mesh.vertex_sharpness[v], 10.0)), holes=np.flatnonzero(mesh.hole),
                    _halfedges=mesh.halfedges)  # the same faces: the control mesh's topology, shared


class ModelClosestPoints:
    """Globally nearest points of the limit surface of a model's state (module docstring).

    The evaluator of the model's mesh is built once; every :meth:`query` moves it to the state ``P``
    (:meth:`ccproof.evaluate.LimitSurface.with_vertices`, the connectivity's tables re-used) and runs
    :class:`ccproof.evaluate.closest.ClosestPointFinder` on the faces that carry a patch of the model.

    Parameters
    ----------
    model : DynamicSurface
    cells : int, optional
        Cells per face side of the search (default :func:`closest_cells`).

    Examples
    --------
    Building the search takes seconds (compilation), so this example is not run; the data points
    on the limit surface are at distance 0:

    >>> from ccproof.apps.dynamics.meshes import paper_initial_model
    >>> from ccproof.apps.dynamics.model import DynamicSurface
    >>> from ccproof.apps.dynamics.cloud import limit_surface_mesh
    >>> m = DynamicSurface(paper_initial_model())
    >>> X = limit_surface_mesh(m.mesh, 1).vertices                                     # doctest: +SKIP
    >>> res = ModelClosestPoints(m).query(m.vertices, X)                                 # doctest: +SKIP
    """

    def __init__(self, model, cells=None):
        from ccproof.evaluate import LimitSurface

        self.model = model
        self.faces = np.flatnonzero(model.layout.face_kind > 0)
        self.cells = closest_cells(self.faces.size) if cells is None else int(cells)
        self.surface = LimitSurface(_evaluated_mesh(model.mesh))

    def query(self, P, X):
        """Nearest limit-surface points to X (m, 3) for the state P (n, 3).

        Returns
        -------
        faces, u, v : (m,) the attachment parameters (faces with a patch of the model)
        points : (m, 3) the limit-surface points
        dist : (m,) their distances to X
        """
        from ccproof.evaluate.closest import ClosestPointFinder

        X = check_points(X, "query points")
        P = np.asarray(P, dtype=np.float64)
        if P.shape != (self.model.n_vertices, 3):
            raise CCProofError(f"control points must have shape ({self.model.n_vertices}, 3), got {P.shape}")
        # quad or tagged (a PolyMesh with the model's vertices, in order): the same numbers as a fresh build
        S = self.surface.with_vertices(P)
        faces = None if self.faces.size == self.model.mesh.n_faces else self.faces
        r = ClosestPointFinder(S, cells=self.cells, faces=faces).query(X)
        return r.face, r.u, r.v, r.P, r.distance
