"""The one topology type of ccproof: the half-edge arrays of a polygon mesh, built once with numpy.

A :class:`HalfEdges` is what OpenSubdiv's ``Vtr::Level`` is to its meshes: flat arrays, no Python
object per face. :class:`~ccproof.mesh.polymesh.PolyMesh` and :class:`~ccproof.mesh.quadmesh.QuadMesh`
build their topology through it (``mesh.halfedges``); the evaluator reads it (the compiled ring walk
reads ``org``, ``nxt``, ``prv``, ``twin``; the tagged walk the tag arrays); a level-1 all-quad mesh
of the evaluator's own step is one built from its ``(m, 4)`` faces (:meth:`HalfEdges.from_quads`).

Conventions: half-edge ``h = offsets[f] + i`` is corner i of face f, running from ``indices[h]`` to
the face's next corner (for an all-quad mesh ``h = 4 f + i``). Non-manifold edges (more than two
faces, two faces traversing it the same way, a face holding it twice, a degenerate edge ``(v, v)``)
get no twin: twins exist only across manifold edges (OpenSubdiv's ``Vtr::Level``).
"""

from __future__ import annotations

import functools
import math

import numpy as np

__all__ = ["HalfEdges", "connected_components"]


def connected_components(n, a, b):
    """Connected components of the undirected graph on ``range(n)`` with the edges ``(a[i], b[i])``.

    Hooking and pointer jumping in numpy (the mesh's fans: ``scipy.sparse.csgraph`` would cost its
    import, ~0.2 s, in every process that reads a mesh).

    Parameters
    ----------
    n : int
    a, b : ndarray of int, shape (m,)

    Returns
    -------
    ncomp : int
    label : ndarray of int64, shape (n,)
        Component of every node, numbered in the order of their smallest node (as
        ``scipy.sparse.csgraph.connected_components`` numbers them).

    Examples
    --------
    >>> ncomp, label = connected_components(6, np.array([4, 1, 5]), np.array([1, 4, 3]))
    >>> ncomp, label.tolist()
    (4, [0, 1, 2, 3, 1, 3])
    """
    lab = np.arange(n, dtype=np.int64)
    a = np.asarray(a, dtype=np.int64)
    b = np.asarray(b, dtype=np.int64)
    while a.size:
        la, lb = lab[a], lab[b]
        lo, hi = np.minimum(la, lb), np.maximum(la, lb)
        diff = lo != hi
        if not diff.any():
            break
        np.minimum.at(lab, hi[diff], lo[diff])  # hook: hi and lo are roots, lo < hi (no cycles)
        while True:  # shortcut every node to its root
            nxt = lab[lab]
            if np.array_equal(nxt, lab):
                break
            lab = nxt
    roots, label = np.unique(lab, return_inverse=True)
    return int(roots.size), label.astype(np.int64, copy=False)


