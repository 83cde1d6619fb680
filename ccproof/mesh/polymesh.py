"""Validated polygon meshes with OpenSubdiv's tags (creases, corners, holes, boundary modes) and ptex faces.

A :class:`PolyMesh` holds any manifold, consistently oriented polygon mesh (triangles, quads,
n-gons) with edge sharpness, vertex sharpness, hole faces and the Sdc :class:`~ccproof.mesh.rules.Options`.

Ptex faces (OpenSubdiv ``Far::PtexIndices``): faces are numbered in order; a quad is one ptex face,
its corner k at (s, t) = (0,0), (1,0), (1,1), (0,1); a face with n != 4 vertices is n consecutive
ptex faces, sub-face k being the quad (v_k, mid(v_k, v_k+1), centre, mid(v_k-1, v_k)) of the first
Catmull-Clark step: (0,0) = v_k, (1,0) = the edge point of (v_k, v_k+1), (1,1) = the face point,
(0,1) = the edge point of (v_k-1, v_k). :meth:`PolyMesh.ptex_of` and :meth:`PolyMesh.face_of_ptex`
are the mapping (face, corner) <-> ptex index.

Checks (:class:`~ccproof.errors.MeshError` naming the element otherwise): faces with >= 3 vertex
indices in range (a repeated one as OpenSubdiv takes it, below), finite coordinates on every vertex
a face uses (unused vertices may hold anything and keep their index), crease tags on existing
edges, sharpness finite or infinite but not negative and not NaN, hole indices in range.

Non-manifold edges and vertices are taken as OpenSubdiv takes them (``Vtr::Level``: an edge with
more than two faces or two faces in the same direction, e.g. a face given twice, a degenerate edge
(v, v) and an edge a face holds twice; a vertex at such an edge or whose faces form several fans;
``Far::TopologyRefinerFactory``: such edges infinitely sharp, such vertices infinitely sharp
corners but on an interior non-manifold crease). :attr:`PolyMesh.manifold` is the mesh the surface
is evaluated on: the fans of every non-manifold vertex split apart (see
:func:`ccproof.mesh.nonmanifold.split_nonmanifold_vertices`), the same faces.
"""

from __future__ import annotations

import functools
import itertools
import math

import numpy as np

from ccproof.errors import MeshError
from ccproof.mesh.csr import csr_matrix_with_empty_rows
from ccproof.mesh.halfedges import HalfEdges
from ccproof.mesh.quadmesh import check_used_finite
from ccproof.mesh.rules import Complex, Options, refine_complex
from ccproof.mesh.tags import corner_tags, crease_tags

__all__ = ["PolyMesh"]


