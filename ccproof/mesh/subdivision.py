"""One reference Catmull-Clark step (bmz04 Fig. 1, docs/readings.md R1) with the standard boundary rules.

Rules (no creases; boundary as OpenSubdiv ``VTX_BOUNDARY_EDGE_ONLY``: every boundary edge is an
infinitely sharp crease, no vertex is a corner):

* face point: the mean of the four vertices of the face;
* interior edge point: the mean of the two endpoints and the two adjacent face points;
* interior vertex of valence k: ``(F + 2 R + (k - 3) V) / k`` with F the mean of the k adjacent new
  face points and R the mean of the k midpoints of the adjacent edges; equivalently weights
  ``1 - 7/(4k)`` on V, ``beta/k = 3/(2k^2)`` on every edge neighbour and ``gamma/k = 1/(4k^2)`` on
  every face-diagonal neighbour (bmz04: beta = 3/(2k), gamma = 1/(4k));
* boundary edge point: the midpoint of the edge;
* boundary vertex (any number of faces): the cubic B-spline curve rule ``(e0 + 6 V + e1) / 8`` on
  its two boundary neighbours e0, e1.

Layout of the refined mesh (``n`` vertices, ``E`` edges, ``m`` faces before the step): new vertex
``v`` (``v < n``) is the vertex point of old vertex ``v``; ``n + e`` is the edge point of edge ``e``
(``mesh.edges[e]``); ``n + E + f`` is the face point of face ``f``. Child ``4 f + i`` of face ``f``
is ``(v_i', e_{i,i+1}, f', e_{i-1,i})``: it covers the quarter of face ``f`` at corner ``i``, and its
own corner 0 is the vertex point of corner ``i`` (its parameter is the parent's, rotated by ``i``
quarter turns and scaled by 1/2).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ccproof.mesh.quadmesh import QuadMesh

__all__ = ["subdivide", "subdivision_matrix", "child_faces"]


def child_faces(mesh):
    """Faces of the refined mesh, int (4 m, 4), child ``4 f + i`` at corner ``i`` of face ``f``.

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
    """One Catmull-Clark step computed directly from the rules (R1 and the boundary rules).

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
    V, F = mesh.vertices, mesh.faces
    n = mesh.n_vertices
    fp = V[F].mean(axis=1)
    a, b = mesh.edges[:, 0], mesh.edges[:, 1]
    ef = mesh.edge_faces
    bnd = mesh.is_boundary_edge
    ep = np.empty((mesh.n_edges, 3))
    ep[bnd] = 0.5 * (V[a[bnd]] + V[b[bnd]])
    it = ~bnd
    ep[it] = 0.25 * (V[a[it]] + V[b[it]] + fp[ef[it, 0]] + fp[ef[it, 1]])
    # interior vertices: (F + 2R + (k-3) V)/k
    org = F.reshape(-1)
    dst = np.roll(F, -1, axis=1).reshape(-1)
    k = mesh.valence.astype(np.float64)
    Fsum = np.zeros((n, 3))
    np.add.at(Fsum, org, np.repeat(fp, 4, axis=0))
    Rsum = np.zeros((n, 3))
    np.add.at(Rsum, org, 0.5 * (V[org] + V[dst]))  # each interior edge at v once (outgoing half-edge)
    vp = (Fsum / k[:, None] + 2 * Rsum / k[:, None] + (k - 3)[:, None] * V) / k[:, None]
    bv = mesh.is_boundary_vertex
    if bv.any():
        e0, e1 = _boundary_neighbours(mesh)
        vp[bv] = (V[e0[bv]] + 6 * V[bv] + V[e1[bv]]) / 8
    return QuadMesh(np.concatenate([vp, ep, fp]), child_faces(mesh))


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

    # face points
    add(np.repeat(n + E + np.arange(m), 4), F.reshape(-1), 0.25)
    # edge points
    a, b = mesh.edges[:, 0], mesh.edges[:, 1]
    er = n + np.arange(E)
    bnd = mesh.is_boundary_edge
    add(er[bnd], a[bnd], 0.5)
    add(er[bnd], b[bnd], 0.5)
    it = ~bnd
    add(er[it], a[it], 0.25)
    add(er[it], b[it], 0.25)
    for s in range(2):
        add(np.repeat(er[it], 4), F[mesh.edge_faces[it, s]].reshape(-1), 1.0 / 16)
    # interior vertex points, assembled corner by corner
    org = F.reshape(-1)
    dst = np.roll(F, -1, axis=1).reshape(-1)
    k = mesh.valence.astype(np.float64)
    inner = ~mesh.is_boundary_vertex
    iv = np.flatnonzero(inner)
    add(iv, iv, (k[iv] - 3) / k[iv])
    c = np.flatnonzero(inner[org])  # corners at interior vertices
    v = org[c]
    kk = k[v]
    add(np.repeat(v, 4), F[c // 4].reshape(-1), np.repeat(1.0 / (4 * kk * kk), 4))  # F / k
    add(v, v, 1.0 / (kk * kk))  # 2 R / k: (V + e)/2 per edge, twice, over k^2
    add(v, dst[c], 1.0 / (kk * kk))
    # boundary vertex points
    bv = np.flatnonzero(mesh.is_boundary_vertex)
    if bv.size:
        e0, e1 = _boundary_neighbours(mesh)
        add(bv, bv, 0.75)
        add(bv, e0[bv], 0.125)
        add(bv, e1[bv], 0.125)
    S = sp.coo_matrix(
        (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n + E + m, n)
    )
    return S.tocsr()
