"""Exact limit evaluation on tagged polygon meshes (creases, corners, holes, boundary modes, n-gons).

The patch table of a :class:`~ccproof.mesh.polymesh.PolyMesh` is built by the builder of the all-quad
meshes (:class:`ccproof.evaluate.factory.Builder`: same classification, arrays, locator and
kernels), from the tagged rules of :mod:`ccproof.mesh.rules`; :func:`build_tagged` classifies, the one
evaluator :class:`ccproof.evaluate.surface.LimitSurface` holds the table and evaluates:

1. One global Catmull-Clark step (n-gons become quads; ``TRI_SUB_SMOOTH`` and the
   ``EDGE_AND_CORNER`` corners act here); on an untagged mesh vectorized
   (:func:`ccproof.mesh.step_fast.catmark_step`). A quad's ptex face is split into its four level-1
   children; sub-face k of an n-gon *is* level-1 child k (same (s, t)).
2. Semi-sharp phase: while an edge at a vertex of the face or the vertex itself has a semi-sharp
   sharpness (0 < s < 10), the face's neighbourhood is refined exactly and locally
   (``CREASE_UNIFORM``: the one-ring, all faces sharing a vertex with the face; ``CREASE_CHAIKIN``:
   the two-ring, because the child sharpness at a vertex depends on all its edges). After
   ceil(s) levels every sharpness is 0 or infinite.
3. Every face is then a regular bicubic B-spline patch (each corner: smooth of valence 4; crease
   rule with two faces on the face's side of the crease; corner rule with one face; rows across
   sharp edges completed by ghost points ``2 B - I``, which reproduce the crease rules), or has one
   irregular corner whose tagged one-ring is stationary (the child's one-ring at that corner has the
   same tagged key: extraordinary, dart, boundary or crease vertex of any valence, corner), evaluated
   by exact powers of its local subdivision matrix (:func:`ccproof.evaluate.local.corner_scheme`,
   the method of docs/evaluate.md), or it is subdivided once more (at most ``MAX_DEPTH`` times).

Exact data (stencils of a refinement, regular nets, corner schemes: :mod:`ccproof.evaluate.local`,
shared with the all-quad evaluator) are cached per tagged configuration key, shared by all faces of
the same configuration.
"""

from __future__ import annotations

import math

import numpy as np

from ccproof.evaluate.factory import Builder, Jobs
from ccproof.evaluate.frames import child_frame, compose, domain
from ccproof.evaluate.halfedge_views import TaggedHalfEdges
from ccproof.mesh.csr import pack_csr
from ccproof.mesh.halfedges import HalfEdges
from ccproof.mesh.polymesh import PolyMesh
from ccproof.mesh.step_fast import catmark_step

__all__ = ["build_tagged", "vertex_corners"]


def build_tagged(mesh: PolyMesh, progress=None, keep=None):
    """Classify every ptex face of a tagged polygon mesh (steps 1-3 of the module docstring).

    Parameters
    ----------
    mesh : PolyMesh
        Polygons with OpenSubdiv's tags (creases, corners, holes, boundary options); a non-manifold
        mesh is classified on its split (:attr:`PolyMesh.manifold`: same faces and ptex faces).
    progress : bool, optional
        As in :class:`ccproof.evaluate.surface.LimitSurface`.
    keep : dict, optional
        Receives, where the build runs the tagged level-1 step (a tagged mesh that is not all quads),
        that step under ``"step"`` (:class:`~ccproof.mesh.csr.PackedCSR`, the columns the vertices of
        :attr:`PolyMesh.manifold`): what :meth:`LimitSurface.with_vertices
        <ccproof.evaluate.surface.LimitSurface.with_vertices>` re-applies to moved vertices.

    Returns
    -------
    builder : Builder
        Every job classified (the patch table is ``builder.table(top, hole)``).
    top : ndarray of int, shape (n_ptex, 4)
        The job of each quadrant of every ptex face.
    hole : ndarray of bool, shape (n_ptex,)
        The ptex faces on holes (evaluation refuses them).
    ptex_face : ndarray of int64, shape (n_ptex,)
        The base face of every ptex face.

    Examples
    --------
    >>> from ccproof.mesh.examples import cube
    >>> c = cube()
    >>> b, top, hole, ptex_face = build_tagged(PolyMesh(c.vertices, c.faces.tolist(), holes=[5]))
    >>> top.shape, hole.tolist(), ptex_face.tolist()
    ((6, 4), [False, False, False, False, False, True], [0, 1, 2, 3, 4, 5])
    """
    mesh = mesh.manifold
    b = Builder(2 if mesh.options.crease_method == "chaikin" else 1, what="ptex face", progress=progress)
    if mesh.is_all_quads:
        top, ptex_face = _classify_base_quads(mesh, b)
        return b, top, mesh.is_hole[ptex_face], ptex_face
    step = catmark_step(mesh)  # untagged: vectorized, and the level-1 mesh as half-edge arrays
    if step is not None:
        X = step[0]
        he = HalfEdges.from_quads(step[1], X.shape[0], mesh.options, edges=False)
    else:  # tagged: the level-1 mesh's own topology, with its tags (no Python complex of the mesh)
        m1, csr = mesh.refine(operator="csr")
        if keep is not None:  # the step, for with_vertices (small: docs/evaluate.md)
            keep["step"] = pack_csr(csr)
        del csr
        he = TaggedHalfEdges.of(m1.halfedges)
        X = np.asarray(m1.vertices)
    top, ptex_face, jobs = _level1_jobs(mesh)
    b.classify(he, X, jobs)
    del he, step, jobs  # before the table's float data
    return b, top, mesh.is_hole[ptex_face], ptex_face


