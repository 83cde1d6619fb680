"""Exact limit evaluation on tagged polygon meshes (creases, corners, holes, boundary modes, n-gons).

The patch table of a :class:`~ccproof.mesh.polymesh.PolyMesh` is built by the builder of the all-quad
evaluator (:class:`ccproof.evaluate.surface._Builder`: same classification, arrays, locator and
kernels), from the tagged rules of :mod:`ccproof.mesh.rules`:

1. One global Catmull-Clark step (n-gons become quads; ``TRI_SUB_SMOOTH`` and the
   ``EDGE_AND_CORNER`` corners act here); on an untagged mesh vectorized
   (:func:`ccproof.evaluate._table.catmark_step`). A quad's ptex face is split into its four level-1
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

from ccproof.errors import CCProofError
from ccproof.evaluate._table import QuadHalfEdges, _Builder, _child_frame, _compose, _domain, _Jobs, catmark_step
from ccproof.evaluate.surface import LimitSurface
from ccproof.mesh.polymesh import PolyMesh
from ccproof.mesh.rules import Complex

__all__ = ["TaggedLimitSurface"]


class TaggedLimitSurface(LimitSurface):
    """Exact evaluator of the limit surface of a tagged polygon mesh, by ptex face.

    Build it with :func:`ccproof.limit_surface`. ``evaluate(ptex, s, t, derivatives)``
    as :meth:`LimitSurface.evaluate`, with ``face`` the ptex face index (OpenSubdiv's
    ``Far::PtexIndices``, :meth:`PolyMesh.ptex_of`) and derivatives with respect to its (s, t).
    Points on hole faces raise an error naming the point and the face.

    Parameters
    ----------
    mesh : PolyMesh
        Polygons with OpenSubdiv's tags (creases, corners, holes, boundary options).

    Notes
    -----
    OpenSubdiv's Sdc rules in exact arithmetic (:mod:`ccproof.mesh.rules`), then the method of
    :class:`LimitSurface`; docs/evaluate.md "Tagged polygon meshes (OpenSubdiv's features)".

    Examples
    --------
    An infinitely sharp corner on vertex 0 of the cube is interpolated; the untagged corners keep
    the smooth limit point (-1/2, -1/2, 1/2) of vertex 4 = (-1, -1, 1):

    >>> from ccproof.mesh import PolyMesh
    >>> from ccproof.mesh.examples import cube
    >>> c = cube()
    >>> S = TaggedLimitSurface(PolyMesh(c.vertices, c.faces.tolist(), corners={0: 10}))
    >>> S.evaluate([0, 1], [0.0, 0.0], [0.0, 0.0])["P"].round(12).tolist()
    [[-1.0, -1.0, -1.0], [-0.5, -0.5, 0.5]]
    """

    def __init__(self, mesh: PolyMesh, *, progress=None):
        self.mesh = mesh
        # a non-manifold mesh is evaluated on its split (PolyMesh.manifold): same faces and ptex faces
        mesh = mesh.manifold
        b = _Builder(2 if mesh.options.crease_method == "chaikin" else 1, what="ptex face", progress=progress)
        ident = ((0.0, 0.0), (1.0, 0.0), (0.0, 1.0))
        P = mesh.n_ptex
        self._ptex_face = np.empty(P, dtype=np.int64)
        if mesh.is_all_quads:
            # no global step needed: start on the base mesh, with the one level-0-only rule that
            # can act on quads (EDGE_AND_CORNER sharpens one-face boundary vertices) made explicit
            cx = mesh.complex()
            if mesh.options.boundary == "edge_and_corner":
                vs = dict(cx.vertex_sharpness)
                for v in range(mesh.n_vertices):
                    fan, closed = cx.fan(v)
                    if fan is not None and not closed and len(fan) == 1:
                        vs[v] = math.inf
                cx = Complex(cx.faces, cx.edge_sharpness, vs, cx.options, level=1, n_vertices=cx.n_vertices)
            if not cx.edge_sharpness and not cx.vertex_sharpness:
                cx = QuadHalfEdges(cx.faces, cx.n_vertices, cx.options)
            self._ptex_face[:] = np.arange(mesh.n_faces)
            m = mesh.n_faces
            b.classify(cx, np.asarray(mesh.vertices), _Jobs(np.arange(m), np.zeros(m, np.int64), np.arange(m), [ident]))
            top = np.repeat(np.arange(P, dtype=np.int64)[:, None], 4, axis=1)
            self._hole_ptex = mesh.is_hole[self._ptex_face]
            self._finish(b, top, self._hole_ptex, keep_rings=False)
            return
        step = catmark_step(mesh)  # untagged: vectorized, and the level-1 complex as arrays
        if step is not None:
            X = step[0]
            cx = QuadHalfEdges(step[1], X.shape[0], mesh.options)
        else:
            m1, _ = mesh.refine()
            cx = m1.complex()
            X = np.asarray(m1.vertices)
        # jobs: sub-face i of an n-gon is level-1 child i (same (s, t)), its own ptex face; a quad is
        # one ptex face whose four level-1 children are its quadrants (frames: the child frames)
        frames = [ident]
        quarter_q = []
        for i in range(4):
            cf = _compose(ident, _child_frame(i))
            cu, cv, _ = _domain(cf)
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
        self._ptex_face[ptex] = face
        top = np.empty((P, 4), dtype=np.int32 if len(mesh.indices) < 2**31 else np.int64)
        jid = np.arange(face.size)
        nq = np.flatnonzero(~is_quad)
        top[ptex[nq]] = jid[nq, None]
        qd = np.flatnonzero(is_quad)
        top[ptex[qd], np.asarray(quarter_q)[corner[qd]]] = jid[qd]
        b.classify(cx, X, _Jobs(g, fid, ptex, frames))
        del cx, step, g, fid, ptex, face, corner, is_quad, jid  # before the table's float data
        self._hole_ptex = mesh.is_hole[self._ptex_face]
        self._finish(b, top, self._hole_ptex, keep_rings=False)

    @property
    def n_faces(self):
        """Number of ptex faces (the valid ``face`` ids)."""
        return self.mesh.n_ptex

    def _refused_faces(self):
        return self._hole_ptex

    def _check_values(self, f, u, v):
        super()._check_values(f, u, v)
        if self._hole_ptex.any():
            bad = np.flatnonzero(self._hole_ptex[f])
            if bad.size:
                i = int(bad[0])
                raise CCProofError(
                    f"point {i}: ptex face {int(f[i])} (face {int(self._ptex_face[f[i]])}) is a hole"
                )
        return f, u, v

    def _vertex_corners(self):
        """One ptex corner (face, s, t) per corner of every base face, and its vertex."""
        from ccproof.evaluate.local import CORNERS

        mesh = self.mesh
        faces, us, vs, verts = [], [], [], []
        for f, p in enumerate(mesh.polygons):
            for i, v in enumerate(p):
                if len(p) == 4:
                    faces.append(int(mesh.ptex_start[f]))
                    us.append(float(CORNERS[i][0]))
                    vs.append(float(CORNERS[i][1]))
                else:
                    faces.append(int(mesh.ptex_start[f]) + i)
                    us.append(0.0)
                    vs.append(0.0)
                verts.append(v)
        return np.array(faces, dtype=np.int64), np.array(us), np.array(vs), np.array(verts, dtype=np.int64)

    def vertex_limits(self):
        """Limit positions of the base vertices (shape (n_vertices, 3)), NaN at unused vertices.

        Evaluated at the ptex corner (0, 0) of a sub-face at the vertex, or at the quad corner
        (hole faces included: holes do not change the surface of the other faces).
        """
        out = np.full((self.mesh.n_vertices, 3), np.nan)
        f, u, v, verts = self._vertex_corners()
        r = {"P": np.empty((f.size, 3))}
        self._eval_chunk(f, u, v, 0, r)
        out[verts] = r["P"]
        return out

    def vertex_normals(self):
        """Unit limit normals of the base vertices (shape (n_vertices, 3)), see :meth:`normals`.

        Each vertex takes the normal of its first face corner that is not on a hole; NaN where the
        tangent plane is not determined (see :meth:`normals`) or the vertex has only hole faces.
        """
        out = np.full((self.mesh.n_vertices, 3), np.nan)
        f, u, v, verts = self._vertex_corners()
        keep = ~self._hole_ptex[f]
        f, u, v, verts = f[keep][::-1], u[keep][::-1], v[keep][::-1], verts[keep][::-1]
        out[verts] = self.normals(f, u, v)  # reversed: the first corner of a vertex is written last
        return out
