"""Limit-position and limit-tangent masks of Catmull-Clark at the vertices of a mesh (the limit weights read
through the scheme, :data:`ccproof.mesh.scheme.CATMARK`).

Interior vertex of valence k with edge neighbours e_j and face-diagonal neighbours d_j (counter-
clockwise, :meth:`QuadMesh.one_ring`):

* position (left eigenvector of eigenvalue 1; Halstead, Kass, DeRose 1993; Stam 1998):
  ``(k^2 V + 4 sum e_j + sum d_j) / (k (k + 5))``;
* tangents (left eigenvectors of the subdominant eigenvalue lam of docs/readings.md R2):
  ``t1 = sum_j A cos(2 pi j/k) e_j + (cos(2 pi j/k) + cos(2 pi (j+1)/k)) d_j`` and ``t2`` the same
  with sines, where ``A = 1 + c + sqrt((1 + c)(9 + c)) = 16 lam - 4`` and ``c = cos(2 pi/k)``;
  the normal is ``t1 x t2`` (it points to the side from which the faces are counter-clockwise).

Boundary vertex (the boundary is the cubic B-spline through the boundary vertices):

* position ``(e0 + 4 V + e1) / 6`` on the two boundary neighbours (any number of faces);
* for a *regular* boundary vertex (two faces, boundary neighbours e0, e2, interior neighbour e1,
  diagonals d0, d1) the tangent along the boundary is ``e0 - e2`` and the cross-boundary tangent
  is ``(d0 + 4 e1 + d1 - e0 - 4 V - e2) / 6`` (bicubic B-spline with the ghost row ``2 B - I``).
  Other boundary vertices have no closed-form mask here (their normal is NaN; the evaluation
  layer computes them from the exact surface).
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np

from ccproof.mesh.quadmesh import QuadMesh
from ccproof.mesh.scheme import CATMARK
from ccproof.mesh.subdivision import boundary_neighbours
from ccproof.valence import lam_from_c

__all__ = ["limit_positions", "limit_tangents", "limit_normals"]


def limit_positions(mesh: QuadMesh, vertices=None):
    """Exact limit positions of the vertices (masks in the module docstring).

    Parameters
    ----------
    mesh : QuadMesh
    vertices : ndarray, shape (n, 3), optional
        Control points to use instead of ``mesh.vertices`` (same connectivity).

    Returns
    -------
    ndarray, shape (n, 3)

    Examples
    --------
    >>> import numpy as np
    >>> V = np.array([[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1],
    ...               [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]], float)
    >>> F = [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]]
    >>> np.round(limit_positions(QuadMesh(V, F))[6], 12).tolist()      # cube corner: (9 V + 4*3 e + 3 d)/24
    [0.5, 0.5, 0.5]
    """
    V = mesh.vertices if vertices is None else np.asarray(vertices, dtype=np.float64)
    F = mesh.faces
    n = mesh.n_vertices
    org = F.reshape(-1)
    e = np.roll(F, -1, axis=1).reshape(-1)
    d = np.roll(F, -2, axis=1).reshape(-1)
    esum = np.zeros((n, 3))
    dsum = np.zeros((n, 3))
    np.add.at(esum, org, V[e])
    np.add.at(dsum, org, V[d])
    # integer numerators over a common denominator: one rounding, at the division
    unused = getattr(mesh, "is_unused_vertex", np.zeros(n, dtype=bool))
    val = np.where(unused, 4, mesh.valence)  # unused vertices (valence 0): NaN below
    ks = np.unique(val)
    table = np.array([_integer_weights(CATMARK.limit(int(k), Fraction(1))) for k in ks], dtype=np.float64)
    nV, ne, nd, den = table[np.searchsorted(ks, val)].T[:, :, None]
    with np.errstate(invalid="ignore"):
        L = (nV * V + ne * esum + nd * dsum) / den
    L[unused] = np.nan
    bv = mesh.is_boundary_vertex
    if bv.any():
        e0, e1 = boundary_neighbours(mesh)
        cV, ce, cden = _integer_weights(CATMARK.crease_limit(Fraction(1)))
        L[bv] = (cV * V[bv] + ce * (V[e0[bv]] + V[e1[bv]])) / cden
    return L


def _integer_weights(ws):
    """Exact weights as integer numerators and their common denominator (last)."""
    den = math.lcm(*(w.denominator for w in ws))
    return [int(w * den) for w in ws] + [den]


def limit_tangents(mesh: QuadMesh, vertices=None):
    """Limit tangent masks t1, t2 (module docstring), NaN at irregular boundary and unused vertices.

    Parameters
    ----------
    mesh : QuadMesh
    vertices : array_like, shape (n, 3), optional
        Positions to use instead of ``mesh.vertices`` (same topology).

    Returns
    -------
    t1, t2 : ndarray, shape (n, 3)
        Scaled as in the masks (only the plane they span and its orientation are meaningful).

    Notes
    -----
    Interior vertices: the eigen tangent masks of Halstead et al. 1993 with
    ``A = 1 + cos(2 pi / k) + sqrt((1 + cos(2 pi / k)) (9 + cos(2 pi / k)))`` on the edge neighbours and
    ``cos th_j + cos th_(j+1)`` on the diagonal ones; regular boundary vertices: ``e0 - e2`` and
    ``(d0 + 4 e1 + d1 - e0 - 4 V - e2) / 6`` (docs/evaluate.md "Method", item 4).

    Examples
    --------
    On the planar 2 x 2 grid: at the inner vertex 4 (valence 4, A = 4) the masks have length
    ``2 A + 4 = 12`` along the grid lines; at the boundary vertex 1 = (1, 0), ``e0 - e2 = (2, 0, 0)``
    and ``(6 (y = 1) - 0) / 6 = 1`` across; the corner vertex 0 (one face) is NaN:

    >>> import numpy as np
    >>> from ccproof.mesh.examples import grid
    >>> t1, t2 = limit_tangents(grid(2, 2))
    >>> (np.round(t1[4], 12) + 0.0).tolist(), (np.round(t2[4], 12) + 0.0).tolist()
    ([-12.0, 0.0, 0.0], [0.0, -12.0, 0.0])
    >>> t1[1].tolist(), t2[1].tolist(), bool(np.isnan(t1[0]).all())
    ([2.0, 0.0, 0.0], [0.0, 1.0, 0.0], True)
    """
    V = mesh.vertices if vertices is None else np.asarray(vertices, dtype=np.float64)
    F = mesh.faces
    n = mesh.n_vertices
    t1 = np.full((n, 3), np.nan)
    t2 = np.full((n, 3), np.nan)
    ptr, fan = mesh.fan_ptr, mesh.fan_corners
    cnt = mesh.face_count
    # position j of every corner in its vertex's fan
    j = np.arange(fan.size) - np.repeat(ptr[:-1], cnt)
    v = F.reshape(-1)[fan]
    f, i = fan // 4, fan % 4
    e = F[f, (i + 1) % 4]
    d = F[f, (i + 2) % 4]
    inner = ~mesh.is_boundary_vertex[v]
    k = mesh.valence[v].astype(np.float64)
    A = 16 * lam_from_c(np.cos(2 * np.pi / k), np.sqrt) - 4  # = 1 + c + sqrt((1 + c)(9 + c))
    th = 2 * np.pi * j / k
    th1 = 2 * np.pi * (j + 1) / k
    iv = ~mesh.is_boundary_vertex & ~getattr(mesh, "is_unused_vertex", np.zeros(n, dtype=bool))
    vi, Ve, Vd = v[inner], V[e[inner]], V[d[inner]]  # the interior corners only
    th, th1, A = th[inner], th1[inner], A[inner]
    for t, trig in ((t1, np.cos), (t2, np.sin)):
        c0 = trig(th)
        w_e = A * c0
        w_d = c0 + trig(th1)
        contrib = w_e[:, None] * Ve + w_d[:, None] * Vd
        # per vertex, the sum over its corners in their order (np.add.at's order: the same bits, 5x faster)
        acc = np.stack([np.bincount(vi, contrib[:, x], minlength=n) for x in range(3)], axis=1)
        t[iv] = acc[iv]
    rb = np.flatnonzero(mesh.is_boundary_vertex & (mesh.face_count == 2))
    if rb.size:
        c0 = fan[ptr[rb]]
        c1 = fan[ptr[rb] + 1]
        f0, i0, f1, i1 = c0 // 4, c0 % 4, c1 // 4, c1 % 4
        e0 = F[f0, (i0 + 1) % 4]
        e1 = F[f1, (i1 + 1) % 4]
        e2 = F[f1, (i1 + 3) % 4]
        d0 = F[f0, (i0 + 2) % 4]
        d1 = F[f1, (i1 + 2) % 4]
        t1[rb] = V[e0] - V[e2]
        t2[rb] = (V[d0] + 4 * V[e1] + V[d1] - V[e0] - 4 * V[rb] - V[e2]) / 6
    return t1, t2


def limit_normals(mesh: QuadMesh, vertices=None):
    """Unit limit normals ``t1 x t2 / |t1 x t2|`` (NaN at irregular boundary vertices).

    Returns
    -------
    ndarray, shape (n, 3)

    Examples
    --------
    >>> import numpy as np
    >>> V = np.array([[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1],
    ...               [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]], float)
    >>> F = [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]]
    >>> np.round(limit_normals(QuadMesh(V, F))[6] * np.sqrt(3), 12).tolist()
    [1.0, 1.0, 1.0]
    """
    t1, t2 = limit_tangents(mesh, vertices)
    nrm = np.cross(t1, t2)
    return nrm / np.linalg.norm(nrm, axis=1, keepdims=True)
