"""Point clouds against a surface, the measures of shape recovery (qmv98 section 4.2; docs/qmv98.md): the
minimal enclosing sphere (Welzl) that normalizes the data, the checks of a cloud, the data spacing, the
paper's fit error (data -> surface) and the other direction (:func:`surface_to_data`: surface samples far
from every data point). Used by :func:`ccproof.apps.dynamics.fit.fit_points`.
"""

from __future__ import annotations

import math

import numpy as np

from ccproof.apps.control_mesh import TaggedQuadMesh
from ccproof.apps.dynamics.forces import ModelClosestPoints, check_points
from ccproof.errors import CCProofError
from ccproof.mesh import QuadMesh

__all__ = ["minimal_enclosing_sphere", "fit_error", "check_cloud", "limit_surface_mesh", "surface_to_data",
           "data_spacing"]


def _ball(pts):
    """Smallest ball with all of ``pts`` (1 to 4 points) on its boundary; (centre, radius)."""
    pts = np.asarray(pts, dtype=np.float64)
    k = pts.shape[0]
    if k == 1:
        return pts[0].copy(), 0.0
    if k == 2:
        c = 0.5 * (pts[0] + pts[1])
        return c, float(np.linalg.norm(pts[0] - c))
    if k == 3:
        a, b = pts[1] - pts[0], pts[2] - pts[0]
        axb = np.cross(a, b)
        den = 2.0 * float(axb @ axb)
        if den <= 1e-30 * max(float(a @ a), float(b @ b), 1e-300) ** 2:
            return _best_sub_ball(pts)
        c = pts[0] + (np.cross(axb, a) * float(b @ b) + np.cross(b, axb) * float(a @ a)) / den
        return c, float(np.linalg.norm(pts[0] - c))
    A = 2.0 * (pts[1:] - pts[0])
    rhs = np.sum(pts[1:] ** 2, axis=1) - float(pts[0] @ pts[0])
    if abs(np.linalg.det(A)) <= 1e-14 * np.abs(A).max() ** 3:
        return _best_sub_ball(pts)
    c = np.linalg.solve(A, rhs)
    return c, float(np.linalg.norm(pts[0] - c))


def _best_sub_ball(pts):
    """Degenerate support set: the smallest ball through a subset that contains all of ``pts``."""
    from itertools import combinations

    best = None
    for size in range(2, pts.shape[0]):
        for sub in combinations(range(pts.shape[0]), size):
            c, r = _ball(pts[list(sub)])
            if np.all(np.linalg.norm(pts - c, axis=1) <= r * (1 + 1e-12) + 1e-15) and (best is None or r < best[1]):
                best = (c, r)
    return best


def minimal_enclosing_sphere(X, seed=0):
    """Smallest sphere containing the points (Welzl's algorithm, randomized, expected linear time).

    Parameters
    ----------
    X : array_like (m, 3)
    seed : int
        Seed of the random permutation (the result does not depend on it up to round-off).

    Returns
    -------
    centre : ndarray (3,)
    radius : float

    >>> c, r = minimal_enclosing_sphere([[1, 0, 0], [-1, 0, 0], [0, 0.5, 0], [0, 0, 0.2]])
    >>> np.round(c, 12).tolist(), round(r, 12)
    ([0.0, 0.0, 0.0], 1.0)
    """
    X = check_points(X)
    P = X[np.random.default_rng(seed).permutation(X.shape[0])]
    scale = float(np.abs(P).max()) or 1.0
    eps = 1e-12

    def first_out(c, r, lo, hi):
        if hi <= lo:
            return -1
        d = np.linalg.norm(P[lo:hi] - c, axis=1)
        out = np.flatnonzero(d > r * (1 + eps) + eps * scale)
        return lo + int(out[0]) if out.size else -1

    def with_support(n, support):
        if not support:  # the ball of P[:n]: start from the first point
            c, r = P[0].copy(), 0.0
            i = first_out(c, r, 1, n)
        else:
            c, r = _ball(np.array(support))
            if len(support) == 4:
                return c, r
            i = first_out(c, r, 0, n)
        while i >= 0:
            c, r = with_support(i, support + [P[i]])
            i = first_out(c, r, i + 1, n)
        return c, r

    c, r = with_support(P.shape[0], [])
    return c, r








