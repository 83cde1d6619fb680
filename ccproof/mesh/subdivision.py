"""One reference Catmull-Clark step of a quad mesh (bmz04 Fig. 1, docs/readings.md R1), vectorized.

The rules are those of :mod:`ccproof.mesh.rules` (the one rule implementation): this module only
assembles them over the whole mesh with numpy, taking every weight from the rule functions of
:mod:`ccproof.rule_weights` (:func:`~ccproof.rule_weights.face_point_weight`,
:func:`~ccproof.rule_weights.smooth_edge_weights`, :func:`~ccproof.rule_weights.sharp_edge_weight`,
:func:`~ccproof.rule_weights.smooth_vertex_weights` and :func:`~ccproof.rule_weights.crease_vertex_weights`)
evaluated in floats (the exact stencils of
:func:`~ccproof.mesh.rules.refine_complex` evaluate the same functions exactly;
tests/mesh/test_subdivision.py checks that the two operators agree). No creases; boundary as
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

from ccproof.mesh.quadmesh import QuadMesh
from ccproof.rule_weights import (
    crease_vertex_weights,
    face_point_weight,
    sharp_edge_weight,
    smooth_edge_weights,
    smooth_vertex_weights,
)

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


def _boundary_neighbours(mesh):
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
    return QuadMesh(subdivision_matrix(mesh) @ mesh.vertices, child_faces(mesh))


def subdivision_matrix(mesh):
    """The subdivision matrix S of one step: ``subdivide(mesh).vertices == S @ mesh.vertices``.

    Parameters
    ----------
    mesh : QuadMesh

    Returns
    -------
    scipy.sparse.csr_matrix, shape (n + E + m, n)
        Rows laid out as in the module docstring; every row sums to 1.

    Examples
    --------
    >>> import numpy as np
    >>> V = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]
    >>> S = subdivision_matrix(QuadMesh(V, [[0, 1, 2, 3]]))
    >>> S.shape, np.allclose(S.sum(axis=1), 1)
    ((9, 4), True)
    """
    F = mesh.faces
    n, E, m = mesh.n_vertices, mesh.n_edges, mesh.n_faces
    rows, cols, vals = [], [], []

    def add(r, c, w):
        r, c = np.broadcast_arrays(np.asarray(r), np.asarray(c))
        rows.append(r.reshape(-1))
        cols.append(c.reshape(-1))
        vals.append(np.broadcast_to(np.asarray(w, dtype=np.float64), r.shape).reshape(-1))

    one = 1.0  # the rule functions in floats (exact_one() would give the exact weights)
    wq = face_point_weight(4, one)
    # face points
    add(np.repeat(n + E + np.arange(m), 4), F.reshape(-1), wq)
    # edge points
    a, b = mesh.edges[:, 0], mesh.edges[:, 1]
    er = n + np.arange(E)
    bnd = mesh.is_boundary_edge
    half = sharp_edge_weight(one)
    add(er[bnd], a[bnd], half)
    add(er[bnd], b[bnd], half)
    it = ~bnd
    we_end, we_face = smooth_edge_weights(one)
    add(er[it], a[it], we_end)
    add(er[it], b[it], we_end)
    for s in range(2):  # the face point of each adjacent face, spelled out on its vertices
        add(np.repeat(er[it], 4), F[mesh.edge_faces[it, s]].reshape(-1), we_face * wq)
    # interior vertex points (smooth rule), assembled corner by corner
    org = F.reshape(-1)
    dst = np.roll(F, -1, axis=1).reshape(-1)
    inner = ~mesh.is_boundary_vertex
    k = np.maximum(mesh.valence.astype(np.int64), 1)  # (unused vertices: valence 0, weights unused)
    wv, we, wf = smooth_vertex_weights(k, one)
    iv = np.flatnonzero(inner)
    add(iv, iv, wv[iv])
    c = np.flatnonzero(inner[org])  # corners at interior vertices: one edge and one face each
    v = org[c]
    add(v, dst[c], we[v])
    add(np.repeat(v, 4), F[c // 4].reshape(-1), np.repeat(wf[v] * wq, 4))
    # boundary vertex points (crease rule along the boundary)
    bv = np.flatnonzero(mesh.is_boundary_vertex)
    if bv.size:
        e0, e1 = _boundary_neighbours(mesh)
        wc, wn = crease_vertex_weights(one)
        add(bv, bv, wc)
        add(bv, e0[bv], wn)
        add(bv, e1[bv], wn)
    import scipy.sparse as sp

    S = sp.coo_matrix(
        (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n + E + m, n)
    )
    return S.tocsr()
