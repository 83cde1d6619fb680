"""Validated all-quad meshes and their topology (bmz04 section 2, "Control meshes").

A :class:`QuadMesh` is a two-dimensional polygonal complex K = (V, E, F) whose faces are
quadruples of vertices (bmz04 section 2) together with the control points p (one 3-vector per
vertex). The constructor checks everything the subdivision and evaluation layers rely on and raises
:class:`ccproof.errors.MeshError` naming the offending face, edge or vertex otherwise:

* every face is a quadrilateral with four distinct vertex indices in range;
* coordinates are finite at every vertex a face uses (unused vertices are allowed, with any
  coordinates: they keep their index and have no surface, valence 0 and NaN limits);
* every edge has one (boundary) or two (interior) faces (edge-manifold);
* the two faces of an interior edge traverse it in opposite directions (consistent orientation);
* the faces around every vertex form a single fan, closed (interior vertex) or open (boundary
  vertex): the *link* of every vertex is a simple polygonal line (bmz04: manifold meshes);
* every interior vertex has valence >= 3.

Half-edge conventions (used throughout ccproof): half-edge ``h = 4 f + i`` runs from
``faces[f, i]`` to ``faces[f, (i + 1) % 4]``; it is also the *corner* of face ``f`` at vertex
``faces[f, i]``. ``twin[h]`` is the opposite half-edge, ``-1`` on the boundary. The arrays are those
of the mesh's :class:`~ccproof.mesh.halfedges.HalfEdges` (``mesh.halfedges``, built once).
"""

from __future__ import annotations

import numpy as np

from ccproof.errors import MeshError
from ccproof.mesh.halfedges import HalfEdges, connected_components
from ccproof.mesh.rules import Options
from ccproof.mesh.scheme import CATMARK

__all__ = ["QuadMesh", "connected_components"]


def _edge_str(a, b):
    return f"edge ({int(a)}, {int(b)})"


def _check_pairing(he):
    """Raise :class:`MeshError` naming the edge and faces when an edge of the half-edges ``he``
    (:class:`~ccproof.mesh.halfedges.HalfEdges`) has more than two faces or two faces traverse it the
    same way (a face given twice, the likeliest cause, named as such)."""
    counts = he.edge_face_count
    if not (counts > 2).any() and not he._same.size:
        return
    org, face_of = he.org, he.face_of
    order = np.argsort(he.edge_of, kind="stable")  # the half-edges by edge
    starts = np.r_[0, np.cumsum(counts)[:-1]]
    H = org.size
    dst = org[he.nxt]
    bad = (counts > 2) | ((counts == 2) & (org[order[starts]] == org[order[np.minimum(starts + 1, H - 1)]]))
    if bad.any():  # a face given twice is the likeliest cause: name it
        g = int(np.flatnonzero(bad)[0])
        dup = _duplicate_face(org, face_of, order[starts[g] : starts[g] + counts[g]])
        if dup is not None:
            raise MeshError(f"duplicate face: faces {dup[0]} and {dup[1]} have the same vertices {dup[2]}")
    if (counts > 2).any():
        g = int(np.flatnonzero(counts > 2)[0])
        hs = order[starts[g] : starts[g] + counts[g]]
        lo, hi = he.edges[g]
        raise MeshError(
            f"non-manifold {_edge_str(lo, hi)}: shared by {int(counts[g])} faces "
            f"{sorted(int(face_of[h]) for h in hs)}"
        )
    two = starts[counts == 2]
    h1, h2 = order[two], order[two + 1]
    same = org[h1] == org[h2]
    if same.any():
        i = int(np.flatnonzero(same)[0])
        a, b = org[h1[i]], dst[h1[i]]
        raise MeshError(
            f"inconsistent orientation: faces {int(face_of[h1[i]])} and {int(face_of[h2[i]])} both traverse "
            f"{_edge_str(a, b)} from {int(a)} to {int(b)}"
        )