def fit_error(model, P, X, finder=None, diameter=None):
    """Distances of the data points to the limit surface and the paper's fit error.

    Global closest points (:class:`~ccproof.apps.dynamics.forces.ModelClosestPoints`); the error
    measure of qmv98 section 4 (docs/qmv98.md B6).

    Parameters
    ----------
    model : DynamicSurface
    P : ndarray, shape (n_vertices, 3) float64
        The state.
    X : ndarray, shape (m, 3) float64
        Data points.
    finder : ModelClosestPoints, optional
        Re-used search structure.
    diameter : float, optional
        Default: the diameter of the minimal enclosing sphere of X.

    Returns
    -------
    dict
        ``max``, ``mean`` (absolute), ``max_percent``, ``mean_percent`` (of the diameter),
        ``distances`` (m,).

    Examples
    --------
    Building the closest-point search takes seconds (compilation), so this example is not run:
    for points sampled on the limit surface ``max`` is at rounding level.

    >>> from ccproof.apps.dynamics.meshes import paper_initial_model
    >>> from ccproof.apps.dynamics.model import DynamicSurface
    >>> m = DynamicSurface(paper_initial_model())
    >>> X = limit_surface_mesh(paper_initial_model(), 1).vertices
    >>> fit_error(m, m.vertices, X)["max"]                               # doctest: +SKIP
    """
    X = check_points(X)
    if finder is None:
        finder = ModelClosestPoints(model)
    *_, dist = finder.query(P, X)
    if diameter is None:
        diameter = 2.0 * minimal_enclosing_sphere(X)[1]
    return {
        "max": float(dist.max()),
        "mean": float(dist.mean()),
        "max_percent": 100.0 * float(dist.max()) / diameter,
        "mean_percent": 100.0 * float(dist.mean()) / diameter,
        "distances": dist,
    }


def check_cloud(X, min_points=20, flatness=1e-3):
    """Reject clouds no closed surface can be fitted to.

    Too few points, non-finite, coincident, coplanar or collinear (smallest principal extent below
    ``flatness`` times the largest).

    Parameters
    ----------
    X : array_like, shape (m, 3)
    min_points : int, optional
    flatness : float, optional

    Returns
    -------
    ndarray, shape (m, 3) float64

    Raises
    ------
    CCProofError
        Naming the problem.

    Examples
    --------
    >>> import numpy as np
    >>> check_cloud(np.zeros((30, 3)))
    Traceback (most recent call last):
    ...
    ccproof.errors.CCProofError: the data points all coincide
    >>> check_cloud(np.c_[np.random.default_rng(0).random((30, 2)), np.zeros(30)])
    Traceback (most recent call last):
    ...
    ccproof.errors.CCProofError: ...
    """
    X = check_points(X)
    C = X - X.mean(axis=0)
    s = np.linalg.svd(C, compute_uv=False)
    if not s[0] > 0:
        raise CCProofError("the data points all coincide")
    if X.shape[0] < min_points:
        raise CCProofError(f"need at least {min_points} data points to fit a closed surface, got {X.shape[0]}")
    if s[2] <= flatness * s[0]:
        kind = "collinear" if s[1] <= flatness * s[0] else "coplanar"
        raise CCProofError(
            f"the data points are (nearly) {kind}: principal extents {s[0]:.3g}, {s[1]:.3g}, {s[2]:.3g} "
            f"(ratio {s[2] / s[0]:.2g} <= {flatness:g}); a closed surface cannot be fitted to them")
    return X


