"""Validated polygon meshes with OpenSubdiv's tags (creases, corners, holes, boundary modes) and ptex faces.

A :class:`PolyMesh` holds any manifold, consistently oriented polygon mesh (triangles, quads,
n-gons) with edge sharpness, vertex sharpness, hole faces and the Sdc :class:`~ccproof.mesh.rules.Options`.

Ptex faces (OpenSubdiv ``Far::PtexIndices``): faces are numbered in order; a quad is one ptex face,
its corner k at (s, t) = (0,0), (1,0), (1,1), (0,1); a face with n != 4 vertices is n consecutive
ptex faces, sub-face k being the quad (v_k, mid(v_k, v_k+1), centre, mid(v_k-1, v_k)) of the first
Catmull-Clark step: (0,0) = v_k, (1,0) = the edge point of (v_k, v_k+1), (1,1) = the face point,
(0,1) = the edge point of (v_k-1, v_k). :meth:`PolyMesh.ptex_of` and :meth:`PolyMesh.face_of_ptex`
are the mapping (face, corner) <-> ptex index.

Checks (:class:`~ccproof.errors.MeshError` naming the element otherwise): faces with >= 3 distinct
vertex indices in range, finite coordinates, every edge in one or two faces traversed in opposite
directions, the faces around every vertex a single fan, crease tags on existing edges, sharpness
finite or infinite but not negative and not NaN, hole indices in range.
"""

from __future__ import annotations

import math

import numpy as np
import scipy.sparse as sp

from ccproof.errors import MeshError
from ccproof.mesh.quadmesh import _pair_halfedges
from ccproof.mesh.rules import INFINITE, Complex, Options, refine_complex, to_float

__all__ = ["PolyMesh"]


def _sharp_value(x, what):
    try:
        s = float(x)
    except (TypeError, ValueError):
        raise MeshError(f"{what}: sharpness {x!r} is not a number") from None
    if math.isnan(s):
        raise MeshError(f"{what}: sharpness is NaN")
    if s < 0:
        raise MeshError(f"{what}: negative sharpness {s!r}")
    if s >= INFINITE:
        return math.inf
    return float(np.float32(s))  # OpenSubdiv stores sharpness as float32