_IDENT = ((0.0, 0.0), (1.0, 0.0), (0.0, 1.0))


def _classify_base_quads(mesh, b):
    """Classify the all-quad manifold ``mesh`` on ``b`` from the base mesh itself; returns (top, ptex_face)."""
    # no global step needed: start on the base mesh, with the one level-0-only rule that
    # can act on quads (EDGE_AND_CORNER sharpens one-face boundary vertices) made explicit
    he = mesh.halfedges
    if mesh.edge_sharpness or mesh.vertex_sharpness or mesh.options.boundary == "edge_and_corner":
        vv = he.vertex_tags().copy()
        if mesh.options.boundary == "edge_and_corner":
            vv[(he.face_count == 1) & he.is_boundary_vertex] = math.inf
        if mesh.edge_sharpness or vv.any():  # tagged: the tags enter the rings' keys
            he = TaggedHalfEdges.of(he.with_tags(mesh.edge_sharpness, vertex_values=vv))
    ptex_face = np.empty(mesh.n_ptex, dtype=np.int64)
    ptex_face[:] = np.arange(mesh.n_faces)
    m = mesh.n_faces
    b.classify(he, np.asarray(mesh.vertices), Jobs(np.arange(m), np.zeros(m, np.int64), np.arange(m), [_IDENT]))
    top = np.repeat(np.arange(mesh.n_ptex, dtype=np.int64)[:, None], 4, axis=1)
    return top, ptex_face


def _level1_jobs(mesh):
    """(top, ptex_face, Jobs) of the level-1 children of the manifold ``mesh``: sub-face i of an n-gon is
    level-1 child i (same (s, t)), its own ptex face; a quad is one ptex face whose four level-1 children
    are its quadrants (frames: the child frames)."""
    frames = [_IDENT]
    quarter_q = []
    for i in range(4):
        cf = compose(_IDENT, child_frame(i))
        cu, cv, _ = domain(cf)
        frames.append(cf)
        quarter_q.append(int(cu > 0) + 2 * int(cv > 0))
    sizes = np.asarray(mesh.sizes, dtype=np.int64)
    nf = sizes.size
    face = np.repeat(np.arange(nf), sizes)  # per level-1 child: its base face
    corner = np.arange(face.size) - np.repeat(np.asarray(mesh.offsets, dtype=np.int64)[:nf], sizes)
    is_quad = sizes[face] == 4
    ptex_start = np.asarray(mesh.ptex_start, dtype=np.int64)[:nf]
    ptex = np.where(is_quad, ptex_start[face], ptex_start[face] + corner)
    g = np.asarray(mesh.offsets, dtype=np.int64)[:nf][face] + corner
    fid = np.where(is_quad, 1 + corner, 0)
    ptex_face = np.empty(mesh.n_ptex, dtype=np.int64)
    ptex_face[ptex] = face
    top = np.empty((mesh.n_ptex, 4), dtype=np.int32 if len(mesh.indices) < 2**31 else np.int64)
    jid = np.arange(face.size)
    nq = np.flatnonzero(~is_quad)
    top[ptex[nq]] = jid[nq, None]
    qd = np.flatnonzero(is_quad)
    top[ptex[qd], np.asarray(quarter_q)[corner[qd]]] = jid[qd]
    return top, ptex_face, Jobs(g, fid, ptex, frames)


def vertex_corners(mesh: PolyMesh):
    """One ptex corner (face, s, t) per corner of every base face, and its vertex.

    Returns
    -------
    face : ndarray of int64, shape (c,)
        Ptex face (a quad's own, or sub-face k of an n-gon at its corner k).
    s, t : ndarray, shape (c,)
        The corner in that ptex face.
    vertex : ndarray of int64, shape (c,)

    Examples
    --------
    >>> m = PolyMesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])
    >>> [a.tolist() for a in vertex_corners(m)]
    [[0, 1, 2], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0, 1, 2]]
    """
    from ccproof.evaluate.local import CORNERS

    sizes = np.asarray(mesh.sizes, dtype=np.int64)
    face = np.repeat(np.arange(sizes.size), sizes)
    corner = np.arange(face.size) - np.asarray(mesh.offsets, dtype=np.int64)[face]
    quad = sizes[face] == 4
    st = np.asarray(CORNERS, dtype=np.float64)[np.where(quad, corner, 0)]
    ptex = np.asarray(mesh.ptex_start, dtype=np.int64)[face] + np.where(quad, 0, corner)
    return (ptex, np.where(quad, st[:, 0], 0.0), np.where(quad, st[:, 1], 0.0),
            np.asarray(mesh.indices, dtype=np.int64).copy())