def limit_surface_mesh(mesh, level):
    """The limit surface sampled at ``level``.

    The control mesh subdivided ``level`` times with its vertices moved to their exact limit positions
    (Catmull-Clark limit masks of the subdivision rules of docs/readings.md R1).

    Parameters
    ----------
    mesh : QuadMesh or TaggedQuadMesh
        A tagged mesh is subdivided with its tags and its hole faces are left out.
    level : int

    Returns
    -------
    QuadMesh

    Examples
    --------
    The corners of the cube with corners (+-1, +-1, +-1) go to (+-1/2, ...) (mask (n^2 v + 4 sum e +
    sum d) / (n (n + 5)), n = 3); after one step the face centres go to distance 68/81:

    >>> import numpy as np
    >>> from ccproof.mesh.examples import cube
    >>> float(np.abs(limit_surface_mesh(cube(), 0).vertices).max()), limit_surface_mesh(cube(), 1).n_faces
    (0.5, 24)
    >>> round(float(np.abs(limit_surface_mesh(cube(), 1).vertices).max()) * 81, 9)
    68.0
    """
    from ccproof.mesh import QuadMesh, limit_positions, subdivide
    from ccproof.mesh.quadmesh import shared_halfedges

    if isinstance(mesh, TaggedQuadMesh):  # tagged steps, exact limit masks with the tags; holes left out
        from ccproof.apps.control_mesh import moving_limit_rows, subdivide_control

        t: QuadMesh = mesh
        for _ in range(int(level)):
            t = subdivide_control(t)  # a TaggedQuadMesh stays one
        if not isinstance(t, TaggedQuadMesh):  # pragma: no cover - subdivide_control keeps the type
            raise TypeError("subdivide_control lost the tags")
        R = moving_limit_rows(t, np.arange(t.n_vertices), t.edge_sharpness, t.vertex_sharpness)
        F = t.faces[~t.hole]
        used, inv = np.unique(F, return_inverse=True)
        F = inv.reshape(F.shape)  # no holes, no unused vertex: t's faces, its topology shared
        return QuadMesh((R @ t.vertices)[used], F, _halfedges=shared_halfedges(t, F, used.size))
    m = mesh
    for _ in range(int(level)):
        m = subdivide(m)
    return m.with_vertices(limit_positions(m))


def _vertex_areas(mesh):
    V, F = np.asarray(mesh.vertices), mesh.faces
    a = 0.5 * (np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1)
               + np.linalg.norm(np.cross(V[F[:, 2]] - V[F[:, 0]], V[F[:, 3]] - V[F[:, 0]]), axis=1))
    return np.bincount(F.ravel(), weights=np.repeat(a / 4, 4), minlength=V.shape[0])


def data_spacing(X):
    """Median distance of a data point to its nearest other data point (cKDTree).

    Parameters
    ----------
    X : ndarray, shape (m, 3) float64

    Returns
    -------
    float

    Examples
    --------
    Nearest-neighbour distances 1, 1, 2: the median is 1:

    >>> import numpy as np
    >>> data_spacing(np.array([[0, 0, 0], [1, 0, 0], [3, 0, 0.0]]))
    1.0
    """
    from scipy.spatial import cKDTree

    d, _ = cKDTree(X).query(X, k=2)
    return float(np.median(d[:, 1]))


def surface_to_data(surface, X, stray_distance):
    """Surface -> data distances of the vertices of ``surface`` (a sampled limit surface, QuadMesh).

    The second half of the two-sided (Hausdorff) fit error (docs/qmv98.md).

    Parameters
    ----------
    surface : QuadMesh
    X : ndarray, shape (m, 3) float64
    stray_distance : float

    Returns
    -------
    dict
        ``distances`` (n,), ``areas`` (n,) vertex area weights, ``max``, ``mean`` and ``rms``
        (area-weighted), ``stray_fraction`` (area fraction farther than ``stray_distance``).

    Examples
    --------
    Data that is the surface's vertices moved by 0.01 along z:

    >>> from ccproof.mesh.examples import cube
    >>> S = limit_surface_mesh(cube(), 1)
    >>> r = surface_to_data(S, S.vertices + [0, 0, 0.01], 0.005)
    >>> round(r["max"], 12), round(r["mean"], 12), round(r["rms"], 12), r["stray_fraction"]
    (0.01, 0.01, 0.01, 1.0)
    """
    from scipy.spatial import cKDTree

    S = np.asarray(surface.vertices)
    d, _ = cKDTree(X).query(S)
    w = _vertex_areas(surface)
    W = float(w.sum()) or 1.0
    return {"distances": d, "areas": w, "max": float(d.max()), "mean": float(w @ d) / W,
            "rms": math.sqrt(float(w @ d**2) / W), "stray_fraction": float(w[d > stray_distance].sum()) / W}