class PolyMesh:
    """A manifold polygon mesh with Sdc tags (OpenSubdiv's ``Far::TopologyDescriptor``).

    Parameters
    ----------
    vertices : array_like, shape (n, 3)
    faces : sequence of sequence of int, or (indices, offsets)
        Either a list of vertex lists (counter-clockwise), or the flat ``indices`` (int, (sum of
        sizes,)) with ``offsets`` (int, (m + 1,), ``offsets[0] = 0``) or per-face ``sizes`` (m,).
    creases : array_like, optional
        Either ``(edges, sharpness)`` with edges int (c, 2) and sharpness float (c,) or scalar,
        or a dict ``{(a, b): s}``. ``s >= 10`` is infinitely sharp.
    corners : optional
        ``(vertices, sharpness)`` or dict ``{v: s}``.
    holes : sequence of int, optional
        Faces tagged as holes.
    options : Options or dict, optional
        ``boundary`` ('edge_only' | 'edge_and_corner' | 'none'), ``crease_method``
        ('uniform' | 'chaikin'), ``triangle_subdivision`` ('catmark' | 'smooth').

    Examples
    --------
    >>> m = PolyMesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])
    >>> m.n_ptex, m.ptex_of(0, 2), m.face_of_ptex(1)
    (3, 2, (0, 1))
    >>> PolyMesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]], creases=([[0, 2]], [-1]))
    Traceback (most recent call last):
    ...
    ccproof.errors.MeshError: crease on edge (0, 2): negative sharpness -1.0
    """

    def __init__(self, vertices, faces, *, creases=None, corners=None, holes=None, options=None, sizes=None):
        V = np.array(vertices, dtype=np.float64)
        if V.ndim != 2 or V.shape[1] != 3:
            raise MeshError(f"vertices must have shape (n, 3), got {V.shape}")
        bad = np.flatnonzero(~np.isfinite(V).all(axis=1))
        if bad.size:
            raise MeshError(f"vertex {int(bad[0])} has a non-finite coordinate: {V[bad[0]].tolist()}")
        polys = self._polygons(faces, sizes)
        if not polys:
            raise MeshError("the mesh has no faces")
        n = V.shape[0]
        for f, p in enumerate(polys):
            if len(p) < 3:
                raise MeshError(f"face {f} has {len(p)} vertices (needs >= 3): {p}")
            for v in p:
                if not 0 <= v < n:
                    raise MeshError(f"face {f} has a vertex index out of range [0, {n}): {p}")
            if len(set(p)) != len(p):
                r = next(v for v in p if p.count(v) > 1)
                raise MeshError(f"face {f} repeats vertex {r}: {p}")
        self.vertices = V
        self.vertices.setflags(write=False)
        self.polygons = [tuple(p) for p in polys]
        self.sizes = np.array([len(p) for p in polys], dtype=np.int64)
        self.offsets = np.r_[0, np.cumsum(self.sizes)].astype(np.int64)
        self.indices = np.array([v for p in polys for v in p], dtype=np.int64)
        if options is None:
            options = Options()
        elif isinstance(options, dict):
            options = Options(**options)
        self.options = options
        self._build_topology()
        self.edge_sharpness = self._creases(creases)
        self.vertex_sharpness = self._corners(corners)
        m = len(polys)
        hole = np.zeros(m, dtype=bool)
        for f in [] if holes is None else list(holes):
            fi = int(f)
            if fi != f or not 0 <= fi < m:
                raise MeshError(f"hole face {f!r} out of range [0, {m})")
            hole[fi] = True
        self.is_hole_tagged = hole
        self.is_hole = hole | self._implicit_holes()
        ptex_count = np.where(self.sizes == 4, 1, self.sizes)
        self.ptex_start = np.r_[0, np.cumsum(ptex_count)].astype(np.int64)
        self.n_ptex = int(self.ptex_start[-1])
        #: subdivision level (0 for input meshes; the TRI_SUB_SMOOTH and EDGE_AND_CORNER rules act at 0)
        self.level = 0

    # ------------------------------------------------------------------ construction helpers
    @staticmethod
    def _polygons(faces, sizes):
        if sizes is not None:
            idx = np.asarray(faces, dtype=np.int64).reshape(-1)
            sz = np.asarray(sizes, dtype=np.int64).reshape(-1)
            if (sz < 0).any() or sz.sum() != idx.size:
                raise MeshError(f"face sizes sum to {int(sz.sum())}, but there are {idx.size} indices")
            off = np.r_[0, np.cumsum(sz)]
            return [idx[off[f] : off[f + 1]].tolist() for f in range(sz.size)]
        if isinstance(faces, tuple) and len(faces) == 2 and np.ndim(faces[0]) == 1 and np.ndim(faces[1]) == 1:
            idx = np.asarray(faces[0], dtype=np.int64)
            off = np.asarray(faces[1], dtype=np.int64)
            if off.size == 0 or off[0] != 0 or off[-1] != idx.size or (np.diff(off) < 0).any():
                raise MeshError("offsets must start at 0, be non-decreasing and end at len(indices)")
            return [idx[off[f] : off[f + 1]].tolist() for f in range(off.size - 1)]
        out = []
        for f, p in enumerate(faces):
            q = np.asarray(p)
            if q.ndim != 1 or (q.size and not np.issubdtype(q.dtype, np.integer)):
                qi = q.astype(np.int64) if q.ndim == 1 else None
                if qi is None or not np.array_equal(qi, q):
                    raise MeshError(f"face {f}: vertex indices must be integers, got {p!r}")
                q = qi
            out.append([int(v) for v in q])
        return out

    def _build_topology(self):
        n = self.vertices.shape[0]
        off, idx = self.offsets, self.indices
        H = idx.size
        face_of = np.repeat(np.arange(len(self.polygons)), self.sizes)
        loc = np.arange(H) - off[face_of]
        nxt = off[face_of] + (loc + 1) % self.sizes[face_of]
        prv = off[face_of] + (loc - 1) % self.sizes[face_of]
        org, dst = idx, idx[nxt]
        lo, hi, order, starts, counts, edge_of, twin = _pair_halfedges(org, dst, face_of, n)
        first = order[starts]
        self.edges = np.stack([lo[first], hi[first]], axis=1)
        self.edge_index = {(int(a), int(b)): e for e, (a, b) in enumerate(self.edges.tolist())}
        self.is_boundary_edge = counts == 1
        self.twin, self.next, self.prev, self.face_of_halfedge = twin, nxt, prv, face_of
        self.edge_of_halfedge = edge_of
        face_count = np.bincount(org, minlength=n)
        self.face_count = face_count
        # fans: rot(c) = twin(prev(c)) is the next corner counter-clockwise around org(c)
        rot = twin[prv]
        seen = np.zeros(H, dtype=bool)
        nfans = np.zeros(n, dtype=np.int64)
        for c0 in range(H):
            if seen[c0]:
                continue
            v = int(org[c0])
            nfans[v] += 1
            c = c0
            while c >= 0 and not seen[c]:
                seen[c] = True
                c = int(rot[c])
            c = int(twin[c0])
            c = -1 if c < 0 else int(nxt[c])
            while c >= 0 and not seen[c]:
                seen[c] = True
                t = int(twin[c])
                c = -1 if t < 0 else int(nxt[t])
        if (nfans > 1).any():
            v = int(np.flatnonzero(nfans > 1)[0])
            raise MeshError(
                f"non-manifold vertex {v}: its faces form {int(nfans[v])} separate fans "
                f"(faces {sorted(set(face_of[org == v].tolist()))})"
            )
        self.is_boundary_vertex = np.bincount(org[twin < 0], minlength=n) > 0
        self.is_unused_vertex = face_count == 0

    def _creases(self, creases):
        out = {}
        if creases is None:
            return out
        if isinstance(creases, dict):
            items = list(creases.items())
        else:
            E, S = creases
            E = np.asarray(E).reshape(-1, 2)
            S = np.broadcast_to(np.asarray(S, dtype=object), (E.shape[0],))
            items = [((a, b), s) for (a, b), s in zip(E.tolist(), S.tolist())]
        for (a, b), s in items:
            a, b = int(a), int(b)
            what = f"crease on edge ({a}, {b})"
            sv = _sharp_value(s, what)
            k = (min(a, b), max(a, b))
            if k not in self.edge_index:
                raise MeshError(f"{what}: no such edge in the mesh")
            if sv > 0:
                out[k] = sv
            else:
                out.pop(k, None)
        return out

    def _corners(self, corners):
        out = {}
        if corners is None:
            return out
        if isinstance(corners, dict):
            items = list(corners.items())
        else:
            Vs, S = corners
            Vs = np.asarray(Vs).reshape(-1)
            S = np.broadcast_to(np.asarray(S, dtype=object), (Vs.shape[0],))
            items = list(zip(Vs.tolist(), S.tolist()))
        n = self.vertices.shape[0]
        for v, s in items:
            vi = int(v)
            if vi != v or not 0 <= vi < n:
                raise MeshError(f"corner on vertex {v!r}: out of range [0, {n})")
            sv = _sharp_value(s, f"corner on vertex {vi}")
            if sv > 0:
                out[vi] = sv
        return out

    def _implicit_holes(self):
        """``VTX_BOUNDARY_NONE``: faces at a boundary vertex with a boundary edge not tagged infinite."""
        m = len(self.polygons)
        out = np.zeros(m, dtype=bool)
        if self.options.boundary != "none":
            return out
        bad_vertex = np.zeros(self.vertices.shape[0], dtype=bool)
        for e in np.flatnonzero(self.is_boundary_edge):
            a, b = self.edges[e]
            if not math.isinf(self.edge_sharpness.get((int(a), int(b)), 0.0)):
                bad_vertex[a] = bad_vertex[b] = True
        for f, p in enumerate(self.polygons):
            if bad_vertex[list(p)].any():
                out[f] = True
        return out

    # ------------------------------------------------------------------ accessors
    @property
    def n_vertices(self):
        return self.vertices.shape[0]

    @property
    def n_faces(self):
        return len(self.polygons)

    @property
    def is_all_quads(self):
        return bool((self.sizes == 4).all())

    @property
    def has_tags(self):
        """Creases, corners, holes or non-default options."""
        return bool(self.edge_sharpness or self.vertex_sharpness or self.is_hole.any()
                    or self.options != Options())

    @property
    def bounding_box_diagonal(self):
        return float(np.linalg.norm(self.vertices.max(axis=0) - self.vertices.min(axis=0)))

    def ptex_of(self, face, corner=0):
        """Ptex index of ``(face, corner)`` (``corner`` ignored for quads)."""
        face = int(face)
        if not 0 <= face < self.n_faces:
            raise MeshError(f"face {face} out of range [0, {self.n_faces})")
        k = int(self.sizes[face])
        if k == 4:
            return int(self.ptex_start[face])
        if not 0 <= corner < k:
            raise MeshError(f"corner {corner} out of range for face {face} with {k} vertices")
        return int(self.ptex_start[face]) + int(corner)

    def face_of_ptex(self, ptex):
        """``(face, corner)`` of ptex face ``ptex`` (corner 0 for a quad)."""
        p = int(ptex)
        if not 0 <= p < self.n_ptex:
            raise MeshError(f"ptex face {p} out of range [0, {self.n_ptex})")
        f = int(np.searchsorted(self.ptex_start, p, side="right") - 1)
        return f, p - int(self.ptex_start[f])

    def complex(self):
        """The mesh as a :class:`~ccproof.mesh.rules.Complex` at level 0."""
        return Complex(self.polygons, dict(self.edge_sharpness), dict(self.vertex_sharpness), self.options,
                       level=self.level, n_vertices=self.n_vertices)

    def refine(self):
        """One Catmull-Clark step with the tagged rules (layout of :mod:`ccproof.mesh.rules`).

        Returns
        -------
        PolyMesh
            All quads; child ``offsets[f] + k`` is corner k of face f; sharpness decayed; holes
            inherited by the children; the options kept (``EDGE_AND_CORNER`` corners carried as
            infinite vertex sharpness).
        S : scipy.sparse.csr_matrix, shape (n + E + m, n)
            ``refined.vertices == S @ self.vertices``.
        """
        cx = self.complex()
        stencils, children, ces, cvs = refine_complex(cx)
        S = _stencil_matrix(stencils, self.n_vertices)
        V1 = S @ self.vertices
        holes = np.repeat(self.is_hole, self.sizes)
        m = PolyMesh(V1, children, creases=(list(ces.keys()), list(ces.values())) if ces else None,
                     corners=cvs or None, holes=np.flatnonzero(holes), options=self.options)
        m.level = self.level + 1
        return m, S

    def subdivision_operator(self, exact=False):
        """The linear operator S of one step: ``refine()[0].vertices == S @ vertices``.

        ``exact=True``: a list of dict rows with exact rational weights (``flint.fmpq``: the
        same stencils the float matrix is rounded from).
        """
        stencils, _, _, _ = refine_complex(self.complex())
        if exact:
            return stencils
        return _stencil_matrix(stencils, self.n_vertices)

    def __repr__(self):
        return (f"PolyMesh({self.n_vertices} vertices, {self.n_faces} faces, {self.n_ptex} ptex faces, "
                f"{len(self.edge_sharpness)} creases, {len(self.vertex_sharpness)} corners, "
                f"{int(self.is_hole.sum())} holes, {self.options})")


def _stencil_matrix(stencils, ncols):
    """Float CSR matrix of a list of stencils (dict column -> weight; None rows are NaN)."""
    rows, cols, vals = [], [], []
    for r, s in enumerate(stencils):
        if s is None:
            rows.append(r)
            cols.append(0)
            vals.append(np.nan)
            continue
        for c, w in s.items():
            rows.append(r)
            cols.append(c)
            vals.append(to_float(w))
    return sp.csr_matrix((vals, (rows, cols)), shape=(len(stencils), ncols))
