"""The fast path of the Catmull-Clark step: one step of an untagged manifold polygon mesh, from its face points.

:func:`catmark_step` is the step of :func:`ccproof.mesh.step.catmark_operator` (``apply_csr(csr, X)``) for the
meshes it takes (None for the others): the same child faces and vertex numbering, the same rules read through
the scheme (:data:`ccproof.mesh.scheme.CATMARK`), the points evaluated from the face points (no operator
assembled): equal to the operator's to round-off, not bit for bit (tests/mesh/test_step.py bounds the
difference on the OpenSubdiv feature meshes). The evaluator's setup of untagged polygon meshes
(:mod:`ccproof.evaluate.tagged`) and :meth:`ccproof.evaluate.surface.LimitSurface.with_vertices` start from it:
``python scripts/bench_step.py`` measures it against the operator (assembly and product).
"""

from __future__ import annotations

import numpy as np

from ccproof.mesh.scheme import CATMARK

__all__ = ["catmark_step"]


def catmark_step(mesh):
    """One Catmull-Clark step of an untagged manifold polygon mesh, vectorized; None otherwise.

    The rules of :func:`ccproof.mesh.rules.refine_complex` for a mesh without tags, holes or
    non-default options (bmz04 Fig. 1, docs/readings.md R1; boundary edges infinitely sharp: edge
    midpoints and the crease rule ``(3/4) V + (1/8)(e0 + e1)`` at boundary vertices), in the layout of
    :meth:`ccproof.mesh.polymesh.PolyMesh.refine`: vertex points (n), edge points (E, edges numbered
    by first occurrence along the faces' corners), face points (m); child ``offsets[f] + i`` of face
    f is ``(v_i, edge point (v_i, v_i+1), face point, edge point (v_i-1, v_i))``. Evaluated from the
    face points (the float weights of :data:`~ccproof.mesh.scheme.CATMARK`), not as stencils of the old
    vertices: the values of :func:`ccproof.mesh.step.catmark_operator` to round-off (the module docstring), the
    same child faces and vertex numbering. The topology is the mesh's own (``mesh.halfedges``), not paired
    again.

    Parameters
    ----------
    mesh : PolyMesh

    Returns
    -------
    (X1, F1) or None
        ``X1`` (n + E + m, 3) float64, ``F1`` (sum of face sizes, 4) int64; None for a tagged mesh
        (creases, corners, holes, boundary mode "none", smooth triangle subdivision, a one-face
        boundary vertex under "edge_and_corner"), one with unused vertices, a non-manifold edge or a
        vertex with more than one boundary edge pair.
    """
    opts = mesh.options
    if (mesh.edge_sharpness or mesh.vertex_sharpness or np.asarray(mesh.is_hole).any()
            or opts.triangle_subdivision != "catmark" or opts.boundary == "none"):
        return None
    X = np.asarray(mesh.vertices, dtype=np.float64)
    he = mesh.halfedges  # the mesh's own topology: no pairing of the half-edges again
    idx, sizes, off = he.org, he.sizes, he.start
    n, m = X.shape[0], sizes.size
    face, prv = he.face_of, he.prv
    org, dst = idx, idx[he.nxt]
    if not he.edge_manifold:  # a directed edge twice (non-manifold or misoriented), a face holding an edge twice
        return None
    first = he.edge_halfedge  # the first half-edge of every edge (edges sorted by their vertices)
    E = first.size
    order = np.argsort(first, kind="stable")  # edges by first occurrence along the faces' corners
    rank = np.empty(E, dtype=np.int64)
    rank[order] = np.arange(E)
    he_edge = rank[he.edge_of]  # edge id of every half-edge (first-occurrence order)
    count = he.edge_face_count[order]
    valence = np.bincount(org, minlength=n)  # faces (outgoing half-edges) at every vertex
    if (valence == 0).any():
        return None
    bnd_h = count[he_edge] == 1  # boundary half-edges
    nb_out = np.bincount(org[bnd_h], minlength=n)
    nb_in = np.bincount(dst[bnd_h], minlength=n)
    if (nb_out > 1).any() or (nb_in != nb_out).any():
        return None
    if opts.boundary == "edge_and_corner" and ((nb_out > 0) & (valence == 1)).any():
        return None  # a one-face corner: sharp from level 1 on (a tagged level-1 mesh)
    one = 1.0
    fp = np.add.reduceat(X[idx], off, axis=0) / sizes[:, None] if m else np.zeros((0, 3))
    # edge points
    h1 = first[order]  # the first half-edge of every edge, in edge order
    h2 = he.twin[h1]  # the other one (-1 on the boundary)
    a, b = org[h1], dst[h1]
    vw, fw = CATMARK.edge_point(one)
    ep = 0.5 * (X[a] + X[b])
    inner = h2 >= 0
    ep[inner] = vw * (X[a[inner]] + X[b[inner]]) + fw * (fp[face[h1[inner]]] + fp[face[h2[inner]]])
    vp = _step_vertex_points(X, (org, dst, face), fp, valence, bnd_h, nb_out)
    X1 = np.concatenate([vp, ep, fp])
    F1 = np.stack([org, n + he_edge, n + E + face, n + he_edge[prv]], axis=1)
    return X1, F1


def _step_vertex_points(X, corners, fp, valence, bnd_h, nb_out):
    """The vertex points of :func:`catmark_step`: the smooth rule, the crease rule at the boundary vertices.
    ``corners`` = (origin, destination, face) of every half-edge, ``fp`` the face points, ``bnd_h`` the
    boundary half-edges, ``nb_out`` the boundary half-edges leaving every vertex."""
    org, dst, face = corners
    n, one = X.shape[0], 1.0
    vp = np.empty((n, 3))
    sum_e = np.stack([np.bincount(org, weights=X[dst, c], minlength=n) for c in range(3)], axis=1)
    sum_f = np.stack([np.bincount(org, weights=fp[face, c], minlength=n) for c in range(3)], axis=1)
    wv, we, wf = CATMARK.vertex_point(valence, one)
    vp[:] = wv[:, None] * X + we[:, None] * sum_e + wf[:, None] * sum_f
    bv = np.flatnonzero(nb_out > 0)
    if bv.size:
        cw, ce = CATMARK.crease_vertex(one)
        bn = np.zeros((n, 3))
        np.add.at(bn, org[bnd_h], X[dst[bnd_h]])
        np.add.at(bn, dst[bnd_h], X[org[bnd_h]])
        vp[bv] = cw * X[bv] + ce * bn[bv]
    return vp
