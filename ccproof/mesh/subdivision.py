"""One Catmull-Clark step of a quad mesh (bmz04 Fig. 1, docs/readings.md R1), vectorized.

The operator is :func:`ccproof.mesh.step.catmark_operator` (the one vectorized step, with the rules of
:mod:`ccproof.rule_weights`; every weight correctly rounded from its exact value) without tags, in the
edge numbering of the :class:`QuadMesh` (tests/mesh/test_step.py checks it against the exact stencils of
:func:`~ccproof.mesh.rules.refine_complex`, tests/mesh/test_subdivision.py against pygel3d). No creases; boundary as
OpenSubdiv ``VTX_BOUNDARY_EDGE_ONLY`` (every boundary edge is an infinitely sharp crease, no vertex
is a corner):

* face point: the mean of the four vertices of the face;
* interior edge point: the mean of the two endpoints and the two adjacent face points;
* interior vertex of valence k: ``((k - 2) V + sum e_j / k + sum f_j / k) / k`` (e_j the edge
  neighbours, f_j the new face points); equivalently weights ``1 - 7/(4k)`` on V, ``3/(2k^2)`` on
  every edge neighbour and ``1/(4k^2)`` on every face-diagonal neighbour (bmz04: beta = 3/(2k),
  gamma = 1/(4k));
* boundary edge point: the midpoint of the edge;
* boundary vertex (any number of faces): the crease rule ``(e0 + 6 V + e1) / 8`` on its two
  boundary neighbours e0, e1 (the cubic B-spline curve rule).

Layout of the refined mesh (``n`` vertices, ``E`` edges, ``m`` faces before the step): new vertex
``v`` (``v < n``) is the vertex point of old vertex ``v``; ``n + e`` is the edge point of edge ``e``
(``mesh.edges[e]``); ``n + E + f`` is the face point of face ``f``. Child ``4 f + i`` of face ``f``
is ``(v_i', e_{i,i+1}, f', e_{i-1,i})``: it covers the quarter of face ``f`` at corner ``i``, and its
own corner 0 is the vertex point of corner ``i`` (its parameter is the parent's, rotated by ``i``
quarter turns and scaled by 1/2).
"""

from __future__ import annotations

import numpy as np

from ccproof.mesh.halfedges import HalfEdges
from ccproof.mesh.quadmesh import QuadMesh

__all__ = ["subdivide", "subdivision_matrix", "child_faces"]


def child_faces(mesh):
    """Faces of the refined mesh, child ``4 f + i`` at corner ``i`` of face ``f``.

    Parameters
    ----------
    mesh : QuadMesh
        n vertices, E edges, m faces.

    Returns
    -------
    ndarray of int64, shape (4 m, 4)
        Child ``4 f + i`` is ``(vertex point of corner i, edge point of edge (i, i+1), face point
        of f, edge point of edge (i-1, i))``; new vertices are numbered vertex points ``0..n-1``,
        edge points ``n..n+E-1`` (order of ``mesh.edges``), face points ``n+E..n+E+m-1``
        (docs/evaluate.md "Conventions"; bmz04 Fig. 1).

    Examples
    --------
    >>> import numpy as np
    >>> m = QuadMesh([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], [[0, 1, 2, 3]])
    >>> child_faces(m)[0].tolist()   # vertex 0, edge (0,1), face point, edge (3,0)
    [0, 4, 8, 5]
    """
    F = mesh.faces
    n, E, m = mesh.n_vertices, mesh.n_edges, mesh.n_faces
    eh = (n + mesh.edge_of_halfedge).reshape(m, 4)  # edge point of half-edge (f, i) -> (f, i+1)
    fp = n + E + np.arange(m)
    out = np.empty((m, 4, 4), dtype=np.int64)
    for i in range(4):
        out[:, i, 0] = F[:, i]
        out[:, i, 1] = eh[:, i]
        out[:, i, 2] = fp
        out[:, i, 3] = eh[:, (i + 3) % 4]
    return out.reshape(4 * m, 4)


def boundary_neighbours(mesh):
    """For every boundary vertex its two boundary neighbours (e0 after it, e1 before it)."""
    F = mesh.faces
    org = F.reshape(-1)
    dst = np.roll(F, -1, axis=1).reshape(-1)
    bh = np.flatnonzero(mesh.twin < 0)
    n = mesh.n_vertices
    e0 = np.full(n, -1, dtype=np.int64)
    e1 = np.full(n, -1, dtype=np.int64)
    e0[org[bh]] = dst[bh]
    e1[dst[bh]] = org[bh]
    return e0, e1


def subdivide(mesh):
    """One Catmull-Clark step: ``subdivision_matrix(mesh) @ mesh.vertices`` on the child faces.

    Parameters
    ----------
    mesh : QuadMesh
        ``n`` vertices, ``E`` edges, ``m`` faces.

    Returns
    -------
    QuadMesh
        ``n + E + m`` vertices and ``4 m`` faces, laid out as in the module docstring.

    Examples
    --------
    >>> import numpy as np
    >>> V = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]
    >>> m1 = subdivide(QuadMesh(V, [[0, 1, 2, 3]]))
    >>> m1.n_vertices, m1.n_faces
    (9, 4)
    >>> m1.vertices[0].tolist(), m1.vertices[8].tolist()   # corner: (e0 + 6 V + e1)/8; face point
    ([0.125, 0.125, 0.0], [0.5, 0.5, 0.0])
    """
    he = HalfEdges.refined(mesh.halfedges, edge_of_halfedge=mesh.edge_of_halfedge)  # derived, not paired again
    return QuadMesh(subdivision_matrix(mesh) @ mesh.vertices, child_faces(mesh), _halfedges=he)


def subdivision_matrix(mesh):
    """The subdivision matrix S of one step: ``subdivide(mesh).vertices == S @ mesh.vertices``.

    Parameters
    ----------
    mesh : QuadMesh

    Returns
    -------
    scipy.sparse.csr_matrix, shape (n + E + m, n)
        Rows laid out as in the module docstring; every row sums to 1 but an unused vertex's (empty).

    Examples
    --------
    >>> import numpy as np
    >>> V = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]
    >>> S = subdivision_matrix(QuadMesh(V, [[0, 1, 2, 3]]))
    >>> S.shape, np.allclose(S.sum(axis=1), 1)
    ((9, 4), True)
    """
    from ccproof.mesh.step import catmark_operator

    m = mesh.n_faces
    return catmark_operator(mesh.n_vertices, mesh.faces.reshape(-1), np.full(m, 4, dtype=np.int64),
                            halfedges=mesh.halfedges, edge_of_halfedge=mesh.edge_of_halfedge).S