class HalfEdges:
    """The half-edge arrays of a polygon mesh (any face sizes, manifold or not), with optional tags.

    Parameters
    ----------
    indices : array_like of int, shape (H,)
        The faces' vertex indices, face after face (counter-clockwise).
    offsets : array_like of int, shape (m + 1,)
        Face f is ``indices[offsets[f]:offsets[f + 1]]``.
    n_vertices : int
    options : ccproof.mesh.rules.Options, optional
        The Sdc options the tags are read under (the evaluator's keys carry them).
    edges : bool
        Keep the undirected edge arrays (else computed again on first use; see :meth:`from_quads`).

    Attributes
    ----------
    org, nxt, prv, twin, face_of, edge_of : ndarray of int64, shape (H,)
        Origin vertex, next and previous half-edge in the face, opposite half-edge (-1 on the
        boundary and across non-manifold edges), face, undirected edge.
    start, sizes : ndarray of int64, shape (m,)
        First half-edge and number of corners of every face.
    edges : ndarray of int64, shape (E, 2)
        Undirected edges ``(lo, hi)``, numbered in the order of ``lo * n + hi``.
    edge_face_count : ndarray of int64, shape (E,)
        Half-edges (face corners) on every edge.
    edge_halfedge : ndarray of int64, shape (E,)
        The smallest half-edge of every edge.
    edge_keys : ndarray of int64, shape (e,)
        Tags: ``a * n_vertices + b`` (``a < b``) of the interior edges with sharpness, sorted.
    edge_values : ndarray of float64, shape (e,)
        Their sharpness (``inf`` from 10 on, OpenSubdiv's infinite sharpness).
    vertex_values : ndarray of float64, shape (n_vertices,)
        Vertex sharpness (0 where none; ``inf`` from 10 on).

    Examples
    --------
    Two quads sharing the edge (1, 4):

    >>> he = HalfEdges([0, 1, 4, 3, 1, 2, 5, 4], [0, 4, 8], 6)
    >>> he.twin.tolist(), he.edges.shape, int(he.edge_face_count.max())
    ([-1, 7, -1, -1, -1, -1, -1, 1], (7, 2), 2)
    >>> HalfEdges.from_quads([[0, 1, 4, 3], [1, 2, 5, 4]], 6).twin.tolist() == he.twin.tolist()
    True
    """

    def __init__(self, indices, offsets, n_vertices, options=None, edges=True):
        org = np.asarray(indices, dtype=np.int64).reshape(-1)
        off = np.asarray(offsets, dtype=np.int64).reshape(-1)
        self.n_vertices = int(n_vertices)
        sizes = np.diff(off)
        H = org.size
        self.offsets, self.sizes, self.start = off, sizes, off[:-1]
        self.org = org
        self.options = options
        #: the one face size of every face (4: all quads), or 0 (mixed sizes)
        self.uniform = int(sizes[0]) if sizes.size and (sizes == sizes[0]).all() else 0
        # next and previous corner: h + 1 and h - 1, wrapped at the faces' ends (one array each, no
        # temporaries: numpy's huge-page advice makes every fresh large array cost page faults)
        self.nxt = np.arange(1, H + 1, dtype=np.int64)
        self.prv = np.arange(-1, H - 1, dtype=np.int64)
        if self.uniform:
            k = self.uniform
            self.nxt.reshape(-1, k)[:, -1] -= k
            self.prv.reshape(-1, k)[:, 0] += k
        else:
            used = sizes > 0
            first, last = off[:-1][used], off[1:][used] - 1
            self.nxt[last] = first
            self.prv[first] = last
        pairing = self._pair(full=edges)
        self.twin = pairing["twin"]
        #: every edge has one or two faces, traversed in opposite directions by different faces
        self.edge_manifold = bool(not (pairing["edge_face_count"] > 2).any() and not pairing["same"].size)
        if edges:
            self.__dict__["_pairing"] = pairing
        self.edge_keys = np.zeros(0, dtype=np.int64)
        self.edge_values = np.zeros(0, dtype=np.float64)
        self.vertex_values = None

    def _pair(self, full=True):
        """The undirected edges (sorted by ``lo * n + hi``, a stable sort of the half-edges) and the twins
        (``full=False``: the twins, the face counts and ``same`` alone). Few fresh (H,) arrays (each costs page
        faults under numpy's huge-page advice): the keys in pieces, their buffer made the twins."""
        org, n = self.org, self.n_vertices
        H = org.size
        key = _edge_keys(org, self.nxt, n)
        order = np.argsort(key, kind="stable")
        new = _run_starts(key, order)  # the first half-edge of an edge, in sorted order
        starts = np.flatnonzero(new)
        counts = np.diff(np.r_[starts, H])
        two = np.flatnonzero(counts == 2)
        h1, h2 = order[starts[two]], order[starts[two] + 1]
        if self.uniform:
            f1, f2 = h1 // self.uniform, h2 // self.uniform
        else:
            f1, f2 = self.face_of[h1], self.face_of[h2]
        same = (org[h1] == org[h2]) | (f1 == f2)  # same direction, or twice in one face
        twin = key  # (the key's buffer)
        twin.fill(-1)
        twin[h1[~same]], twin[h2[~same]] = h2[~same], h1[~same]
        del h1, h2, f1, f2
        out = {"twin": twin, "edge_face_count": counts, "same": two[same]}
        if full:
            edge_of = np.empty(H, dtype=np.int64)
            rank = np.cumsum(new, dtype=np.int64)
            rank -= 1
            edge_of[order] = rank
            del rank
            first = order[starts]
            a, b = org[first], org[self.nxt[first]]
            out.update(edge_of=edge_of, edges=np.stack([np.minimum(a, b), np.maximum(a, b)], axis=1),
                       edge_halfedge=first)
        return out

    @functools.cached_property
    def _pairing(self):
        return self._pair()

    @functools.cached_property
    def face_of(self):
        """int64 (H,): the face of every half-edge."""
        return np.repeat(np.arange(self.sizes.size, dtype=np.int64), self.sizes)

    @property
    def edge_of(self):
        return self._pairing["edge_of"]

    @property
    def edges(self):
        return self._pairing["edges"]

    @property
    def edge_face_count(self):
        return self._pairing["edge_face_count"]

    @property
    def edge_halfedge(self):
        return self._pairing["edge_halfedge"]

    @property
    def _same(self):
        return self._pairing["same"]

    @classmethod
    def from_quads(cls, faces, n_vertices, options=None, edges=True):
        """The half-edges of an all-quad mesh given as an ``(m, 4)`` array (half-edge ``4 f + i``).

        ``edges=False``: the edge arrays (``edges``, ``edge_of``, ...) are not kept but recomputed on
        first use (what the ring walk reads, ``org``, ``nxt``, ``prv``, ``twin``, costs no more memory).
        """
        F = np.asarray(faces, dtype=np.int64).reshape(-1, 4)
        return cls(F.reshape(-1), 4 * np.arange(F.shape[0] + 1, dtype=np.int64), n_vertices, options, edges)

    @classmethod
    def refined(cls, parent, options=None, edge_of_halfedge=None):
        """The half-edges of the all-quad child of one Catmull-Clark step of ``parent``, derived from its
        arrays (OpenSubdiv's ``Vtr::QuadRefinement``), equal to those paired from the child's faces.

        The child is the one of :meth:`ccproof.mesh.polymesh.PolyMesh.refine`
        (:func:`ccproof.mesh.step.catmark_operator`'s layout): vertex ``v < n`` the vertex point of v,
        ``n + k`` the edge point of edge k numbered by first occurrence (the order of the edges'
        smallest half-edges) or as ``edge_of_halfedge`` says, ``n + E + f`` the face point of face f; child
        face ``h`` (a parent
        half-edge) is ``(org h, n + k(h), n + E + f(h), n + k(prv h))``, its half-edges ``4 h + j``.
        Twins follow from the parent's (``4 h`` and ``4 nxt(twin h) + 3``, ``4 h + 1`` and
        ``4 nxt(h) + 2``); the child's edges are the halves ``(v, n + k)`` of the parent's, sorted by
        vertex then edge (one stable sort of the 2E ends), then the ``(n + k, n + E + f)``, which come sorted.

        Parameters
        ----------
        parent : HalfEdges
            A manifold mesh's: every edge with one or two faces in opposite directions, one fan at
            every vertex (ValueError otherwise: pair the child's faces instead).
        options : ccproof.mesh.rules.Options, optional
            The child's options (``parent.options`` when None).
        edge_of_halfedge : ndarray of int64, shape (H,), optional
            The edge points' numbering (``parent.edge_of``: the sorted one of
            :func:`ccproof.mesh.subdivision.child_faces`); default: by first occurrence.

        Returns
        -------
        HalfEdges
            Untagged (the caller adds the child's tags with :meth:`with_tags`).

        Examples
        --------
        >>> p = HalfEdges([0, 1, 4, 3, 1, 2, 5, 4], [0, 4, 8], 6)
        >>> c = HalfEdges.refined(p)
        >>> q = HalfEdges(c.org, c.offsets, c.n_vertices)
        >>> all(np.array_equal(getattr(c, a), getattr(q, a)) for a in ("twin", "edges", "edge_of", "fan_of_corner"))
        True
        """
        if not parent.edge_manifold or (parent.n_fans > 1).any():
            raise ValueError("HalfEdges.refined: the parent is not manifold")
        n, H, m = parent.n_vertices, parent.org.size, parent.sizes.size
        se, is_first, h1, cnt_k = _step_edges(parent, edge_of_halfedge)
        E = h1.size
        N = n + E + m
        h = np.arange(H, dtype=np.int64)
        face = h // parent.uniform if parent.uniform else parent.face_of
        corg = np.stack([parent.org, n + se, n + E + face, n + se[parent.prv]], axis=1)
        ctwin = _child_twins(parent)
        cedge, edges, efc, eh = _child_edges(parent, se, is_first, h1, cnt_k, face)
        E1 = edges.shape[0]
        label, mc = _child_fans(parent, h1, cnt_k, N)
        corg = corg.reshape(-1)
        new = object.__new__(cls)
        new.n_vertices = N
        new.offsets = 4 * np.arange(H + 1, dtype=np.int64)
        new.sizes = np.full(H, 4, dtype=np.int64)
        new.start = new.offsets[:-1]
        new.org = corg
        new.options = parent.options if options is None else options
        new.uniform = 4 if H else 0
        loc = np.arange(4 * H, dtype=np.int64) % 4
        new.nxt = np.arange(4 * H, dtype=np.int64) + np.where(loc == 3, -3, 1)
        new.prv = np.arange(4 * H, dtype=np.int64) + np.where(loc == 0, 3, -1)
        new.twin = ctwin.reshape(-1)
        new.edge_manifold = True
        new.__dict__["_pairing"] = {"twin": new.twin, "edge_of": cedge.reshape(-1), "edges": edges,
                                    "edge_face_count": efc, "edge_halfedge": eh,
                                    "same": np.zeros(0, dtype=np.int64)}
        new.__dict__["repeat_edge"] = np.zeros(E1, dtype=bool)
        new.__dict__["fan_of_corner"] = label[mc[corg]]
        new.edge_keys = np.zeros(0, dtype=np.int64)
        new.edge_values = np.zeros(0, dtype=np.float64)
        new.vertex_values = None
        return new

    def subset(self, faces):
        """The half-edges of the faces ``faces`` of this mesh, in that order: a local neighbourhood as the
        same kind of arrays (OpenSubdiv's Vtr levels of a sparse refinement are such subsets).

        The vertex labels, the options and the tag arrays are this mesh's; a half-edge keeps its twin when the
        twin's face is in the subset (-1 otherwise: the subset's boundary), so that an edge that is not
        manifold in the mesh stays without twins in the subset (the undirected edge arrays, computed on first
        use, are the subset's own). ``parent_halfedge`` (H',) and ``parent_face`` (m',) map the subset's
        half-edges and faces back to this mesh's.

        Parameters
        ----------
        faces : array_like of int
            Distinct face indices of this mesh.

        Returns
        -------
        HalfEdges

        Examples
        --------
        Of two quads sharing the edge (1, 4), the second alone has no twins; both, in either order, keep theirs:

        >>> he = HalfEdges([0, 1, 4, 3, 1, 2, 5, 4], [0, 4, 8], 6)
        >>> he.subset([1]).twin.tolist(), he.subset([1]).org.tolist()
        ([-1, -1, -1, -1], [1, 2, 5, 4])
        >>> sub = he.subset([1, 0])
        >>> sub.twin.tolist(), sub.parent_halfedge[sub.twin[3]].tolist()
        ([-1, -1, -1, 5, -1, 3, -1, -1], 1)
        """
        fs = np.asarray(faces, dtype=np.int64).reshape(-1)
        if fs.size and (fs.min() < 0 or fs.max() >= self.n_faces or np.unique(fs).size != fs.size):
            raise ValueError(f"HalfEdges.subset: faces must be distinct faces in [0, {self.n_faces})")
        sizes = self.sizes[fs]
        off = np.r_[0, np.cumsum(sizes)].astype(np.int64)
        h = np.repeat(self.start[fs] - off[:-1], sizes) + np.arange(int(off[-1]), dtype=np.int64)  # parent h
        new = type(self)(self.org[h], off, self.n_vertices, self.options, edges=False)
        # the parent's twins, where the twin's face is in the subset (its position: a sorted search of h)
        order = np.argsort(h, kind="stable")
        t = self.twin[h]
        pos = np.minimum(np.searchsorted(h, t, sorter=order), max(h.size - 1, 0)) if h.size else t
        inside = (t >= 0) & (h[order[pos]] == t) if h.size else t >= 0
        new.twin = np.where(inside, order[pos] if h.size else t, -1)
        new.__dict__.pop("_pairing", None)  # the edge arrays of the subset, recomputed on first use
        new.edge_manifold = self.edge_manifold
        new.edge_keys, new.edge_values, new.vertex_values = self.edge_keys, self.edge_values, self.vertex_values
        new.parent_halfedge, new.parent_face = h, fs
        return new

    # ------------------------------------------------------------------ tags
    def with_tags(self, edge_sharpness=None, vertex_sharpness=None, vertex_values=None):
        """The same arrays (shared, not copied) with the tags of ``edge_sharpness`` (dict ``{(a, b): s}``)
        and ``vertex_sharpness`` (dict ``{v: s}``) or ``vertex_values`` (float (n_vertices,)) as tag
        arrays (see the class docstring); sharpness on boundary or non-manifold edges is left out (sharp
        by the topology), pairs that are no edge too; an edge given as ``(a, b)`` and ``(b, a)`` takes the
        later value (as :class:`~ccproof.mesh.polymesh.PolyMesh` reads its creases)."""
        new = object.__new__(type(self))
        new.__dict__.update(self.__dict__)
        new.__dict__.pop("has_tags", None)  # (the cached arrays are shared)
        nv = self.n_vertices
        keys = np.zeros(0, dtype=np.int64)
        vals = np.zeros(0, dtype=np.float64)
        if edge_sharpness:
            ab = np.array(list(edge_sharpness.keys()), dtype=np.int64).reshape(-1, 2)
            s = np.array(list(edge_sharpness.values()), dtype=np.float64)
            e = self.edge_index_of(ab[:, 0], ab[:, 1])
            at = np.flatnonzero(e >= 0)
            order = np.argsort(e[at], kind="stable")  # by edge (= by key), in the given order within one
            es = e[at][order]
            at = at[order][np.r_[es[1:] != es[:-1], True]] if es.size else at  # the last value of each edge
            ok = s[at] > 0.0
            at = at[ok][self.twin[self.edge_halfedge[e[at[ok]]]] >= 0]
            keys = self.edges[e[at], 0] * nv + self.edges[e[at], 1]
            vals = np.where(s[at] >= 10.0, math.inf, s[at])
        new.edge_keys, new.edge_values = keys, vals
        if vertex_values is None and vertex_sharpness:
            vertex_values = np.zeros(nv, dtype=np.float64)
            vs = np.array(list(vertex_sharpness.keys()), dtype=np.int64)
            x = np.array(list(vertex_sharpness.values()), dtype=np.float64)
            ok = (x > 0.0) & (vs >= 0) & (vs < nv)
            vertex_values[vs[ok]] = np.where(x[ok] >= 10.0, math.inf, x[ok])
        elif vertex_values is not None:
            vertex_values = np.where(vertex_values >= 10.0, math.inf, np.maximum(vertex_values, 0.0))
        new.vertex_values = vertex_values
        return new

    @functools.cached_property
    def has_tags(self):
        """Edge or vertex tags present (boundary edges do not count: sharp by the topology)."""
        return bool(self.edge_keys.size or (self.vertex_values is not None and self.vertex_values.any()))

    def vertex_tags(self):
        """float64 (n_vertices,): the vertex sharpness (zeros when untagged)."""
        return self.vertex_values if self.vertex_values is not None else np.zeros(self.n_vertices)

    def edge_index_of(self, a, b):
        """The edge ids of the vertex pairs ``(a, b)`` (arrays of int, either order), -1 where no edge."""
        a, b = np.asarray(a, dtype=np.int64), np.asarray(b, dtype=np.int64)
        lo, hi = np.minimum(a, b), np.maximum(a, b)
        if not self.edges.shape[0]:
            return np.full(lo.shape, -1, dtype=np.int64)
        ek = self.edges[:, 0] * self.n_vertices + self.edges[:, 1]  # sorted (edge numbering)
        k = lo * self.n_vertices + hi
        i = np.minimum(np.searchsorted(ek, k), ek.size - 1)
        return np.where((ek[i] == k) & (lo >= 0) & (hi < self.n_vertices), i, -1)

    def edge_sharpness_at(self, a, b):
        """float64: the tag sharpness of the vertex pairs ``(a, b)`` (0 where untagged, boundary or no edge)."""
        a, b = np.asarray(a, dtype=np.int64), np.asarray(b, dtype=np.int64)
        if not self.edge_keys.size:
            return np.zeros(np.broadcast(a, b).shape)
        lo, hi = np.minimum(a, b), np.maximum(a, b)
        k = lo * self.n_vertices + hi
        i = np.minimum(np.searchsorted(self.edge_keys, k), self.edge_keys.size - 1)
        return np.where((self.edge_keys[i] == k) & (lo >= 0) & (hi < self.n_vertices), self.edge_values[i], 0.0)

    # ------------------------------------------------------------------ sizes
    @property
    def n_faces(self):
        return int(self.sizes.size)

    @property
    def faces(self):
        """int64 (m, 4): the faces of an all-quad mesh (a view of ``org``); ValueError otherwise."""
        if self.org.size != 4 * self.sizes.size or not (self.sizes == 4).all():
            raise ValueError("not an all-quad mesh")
        return self.org.reshape(-1, 4)

    @functools.cached_property
    def face_count(self):
        """int64 (n_vertices,): faces (corners) at every vertex."""
        return np.bincount(self.org, minlength=self.n_vertices)

    # ------------------------------------------------------------------ OpenSubdiv's non-manifold elements
    @functools.cached_property
    def repeat_edge(self):
        """bool (E,): degenerate edges ``(v, v)`` and edges a face holds twice (OpenSubdiv gives each such
        occurrence an edge of its own with one face, a boundary edge)."""
        m = max(self.n_faces, 1)
        degenerate = self.edges[:, 0] == self.edges[:, 1]
        fe = np.unique(self.edge_of * m + self.face_of, return_counts=True)
        held_twice = np.zeros(self.edges.shape[0], dtype=bool)
        held_twice[fe[0][fe[1] > 1] // m] = True
        return degenerate | held_twice

    @functools.cached_property
    def is_nonmanifold_edge(self):
        """bool (E,): more than two faces, two faces in the same direction, or a :attr:`repeat_edge`."""
        nm = self.edge_face_count > 2
        nm[self._same] = True
        return nm | self.repeat_edge

    @functools.cached_property
    def fan_of_corner(self):
        """int64 (H,): the fan of every corner (``rot(c) = twin(prv(c))`` joins the corners of a fan:
        OpenSubdiv's spans between singular edges), numbered in the order of their smallest corner."""
        rot = self.twin[self.prv]
        ok = np.flatnonzero(rot >= 0)
        return connected_components(self.org.size, ok, rot[ok])[1]

    @functools.cached_property
    def n_fans(self):
        """int64 (n_vertices,): fans of faces at every vertex (0 for an unused vertex)."""
        comp = self.fan_of_corner
        ncomp = int(comp.max()) + 1 if comp.size else 0
        vertex_of_comp = np.zeros(ncomp, dtype=np.int64)
        vertex_of_comp[comp] = self.org
        return np.bincount(vertex_of_comp, minlength=self.n_vertices)

    @functools.cached_property
    def is_nonmanifold_vertex(self):
        """bool (n_vertices,): several fans, or an end of a non-manifold edge."""
        nm = self.n_fans > 1
        nm[self.edges[self.is_nonmanifold_edge].reshape(-1)] = True
        return nm

    @functools.cached_property
    def is_boundary_vertex(self):
        """bool (n_vertices,): an end of an edge with one face."""
        one = self.edge_face_count[self.edge_of] == 1
        return np.bincount(self.org[one], minlength=self.n_vertices) > 0

    @functools.cached_property
    def vertex_corners(self):
        """``(ptr, corners)``: the corners of vertex v are ``corners[ptr[v]:ptr[v + 1]]``, increasing."""
        ptr = np.r_[0, np.cumsum(self.face_count)].astype(np.int64)
        return ptr, np.argsort(self.org, kind="stable")

    def faces_around(self, vertices):
        """int64: the faces at any of ``vertices`` (sorted, distinct)."""
        ptr, corners = self.vertex_corners
        v = np.asarray(vertices, dtype=np.int64)
        if v.size == 1:
            return np.unique(self.face_of[corners[ptr[v[0]]:ptr[v[0] + 1]]])
        cs = np.concatenate([corners[ptr[x]:ptr[x + 1]] for x in v.tolist()])
        return np.unique(self.face_of[cs])


_CHUNK = 1 << 15  # (H,) work in pieces this long: small temporaries, reused by the allocator


def _edge_keys(org, nxt, n):
    """int64 (H,): ``lo * n + hi`` of every half-edge's ends, computed in pieces (no (H,) temporaries)."""
    key = np.empty(org.size, dtype=np.int64)
    for s in range(0, org.size, _CHUNK):
        o, d = org[s:s + _CHUNK], org[nxt[s:s + _CHUNK]]
        k = np.minimum(o, d)
        k *= n
        k += np.maximum(o, d, out=d)
        key[s:s + _CHUNK] = k
    return key


def _run_starts(key, order):
    """bool (H,): ``key[order[i]] != key[order[i - 1]]`` (True at 0), computed in pieces."""
    new = np.empty(key.size, dtype=bool)
    new[:1] = True
    for s in range(0, key.size, _CHUNK):
        ks = key[order[s:s + _CHUNK + 1]]
        np.not_equal(ks[1:], ks[:-1], out=new[s + 1:s + 1 + ks.size - 1])
    return new


def _step_edges(parent, edge_of_halfedge=None):
    """(se, is_first, h1, cnt_k) of :meth:`HalfEdges.refined`: the parent's edges numbered by first occurrence
    (``catmark_operator``'s numbering: k = rank of the smallest half-edge) or by ``edge_of_halfedge``; ``se``
    the step's edge of every half-edge, ``is_first`` whether a half-edge is its edge's smallest, ``h1`` and
    ``cnt_k`` the smallest half-edge and the face count of step edge k."""
    first, cnt = parent.edge_halfedge, parent.edge_face_count
    E, H = first.size, parent.org.size
    is_first = np.zeros(H, dtype=bool)
    is_first[first] = True
    if edge_of_halfedge is None:
        renum = (np.cumsum(is_first) - 1)[first]
        se = renum[parent.edge_of]  # (H,): the step's edge of every half-edge
    else:
        se = np.asarray(edge_of_halfedge, dtype=np.int64).reshape(-1)
        renum = se[first]
    h1 = np.empty(E, dtype=np.int64)
    h1[renum] = first
    cnt_k = np.empty(E, dtype=np.int64)
    cnt_k[renum] = cnt
    return se, is_first, h1, cnt_k


def _child_twins(parent):
    """(H, 4) twins of the child's half-edges ``4 h + j``: across the parent's edges (the halves at org h)
    and inside the parent's face."""
    nxt, prv, twin = parent.nxt, parent.prv, parent.twin
    t, tp = twin, twin[prv]
    return np.stack([np.where(t >= 0, 4 * nxt[np.maximum(t, 0)] + 3, -1), 4 * nxt + 2, 4 * prv + 1,
                     np.where(tp >= 0, 4 * tp, -1)], axis=1)


def _child_edges(parent, se, is_first, h1, cnt_k, face):
    """(edge of each child half-edge (H, 4), the child's edges (E1, 2), their face counts, their smallest
    half-edges) of :meth:`HalfEdges.refined`."""
    n, H, E = parent.n_vertices, parent.org.size, h1.size
    org, nxt, prv = parent.org, parent.nxt, parent.prv
    h = np.arange(H, dtype=np.int64)
    # edges of the first kind: (v, n + k), v an end of parent edge k; sorted by (v, k)
    ends = np.stack([org[h1], org[nxt[h1]]], axis=1).reshape(-1)  # item 2 k + s: end s of edge k
    order = np.argsort(ends, kind="stable")  # by vertex, then (stable) by edge
    rank1 = np.empty(2 * E, dtype=np.int64)
    rank1[order] = np.arange(2 * E, dtype=np.int64)
    a_end, b_end = rank1[0::2], rank1[1::2]  # the child edge (a_k, n + k), and (b_k, n + k)
    # edges of the second kind: (n + k, n + E + f), by k then f (the faces' order is their half-edges')
    start2 = 2 * E + np.r_[0, np.cumsum(cnt_k)[:-1]].astype(np.int64)
    ex2 = start2[se] + ~is_first  # the second kind of edge through the edge point of h, in h's face
    p = prv
    cedge = np.stack([np.where(is_first, a_end[se], b_end[se]), ex2, ex2[p],
                      np.where(is_first[p], b_end[se[p]], a_end[se[p]])], axis=1)
    E1 = 2 * E + H
    edges = np.empty((E1, 2), dtype=np.int64)
    edges[:2 * E, 0] = ends[order]
    edges[:2 * E, 1] = n + order // 2
    edges[cedge[:, 1], 0] = n + se
    edges[cedge[:, 1], 1] = n + E + face
    efc = np.full(E1, 2, dtype=np.int64)
    efc[:2 * E] = cnt_k[order // 2]
    eh = np.full(E1, 4 * H, dtype=np.int64)
    for j in range(4):  # (an edge has at most one half-edge of each column j: distinct indices)
        col = cedge[:, j]
        eh[col] = np.minimum(eh[col], 4 * h + j)
    return cedge, edges, efc, eh


def _child_fans(parent, h1, cnt_k, N):
    """(fan label of each child corner by smallest corner, smallest corner of each of the N child vertices):
    one fan per child vertex (a manifold parent's child is manifold)."""
    n, H, E = parent.n_vertices, parent.org.size, h1.size
    org, nxt, twin = parent.org, parent.nxt, parent.twin
    h = np.arange(H, dtype=np.int64)
    mc = np.full(N, 4 * H, dtype=np.int64)
    pmin = np.full(n, H, dtype=np.int64)
    np.minimum.at(pmin, org, h)
    used = pmin < H
    mc[:n][used] = 4 * pmin[used]
    ek = np.minimum(4 * h1 + 1, 4 * nxt[h1] + 3)
    two = cnt_k == 2
    h2 = np.where(two, twin[h1], 0)
    mc[n:n + E] = np.where(two, np.minimum(ek, np.minimum(4 * h2 + 1, 4 * nxt[h2] + 3)), ek)
    mc[n + E:] = 4 * parent.start + 2
    first_c = np.zeros(4 * H, dtype=bool)
    first_c[mc[mc < 4 * H]] = True
    label = np.cumsum(first_c) - 1
    return label, mc