class PolyMesh:
    """A polygon mesh with Sdc tags (OpenSubdiv's ``Far::TopologyDescriptor``), manifold or not.

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

    Attributes
    ----------
    is_unused_vertex, is_boundary_vertex, is_nonmanifold_vertex : ndarray of bool, shape (n,)
    edges : ndarray of int, shape (E, 2)
        Undirected edges (lo, hi); ``is_boundary_edge``, ``is_nonmanifold_edge`` (E,),
        ``edge_face_count`` (E,).
    manifold : PolyMesh
        ``self`` when :attr:`is_manifold`, else the split mesh (same faces, vertices
        ``vertices[manifold_vertex_map]``).
    manifold_vertex_map : ndarray of int, shape (n',)
    halfedges : HalfEdges
        The topology (:class:`~ccproof.mesh.halfedges.HalfEdges`: ``twin``, ``next``, ``prev``, ``edges``
        ... above are its arrays), with the edge and vertex sharpness as its tag arrays.

    Examples
    --------
    >>> m = PolyMesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])
    >>> m.n_ptex, m.ptex_of(0, 2), m.face_of_ptex(1)
    (3, 2, (0, 1))

    Two triangles touching at vertex 0 (a bow tie): vertex 0 is non-manifold, an infinitely sharp
    corner; the evaluated mesh has a copy of it (vertex 5) for the second fan:

    >>> b = PolyMesh([[0, 0, 0], [1, 0, 0], [1, 1, 0], [-1, 0, 0], [-1, -1, 0]], [[0, 1, 2], [0, 3, 4]])
    >>> b.is_manifold, b.is_nonmanifold_vertex.tolist(), b.manifold.polygons, b.manifold_vertex_map.tolist()
    (False, [True, False, False, False, False], [(0, 1, 2), (5, 3, 4)], [0, 1, 2, 3, 4, 0])
    >>> b.manifold.vertex_sharpness
    {0: inf, 5: inf}
    >>> PolyMesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]], creases=([[0, 2]], [-1]))
    Traceback (most recent call last):
    ...
    ccproof.errors.MeshError: crease on edge (0, 2): negative sharpness -1.0
    """

    #: the one topology (:class:`~ccproof.mesh.halfedges.HalfEdges`), with the tags as arrays
    halfedges: HalfEdges

    def __init__(self, vertices, faces, *, creases=None, corners=None, holes=None, options=None, sizes=None,
                 _split=True, _halfedges=None):
        V = np.array(vertices, dtype=np.float64)
        if V.ndim != 2 or V.shape[1] != 3:
            raise MeshError(f"vertices must have shape (n, 3), got {V.shape}")
        # the faces as flat arrays (indices, offsets): no Python object per face (memory on large scans)
        idx, sz = self._flat_faces(faces, sizes)
        if not sz.size:
            raise MeshError("the mesh has no faces")
        n = V.shape[0]
        off = np.r_[0, np.cumsum(sz)].astype(np.int64)
        short = np.flatnonzero(sz < 3)
        bad = np.flatnonzero((idx < 0) | (idx >= n))
        f_bad = int(np.searchsorted(off[1:], bad[0], side="right")) if bad.size else sz.size
        if short.size and short[0] <= f_bad:
            f = int(short[0])
            raise MeshError(f"face {f} has {int(sz[f])} vertices (needs >= 3): {idx[off[f]:off[f + 1]].tolist()}")
        if bad.size:
            raise MeshError(f"face {f_bad} has a vertex index out of range [0, {n}): "
                            f"{idx[off[f_bad]:off[f_bad + 1]].tolist()}")
        if _split is False:  # (the split mesh: a face still touching itself)
            for f in range(sz.size):
                p = idx[off[f]:off[f + 1]].tolist()
                if len(set(p)) != len(p):
                    r = next(v for v in p if p.count(v) > 1)
                    raise MeshError(f"face {f} repeats vertex {r} within one fan: {p}")
        check_used_finite(V, idx)
        self.vertices = V
        self.vertices.setflags(write=False)
        self.sizes = sz
        self.offsets = off
        self.indices = idx
        if options is None:
            options = Options()
        elif isinstance(options, dict):
            options = Options(**options)
        self.options = options
        self._build_topology(_halfedges)
        self.edge_sharpness = crease_tags(self.halfedges, creases)
        self.vertex_sharpness = corner_tags(self.vertices.shape[0], corners)
        if self.edge_sharpness or self.vertex_sharpness:  # the tags as arrays on the one topology
            self.halfedges = self.halfedges.with_tags(self.edge_sharpness, self.vertex_sharpness)
        m = int(sz.size)
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
        if self.is_manifold:
            self.manifold, self.manifold_vertex_map = self, np.arange(n, dtype=np.int64)
        elif not _split:
            raise MeshError("internal: the split of the non-manifold vertices is still non-manifold")
        else:
            self.manifold, self.manifold_vertex_map = self._split_nonmanifold()

    def __getstate__(self):
        """Pickled without the Python lists and dicts built on first use (:attr:`polygons`, :attr:`edge_index`:
        tens of bytes per face each, rebuilt from the arrays where needed), e.g. for the workers of a cluster."""
        return {k: v for k, v in self.__dict__.items() if k not in ("polygons", "edge_index")}

    # ------------------------------------------------------------------ construction helpers
    @functools.cached_property
    def polygons(self):
        """The faces as tuples of vertex indices (built on first use from :attr:`indices`, :attr:`offsets`)."""
        flat = self.indices.tolist()
        off = self.offsets.tolist()
        return [tuple(flat[a:b]) for a, b in zip(off[:-1], off[1:])]

    @functools.cached_property
    def edge_index(self):
        """``{(a, b): e}`` for every edge ``e`` (a < b) of :attr:`edges` (built on first use)."""
        return {(int(a), int(b)): e for e, (a, b) in enumerate(self.edges.tolist())}

    @staticmethod
    def _flat_faces(faces, sizes):
        """``(indices, sizes)``, int64 arrays, of the ``faces`` argument (see the class docstring)."""
        if sizes is not None:
            idx = np.asarray(faces, dtype=np.int64).reshape(-1)
            sz = np.asarray(sizes, dtype=np.int64).reshape(-1)
            if (sz < 0).any() or sz.sum() != idx.size:
                raise MeshError(f"face sizes sum to {int(sz.sum())}, but there are {idx.size} indices")
            return idx, sz
        if isinstance(faces, tuple) and len(faces) == 2 and np.ndim(faces[0]) == 1 and np.ndim(faces[1]) == 1:
            idx = np.asarray(faces[0], dtype=np.int64)
            off = np.asarray(faces[1], dtype=np.int64)
            if off.size == 0 or off[0] != 0 or off[-1] != idx.size or (np.diff(off) < 0).any():
                raise MeshError("offsets must start at 0, be non-decreasing and end at len(indices)")
            return idx, np.diff(off)
        if isinstance(faces, np.ndarray) and faces.ndim == 2 and np.issubdtype(faces.dtype, np.integer):
            return faces.astype(np.int64).reshape(-1), np.full(faces.shape[0], faces.shape[1], dtype=np.int64)
        polys = PolyMesh._polygons(faces)
        sz = np.fromiter((len(p) for p in polys), dtype=np.int64, count=len(polys))
        idx = np.fromiter(itertools.chain.from_iterable(polys), dtype=np.int64, count=int(sz.sum()))
        return idx, sz

    @staticmethod
    def _polygons(faces):
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

    def _build_topology(self, he=None):
        """Edges, twins and fans (:class:`~ccproof.mesh.halfedges.HalfEdges`, built once: ``self.halfedges``);
        OpenSubdiv's non-manifold edges and vertices (``Vtr::Level``).

        An edge is non-manifold when more than two faces share it or two faces traverse it in the
        same direction (``completeTopologyFromFaceVertices``; a face given twice is such a case); a
        vertex is non-manifold when it ends a non-manifold edge or its faces do not form a single
        fan (``orderVertexFacesAndEdges``). Twins exist only across manifold edges.

        ``he``: the untagged half-edges of these faces under these options, built elsewhere (a
        :class:`~ccproof.mesh.QuadMesh`'s, :func:`~ccproof.mesh.quadmesh.shared_halfedges`, or derived from the parent's
        by :meth:`refine`: :meth:`HalfEdges.refined <ccproof.mesh.halfedges.HalfEdges.refined>`), shared; built here
        when None (or when they do not match).
        """
        n = self.vertices.shape[0]
        if (he is None or he.has_tags or he.options != self.options or he.n_vertices != n
                or not np.array_equal(he.offsets, self.offsets) or not np.array_equal(he.org, self.indices)):
            he = HalfEdges(self.indices, self.offsets, n, self.options)
        self.halfedges = he
        # a face repeating a vertex: a degenerate edge (v, v), or an edge the face holds twice; OpenSubdiv
        # gives each such occurrence an edge of its own with one face (a boundary edge), so that both
        # ends are sharpened (corners)
        self._repeat_edge = he.repeat_edge
        self.edges = he.edges
        self.edge_face_count = he.edge_face_count
        self.is_boundary_edge = he.edge_face_count == 1
        self.is_nonmanifold_edge = he.is_nonmanifold_edge
        self.twin, self.next, self.prev, self.face_of_halfedge = he.twin, he.nxt, he.prv, he.face_of
        self.edge_of_halfedge = he.edge_of
        self.face_count = he.face_count
        self.is_nonmanifold_vertex = he.is_nonmanifold_vertex
        self.is_boundary_vertex = he.is_boundary_vertex
        self.is_unused_vertex = self.face_count == 0

    @property
    def is_manifold(self):
        """No non-manifold edge or vertex (OpenSubdiv's definition; see :meth:`_build_topology`)."""
        return not self.is_nonmanifold_vertex.any()

    @property
    def nonmanifold_edges(self):
        """int (k, 2): the non-manifold edges (more than two faces, or two faces in the same direction)."""
        return self.edges[self.is_nonmanifold_edge]

    def _split_nonmanifold(self):
        """The manifold mesh on which the limit surface is evaluated, and its vertex map:
        :func:`ccproof.mesh.nonmanifold.split_nonmanifold_vertices`."""
        from ccproof.mesh.nonmanifold import split_nonmanifold_vertices

        return split_nonmanifold_vertices(self)

    def _implicit_holes(self):
        """``VTX_BOUNDARY_NONE``: faces at a boundary vertex with a boundary edge not tagged infinite."""
        m = self.sizes.size
        out = np.zeros(m, dtype=bool)
        if self.options.boundary != "none":
            return out
        bad_vertex = np.zeros(self.vertices.shape[0], dtype=bool)
        # one-face edges, and OpenSubdiv's one-face edges of a face repeating a vertex
        for e in np.flatnonzero(self.is_boundary_edge | self._repeat_edge):
            a, b = self.edges[e]
            if not math.isinf(self.edge_sharpness.get((int(a), int(b)), 0.0)):
                bad_vertex[a] = bad_vertex[b] = True
        return np.logical_or.reduceat(bad_vertex[self.indices], self.offsets[:-1])

    # ------------------------------------------------------------------ accessors
    @property
    def n_vertices(self):
        return self.vertices.shape[0]

    @property
    def n_faces(self):
        return int(self.sizes.size)

    @property
    def is_all_quads(self):
        return bool((self.sizes == 4).all())

    @property
    def is_plain_quads(self):
        """All quads, no tags, manifold: the mesh is a :class:`~ccproof.mesh.QuadMesh` (see :meth:`to_quad_mesh`)."""
        return self.is_all_quads and not self.has_tags and self.is_manifold

    def to_quad_mesh(self):
        """The same mesh as a :class:`~ccproof.mesh.QuadMesh` (same vertices, unused ones included, same faces,
        this mesh's :attr:`halfedges` shared: :meth:`QuadMesh.from_polymesh <ccproof.mesh.QuadMesh.from_polymesh>`).

        Raises
        ------
        MeshError
            If the mesh is not :attr:`is_plain_quads` (the message says why).

        Examples
        --------
        >>> m = PolyMesh([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [9, 9, 9]], [[0, 1, 2, 3]])
        >>> m.is_plain_quads, m.to_quad_mesh()
        (True, QuadMesh(5 vertices, 1 faces, 4 boundary edges, 0 extraordinary vertices))
        """
        from ccproof.mesh.quadmesh import QuadMesh

        if not self.is_plain_quads:
            why = ("it has faces that are not quads" if not self.is_all_quads else
                   "it has OpenSubdiv tags" if self.has_tags else "it is not manifold")
            raise MeshError(f"not a plain quad mesh: {why}")
        return QuadMesh.from_polymesh(self)  # this mesh's half-edges, shared (the topology built once)

    @property
    def has_tags(self):
        """Creases, corners, holes or non-default options."""
        return bool(self.edge_sharpness or self.vertex_sharpness or self.is_hole.any()
                    or self.options != Options())

    @property
    def bounding_box_diagonal(self):
        """Length of the diagonal of the axis-aligned bounding box of the used vertices."""
        V = self.vertices[~self.is_unused_vertex] if self.is_unused_vertex.any() else self.vertices
        return float(np.linalg.norm(V.max(axis=0) - V.min(axis=0)))

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

    def with_vertices(self, vertices):
        """The same mesh with the control points ``vertices``: connectivity, tags and topology re-used.

        Nothing that depends only on the connectivity is rebuilt: the new mesh shares this one's
        :attr:`halfedges` (with its tag arrays), face arrays, tags, holes, options and
        :attr:`manifold_vertex_map`; on a non-manifold mesh its :attr:`manifold` is this one's split mesh
        (sharing that one's topology the same way) with the vertices ``vertices[manifold_vertex_map]``.
        The result equals ``PolyMesh(vertices, faces, creases=..., corners=..., holes=..., options=...)``
        built anew, without the topology, the checks of the faces and tags, and the split; but for
        :attr:`level`, which it keeps (a refined mesh's level-0 rules stay off: the constructor's mesh is at 0).

        Parameters
        ----------
        vertices : array_like, shape (n_vertices, 3)
            Unused vertices may hold anything (NaN, inf): they keep their index and enter nothing.

        Returns
        -------
        PolyMesh

        Raises
        ------
        MeshError
            A shape other than this mesh's ``vertices.shape``, or a non-finite coordinate on a vertex a face uses
            (the message names the first such vertex).

        Examples
        --------
        >>> m = PolyMesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]], creases={(0, 1): 2.0})
        >>> m2 = m.with_vertices([[0, 0, 0], [2, 0, 0], [0, 2, 0]])
        >>> m2.vertices[1].tolist(), m2.halfedges is m.halfedges, m2.edge_sharpness, m.vertices[1].tolist()
        ([2.0, 0.0, 0.0], True, {(0, 1): 2.0}, [1.0, 0.0, 0.0])
        >>> m.with_vertices([[0, 0, 0], [float("nan"), 0, 0], [0, 1, 0]])
        Traceback (most recent call last):
        ...
        ccproof.errors.MeshError: vertex 1 has a non-finite coordinate: [nan, 0.0, 0.0]
        """
        V = np.array(vertices, dtype=np.float64)
        if V.shape != self.vertices.shape:
            raise MeshError(f"vertices must have shape {self.vertices.shape}, got {V.shape}")
        check_used_finite(V, self.indices)
        V.setflags(write=False)
        new = self._replace_vertices(V)
        if self.manifold is self:
            new.manifold = new
        else:
            Vm = V[self.manifold_vertex_map]
            Vm.setflags(write=False)
            new.manifold = self.manifold._replace_vertices(Vm)
            new.manifold.manifold = new.manifold
        return new

    def _replace_vertices(self, V):
        """A shallow copy (every attribute shared) with the checked, read-only vertices ``V``."""
        new = object.__new__(PolyMesh)
        new.__dict__.update(self.__dict__)
        new.vertices = V
        return new

    def complex(self):
        """The mesh as a :class:`~ccproof.mesh.rules.Complex` at level 0.

        On a non-manifold mesh, the complex of :attr:`manifold` (labels of its vertices: indices of
        ``manifold.vertices = vertices[manifold_vertex_map]``).
        """
        if self.manifold is not self:
            return self.manifold.complex()
        return Complex(self.polygons, dict(self.edge_sharpness), dict(self.vertex_sharpness), self.options,
                       level=self.level, n_vertices=self.n_vertices)

    def refine(self, operator=True):
        """One Catmull-Clark step with the tagged rules (layout of :mod:`ccproof.mesh.rules`).

        The step is :func:`ccproof.mesh.step.catmark_operator` (vectorized; each weight the correctly
        rounded value of :func:`~ccproof.mesh.rules.refine_complex`'s exact stencil, the reference of
        ``tests/mesh/test_step.py`` and of ``subdivision_operator(exact=True)``).

        Parameters
        ----------
        operator : bool or "csr"
            Also return the step's sparse matrix (False: None instead, and scipy is not imported;
            ``"csr"``: the step's CSR arrays, below, without scipy).

        Returns
        -------
        PolyMesh
            All quads; child ``offsets[f] + k`` is corner k of face f; sharpness decayed; holes
            inherited by the children; the options kept (``EDGE_AND_CORNER`` corners carried as
            infinite vertex sharpness). The vertex point of an unused vertex is NaN (it stays unused).
        S : scipy.sparse.csr_matrix, shape (n + E + m, n), or None
            ``refined.vertices == S @ self.vertices`` (bit for bit on a manifold mesh: each row summed
            in increasing columns); an unused vertex's row is NaN at column 0. On a non-manifold mesh,
            :meth:`subdivision_operator`: the step of :attr:`manifold` (n + E + m counted there) with the
            copies of a vertex summed exactly into its column; the child is :attr:`manifold`'s, which
            ``S @ self.vertices`` equals up to rounding (the copies' weights merged, other column order).
            With ``operator="csr"``: ``(indptr, indices, data)`` (:attr:`ccproof.mesh.step.Step.csr`) of the
            step of :attr:`manifold`, its columns that mesh's vertices, an unused vertex's row empty:
            ``refined.vertices == apply_csr(csr, manifold.vertices)`` (:func:`ccproof.mesh.csr.apply_csr`)
            but on the unused vertices' rows (NaN there).
        """
        if self.manifold is not self:
            if operator == "csr":
                return self.manifold.refine(operator)
            m, _ = self.manifold.refine(operator=False)
            return m, (self.subdivision_operator() if operator else None)
        from ccproof.mesh.crease import decrement
        from ccproof.mesh.csr import apply_csr

        st = self._step(sparse=False)
        n = self.n_vertices
        unused = np.flatnonzero(self.is_unused_vertex)
        V1 = apply_csr(st.csr, self.vertices)
        V1[unused] = np.nan
        # child vertex sharpness: the step's (used vertices), and an unused vertex's tag decayed
        cvs = np.zeros(n)
        cvs[st.child_corners[0]] = st.child_corners[1]
        if unused.size and self.vertex_sharpness:
            vs = np.array([self.vertex_sharpness.get(v, 0.0) for v in unused.tolist()])
            cvs[unused] = decrement(vs)
        sharp_v = np.flatnonzero(cvs > 0)
        pairs, ces = st.child_creases
        he = self.halfedges
        # the child's topology derived from this mesh's (no pairing of the child's half-edges); paired
        # again by the constructor when this mesh's half-edges are anything unusual
        child_he = HalfEdges.refined(he, self.options) if he.edge_manifold and self.is_manifold else None
        m = PolyMesh(V1, st.faces, creases=(pairs, ces) if ces.size else None,
                     corners=(sharp_v, cvs[sharp_v]) if sharp_v.size else None,
                     holes=np.flatnonzero(st.child_holes), options=self.options, _halfedges=child_he)
        m.level = self.level + 1
        if operator == "csr":
            return m, st.csr
        S = csr_matrix_with_empty_rows(st.csr, unused, n) if operator else None
        return m, S

    def _step(self, **kwargs):
        """:func:`ccproof.mesh.step.catmark_operator` of this manifold mesh with its tags (keyword
        arguments passed on), edges numbered as :class:`~ccproof.mesh.rules.Complex` numbers them; the step
        reads :attr:`halfedges` (no second pairing)."""
        from ccproof.mesh.step import StepOptions, catmark_operator

        return catmark_operator(self.n_vertices, self.indices, self.sizes, halfedges=self.halfedges,
                                edge_sharpness=self.edge_sharpness, vertex_sharpness=self.vertex_sharpness,
                                holes=self.is_hole, options=StepOptions(self.options, self.level, **kwargs))

    def subdivision_operator(self, exact=False):
        """The linear operator S of one step: ``refine()[0].vertices == S @ vertices`` (bit for bit on a
        manifold mesh; on a non-manifold one up to rounding: the child is the split mesh's).

        ``exact=False``: the float matrix of :func:`ccproof.mesh.step.catmark_operator`, every weight
        the correctly rounded exact one (on a non-manifold mesh the copies of a vertex summed exactly
        before rounding); an unused vertex's row is NaN at column 0. ``exact=True``: a list of dict
        rows with exact rational weights (``flint.fmpq``: :func:`~ccproof.mesh.rules.refine_complex`'s
        stencils, the reference the float matrix is checked against; None for an unused vertex).
        """
        if not exact:
            M = self.manifold
            st = M._step(columns=self.manifold_vertex_map, n_columns=self.n_vertices, sparse=False)
            return csr_matrix_with_empty_rows(st.csr, np.flatnonzero(M.is_unused_vertex), self.n_vertices)
        stencils, _, _, _ = refine_complex(self.complex())
        if self.manifold is not self:
            vmap = self.manifold_vertex_map.tolist()
            out: list[dict | None] = []
            for st in stencils:
                if st is None:
                    out.append(None)
                    continue
                d = {}
                for c, w in st.items():
                    d[vmap[c]] = d.get(vmap[c], 0) + w
                out.append(d)
            stencils = out
        return stencils

    def __repr__(self):
        extra = ""
        if not self.is_manifold:
            extra += (f"{int(self.is_nonmanifold_edge.sum())} non-manifold edges, "
                      f"{int(self.is_nonmanifold_vertex.sum())} non-manifold vertices, ")
        if self.is_unused_vertex.any():
            extra += f"{int(self.is_unused_vertex.sum())} unused vertices, "
        return (f"PolyMesh({self.n_vertices} vertices, {self.n_faces} faces, {self.n_ptex} ptex faces, "
                f"{len(self.edge_sharpness)} creases, {len(self.vertex_sharpness)} corners, "
                f"{int(self.is_hole.sum())} holes, {extra}{self.options})")