def check_used_finite(V, used):
    """MeshError naming the first vertex used by a face whose coordinates are not finite (NaN, inf).

    Unused vertices (common in scans) may hold anything: they do not enter the surface.
    """
    bad = ~np.isfinite(V).all(axis=1)
    if bad.any():
        mask = np.zeros(V.shape[0], dtype=bool)
        mask[used] = True
        hit = np.flatnonzero(bad & mask)
        if hit.size:
            v = int(hit[0])
            raise MeshError(f"vertex {v} has a non-finite coordinate: {V[v].tolist()}")


def _duplicate_face(org, face_of, hs):
    """Two faces with the same vertex cycle among the faces of the half-edges ``hs`` (one edge), or None.

    Returns ``(f, g, vertices of f)``; the cycle is compared up to rotation and direction.
    """
    faces = sorted({int(face_of[x]) for x in hs})
    cyc: dict = {}
    for f in faces:
        vs = org[face_of == f].tolist()
        k = len(vs)
        rots = [tuple(vs[i:] + vs[:i]) for i in range(k)]
        rots += [tuple(r[::-1]) for r in rots]
        key = min(rots)
        if key in cyc:
            return cyc[key][0], f, cyc[key][1]
        cyc[key] = (f, vs)
    return None



def _untagged(he):
    """The half-edges ``he`` without tags, under the default options (the same arrays, shared; ``he`` itself
    when it has neither): the topology of a :class:`QuadMesh`."""
    if not he.has_tags and he.options == Options():
        return he
    new = he.with_tags()
    new.options = Options()
    return new


def shared_halfedges(mesh, faces, n_vertices):
    """``mesh.halfedges`` (untagged, default options: :func:`_untagged`) when ``faces`` (int (m, 4)) and
    ``n_vertices`` are the faces and vertex count of ``mesh`` (a QuadMesh or an all-quad PolyMesh), else None.

    For a mesh made from the same faces (new control points, a sub-mesh that is the whole mesh): pass it as
    ``QuadMesh(vertices, faces, _halfedges=...)`` and the topology is not built again (the checks are made).

    >>> from ccproof.mesh.examples import grid
    >>> g = grid(2, 2)
    >>> shared_halfedges(g, g.faces.copy(), g.n_vertices) is g.halfedges, shared_halfedges(g, g.faces[:2], 9)
    (True, None)
    """
    he = mesh.halfedges
    F = np.asarray(faces)
    if (int(n_vertices) != he.n_vertices or F.shape != (he.n_faces, 4) or he.uniform != 4
            or not np.array_equal(F.reshape(-1), he.org)):
        return None
    return _untagged(he)


class QuadMesh:
    """An all-quad, manifold, consistently oriented control mesh (bmz04 section 2).

    Parameters
    ----------
    vertices : array_like, shape (n, 3)
        Control points p, float64.
    faces : array_like, shape (m, 4)
        0-based vertex indices of each quad, in order around the face (OBJ order). The face
        parameter (u, v) of face ``f`` puts corner ``i`` at (0,0), (1,0), (1,1), (0,1) for
        ``i = 0, 1, 2, 3`` (the ptex convention of OpenSubdiv).

    Raises
    ------
    MeshError
        If any of the checks in the module docstring fails; the message names the element.

    Examples
    --------
    >>> import numpy as np
    >>> V = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]
    >>> m = QuadMesh(V, [[0, 1, 2, 3]])
    >>> m.n_vertices, m.n_faces, int(m.is_boundary_vertex.sum())
    (4, 1, 4)
    >>> QuadMesh(V, [[0, 1, 2, 2]])
    Traceback (most recent call last):
    ...
    ccproof.errors.MeshError: face 0 repeats vertex 2: [0, 1, 2, 2]
    """

    def __init__(self, vertices, faces, *, _halfedges=None):
        V = np.array(vertices, dtype=np.float64)
        if V.ndim != 2 or V.shape[1] != 3:
            raise MeshError(f"vertices must have shape (n, 3), got {V.shape}")
        F = np.asarray(faces)
        if F.size == 0:
            raise MeshError("the mesh has no faces")
        if F.ndim != 2 or F.shape[1] != 4:
            raise MeshError(f"faces must have shape (m, 4) (all quads), got {F.shape}")
        if not np.issubdtype(F.dtype, np.integer):
            Fi = F.astype(np.int64)
            if not np.array_equal(Fi, F):
                raise MeshError("face indices must be integers")
            F = Fi
        F = np.array(F, dtype=np.int64)
        n = V.shape[0]
        out = np.flatnonzero(((F < 0) | (F >= n)).any(axis=1))
        if out.size:
            f = int(out[0])
            raise MeshError(f"face {f} has a vertex index out of range [0, {n}): {F[f].tolist()}")
        check_used_finite(V, F.reshape(-1))
        s = np.sort(F, axis=1)
        rep = np.flatnonzero((s[:, 1:] == s[:, :-1]).any(axis=1))
        if rep.size:
            f = int(rep[0])
            r = s[f][np.flatnonzero(s[f][1:] == s[f][:-1])[0]]
            raise MeshError(f"face {f} repeats vertex {int(r)}: {F[f].tolist()}")
        self.vertices = V
        self.faces = F
        self.vertices.setflags(write=False)
        self.faces.setflags(write=False)
        self._build_topology(_halfedges)

    # ------------------------------------------------------------------ construction
    @classmethod
    def from_polygons(cls, vertices, polygons, *, lines=None):
        """Build a QuadMesh from a list of polygons, rejecting any face that is not a quad.

        Parameters
        ----------
        vertices : array_like, shape (n, 3)
        polygons : sequence of sequences of int
            0-based vertex indices per face.
        lines : sequence of int, optional
            Source line number of each polygon (for error messages).

        >>> QuadMesh.from_polygons([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])
        Traceback (most recent call last):
        ...
        ccproof.errors.MeshError: face 0 has 3 vertices, not 4: ccproof needs an all-quad mesh
        """
        for f, poly in enumerate(polygons):
            if len(poly) != 4:
                where = f" (line {lines[f]})" if lines is not None else ""
                raise MeshError(
                    f"face {f}{where} has {len(poly)} vertices, not 4: ccproof needs an all-quad mesh"
                )
        faces = np.array(polygons, dtype=np.int64).reshape(-1, 4)
        return cls(vertices, faces)

    @classmethod
    def from_polymesh(cls, poly, **kwargs):
        """The all-quad manifold :class:`~ccproof.mesh.polymesh.PolyMesh` ``poly`` as a QuadMesh (``cls``): same
        vertices and faces, its :class:`~ccproof.mesh.halfedges.HalfEdges` shared (not built again).

        Every check of the constructor is made (on the shared arrays); ``kwargs`` go to the constructor of
        ``cls`` (the tags of :class:`~ccproof.apps.control_mesh.TaggedQuadMesh`). The half-edges are the
        ones :meth:`HalfEdges.from_quads` builds from the same faces (an all-quad mesh's offsets are
        ``4 f``), without ``poly``'s tags and options (a QuadMesh is untagged: a view sharing the arrays).

        Raises
        ------
        MeshError
            ``poly`` not all quads or not manifold, or a check of the constructor.

        Examples
        --------
        >>> from ccproof.mesh.polymesh import PolyMesh
        >>> p = PolyMesh([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], [[0, 1, 2, 3]])
        >>> q = QuadMesh.from_polymesh(p)
        >>> q.halfedges.twin is p.halfedges.twin, q.faces.tolist()
        (True, [[0, 1, 2, 3]])
        """
        if not poly.is_all_quads or not poly.is_manifold:
            raise MeshError("not an all-quad manifold mesh: " +
                            ("it has faces that are not quads" if not poly.is_all_quads else "it is not manifold"))
        return cls(poly.vertices, poly.indices.reshape(-1, 4), _halfedges=_untagged(poly.halfedges), **kwargs)

    def with_vertices(self, vertices):
        """Same connectivity, new control points (shape (n, 3)); the topology is re-used."""
        new = object.__new__(QuadMesh)
        new.__dict__.update(self.__dict__)
        V = np.array(vertices, dtype=np.float64)
        if V.shape != self.vertices.shape:
            raise MeshError(f"vertices must have shape {self.vertices.shape}, got {V.shape}")
        check_used_finite(V, self.faces.reshape(-1))
        V.setflags(write=False)
        new.vertices = V
        return new

    # ------------------------------------------------------------------ topology
    def _build_topology(self, he=None):
        """The fans and the checks of the module docstring on the half-edges ``he`` (those of the same faces,
        e.g. a :class:`~ccproof.mesh.polymesh.PolyMesh`'s: :meth:`from_polymesh`), built here when None or
        when they are not the half-edges of these faces (other vertex count, corners or face order)."""
        F = self.faces
        n, m = self.vertices.shape[0], F.shape[0]
        H = 4 * m
        if (he is None or he.n_vertices != n or he.org.size != H or (H and he.uniform != 4)
                or not np.array_equal(he.org, F.reshape(-1))):
            he = HalfEdges.from_quads(F, n, Options())  # (not these faces' half-edges, in this order: not taken)
        self.halfedges = he
        _check_pairing(he)
        org, twin = he.org, he.twin
        self.twin = twin
        self.edge_of_halfedge = he.edge_of
        self.edges = he.edges
        first, counts = he.edge_halfedge, he.edge_face_count
        self.edge_faces = np.full((counts.size, 2), -1, dtype=np.int64)
        self.edge_faces[:, 0] = first // 4
        self.edge_faces[counts == 2, 1] = twin[first[counts == 2]] // 4
        self.is_boundary_edge = counts == 1

        # vertices: corners, fans
        face_count = he.face_count
        unused = face_count == 0  # allowed (scans have them): no surface, no valence, indices kept
        # rot(c): next corner counter-clockwise around the same vertex = twin(prev(c))
        rot = twin[he.prv]
        nfans = he.n_fans
        if (nfans > 1).any():
            v = int(np.flatnonzero(nfans > 1)[0])
            raise MeshError(
                f"non-manifold vertex {v}: its faces form {int(nfans[v])} separate fans "
                f"(faces {sorted(set((np.flatnonzero(org == v) // 4).tolist()))})"
            )
        bnd_out = np.bincount(org[twin < 0], minlength=n)
        is_bv = bnd_out > 0
        valence = face_count + is_bv
        bad = np.flatnonzero(~is_bv & ~unused & (valence < 3))
        if bad.size:
            v = int(bad[0])
            raise MeshError(f"interior vertex {v} has valence {int(valence[v])} (needs >= 3)")
        # fan order: start at the clockwise-most corner (boundary) or the smallest corner (interior)
        start = np.full(n, H, dtype=np.int64)
        np.minimum.at(start, org, np.arange(H))
        bstart = np.flatnonzero(twin < 0)  # outgoing boundary half-edge: clockwise-most corner
        start[org[bstart]] = bstart
        ptr = np.r_[0, np.cumsum(face_count)]
        fan = np.empty(H, dtype=np.int64)
        cur = start.copy()
        for j in range(int(face_count.max())):
            idx = np.flatnonzero(face_count > j)
            fan[ptr[idx] + j] = cur[idx]
            cur[idx] = rot[cur[idx]]
        self.rot = rot
        self.fan_ptr = ptr
        self.fan_corners = fan
        self.face_count = face_count
        self.valence = valence
        self.is_boundary_vertex = is_bv
        self.is_unused_vertex = unused
        for a in (self.is_unused_vertex, self.twin, self.edge_of_halfedge, self.edges, self.edge_faces,
                  self.is_boundary_edge,
                  self.rot, self.fan_ptr, self.fan_corners, self.face_count, self.valence,
                  self.is_boundary_vertex):
            a.setflags(write=False)

    # ------------------------------------------------------------------ accessors
    @property
    def n_vertices(self):
        """Number of vertices n."""
        return self.vertices.shape[0]

    @property
    def n_faces(self):
        """Number of faces m."""
        return self.faces.shape[0]

    @property
    def n_edges(self):
        """Number of (undirected) edges."""
        return self.edges.shape[0]

    @property
    def is_regular_vertex(self):
        """bool (n,): interior of valence 4, or boundary with exactly two faces (valence 3): the scheme's regular
        valences (:data:`~ccproof.mesh.scheme.CATMARK`)."""
        v = self.valence
        return np.where(self.is_boundary_vertex, v == CATMARK.regular_boundary_valence, v == CATMARK.regular_valence)

    @property
    def extraordinary_vertices(self):
        """int (e,): interior vertices of valence != 4 (bmz04: extraordinary vertices); unused vertices are not."""
        irregular = self.valence != CATMARK.regular_valence
        return np.flatnonzero(~self.is_boundary_vertex & ~self.is_unused_vertex & irregular)

    @property
    def boundary_edges(self):
        """int (b, 2): the boundary edges, as directed along the boundary (face on the left)."""
        h = np.flatnonzero(self.twin < 0)
        return np.stack([self.faces.reshape(-1)[h], np.roll(self.faces, -1, axis=1).reshape(-1)[h]], 1)

    @property
    def bounding_box_diagonal(self):
        """Length of the diagonal of the axis-aligned bounding box of the used control points."""
        V = self.vertices[~self.is_unused_vertex] if self.is_unused_vertex.any() else self.vertices
        return float(np.linalg.norm(V.max(axis=0) - V.min(axis=0)))

    def corner_vertex(self, c):
        """Vertex of corner / origin of half-edge ``c`` (array_like of int)."""
        return self.faces.reshape(-1)[c]

    def one_ring(self, v):
        """The 1-ring of vertex ``v`` in counter-clockwise cyclic order.

        Returns
        -------
        edge_nbrs : ndarray of int, shape (valence,)
            e_0, e_1, ...: the edge neighbours. For a boundary vertex the first and the last are
            the two boundary neighbours.
        face_nbrs : ndarray of int, shape (face_count,)
            d_0, d_1, ...: the vertex of face j opposite to ``v`` (face j lies between e_j and
            e_{j+1}).
        faces : ndarray of int, shape (face_count,)
            The faces, in the same order.

        >>> import numpy as np
        >>> V = np.array([[x, y, 0.0] for y in range(3) for x in range(3)])
        >>> F = [[0, 1, 4, 3], [1, 2, 5, 4], [3, 4, 7, 6], [4, 5, 8, 7]]
        >>> e, d, f = QuadMesh(V, F).one_ring(4)
        >>> e.tolist(), d.tolist(), f.tolist()
        ([3, 1, 5, 7], [0, 2, 8, 6], [0, 1, 3, 2])
        """
        v = int(v)
        if not 0 <= v < self.n_vertices:
            raise MeshError(f"vertex {v} out of range [0, {self.n_vertices})")
        c = self.fan_corners[self.fan_ptr[v] : self.fan_ptr[v + 1]]
        f, i = c // 4, c % 4
        F = self.faces
        e = F[f, (i + 1) % 4]
        d = F[f, (i + 2) % 4]
        if self.is_boundary_vertex[v]:
            e = np.r_[e, F[f[-1], (i[-1] + 3) % 4]]
        return e, d, f

    def __repr__(self):
        return (
            f"QuadMesh({self.n_vertices} vertices, {self.n_faces} faces, "
            f"{int(self.is_boundary_edge.sum())} boundary edges, "
            f"{self.extraordinary_vertices.size} extraordinary vertices)"
        )
