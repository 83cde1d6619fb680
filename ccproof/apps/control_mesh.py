"""The control mesh of the applications: every mesh ``ccproof eval`` reads, as an all-quad mesh (the file side:
reading, vertex copies merged back, labels, writing: :mod:`ccproof.apps.control_file`).

ARAP (hsh10) and the dynamic surfaces (qmv98) work on all-quad Catmull-Clark control meshes. A mesh with
triangles or n-gons (any format of :func:`ccproof.mesh.io.read_mesh`: OBJ, PLY, OFF, STL, VTK, ...) is
subdivided once with the Catmull-Clark rules first: every n-gon becomes n quads and the limit surface is
unchanged (it is the step every Catmull-Clark evaluator takes on such a mesh anyway). Vertices that no face
uses (common in scans) are dropped, the others keep their order.

Meshes with OpenSubdiv tags (creases, corners, holes, boundary modes) and non-manifold meshes (which
OpenSubdiv, and :attr:`~ccproof.mesh.polymesh.PolyMesh.manifold`, turn into tagged manifold ones: their
non-manifold edges and vertices infinitely sharp) become a :class:`TaggedQuadMesh` (edge and vertex
sharpness, hole faces), subdivided by the rules of :mod:`ccproof.mesh.rules` (OpenSubdiv's Sdc):

* :func:`tagged_step` is one step as a sparse operator on any quad mesh with those tags (the chart levels
  of ARAP, :func:`subdivide_control`): :func:`ccproof.mesh.step.catmark_operator`, the one vectorized step.
  Infinite tags are *stationary* (the same rules at every level: an infinitely sharp edge's point is its
  midpoint, a vertex with two sharp edges takes the crease rule ``(3/4) V + (1/8)(e0 + e1)``, with more or a
  sharp vertex it stays, with one (a dart) or none the smooth rule); semi-sharp tags (0 < s < 10,
  ``CREASE_UNIFORM``: s - 1 per step) blend these with Sdc's fractional weights.
* Limit positions: closed-form masks at stationary vertices (:mod:`ccproof.apps.arap.samples`), and
  :func:`moving_limit_rows` (the fan subdivided until stationary, then the exact eigenvector) elsewhere.
* ``CREASE_CHAIKIN`` semi-sharp tags (Chaikin's rule at a vertex needs all the edges at both ends of an
  edge) are resolved by global steps (:meth:`PolyMesh.refine <ccproof.mesh.polymesh.PolyMesh.refine>`,
  ceil(s) of them, at most :data:`MAX_TAGGED_FACES` faces); ``EDGE_AND_CORNER`` corners and
  ``TRI_SUB_SMOOTH`` act at level 0 only: they are made explicit (sharp vertices) or taken by the first
  global step.

The limit surface is the one ``ccproof eval`` evaluates (tests/apps/arap/test_arap_tagged.py compares them).
"""

from __future__ import annotations

import functools
import math

import numpy as np

from ccproof.errors import MeshError
from ccproof.mesh import QuadMesh

#: OpenSubdiv's infinite sharpness (Sdc::Crease::SHARPNESS_INFINITE)
INFINITE = 10.0

__all__ = ["TaggedQuadMesh", "tagged_step", "subdivide_control", "refuse_tags", "edge_values", "vertex_rules",
           "moving_limit_rows", "MAX_TAGGED_FACES", "copy_labels"]

#: most faces the global tagged steps of :func:`~ccproof.apps.control_file.read_control_mesh` may make
#: (Python rules: ~50 us a face)
MAX_TAGGED_FACES = 200_000


def _pair_keys(pairs, n):
    p = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    return np.minimum(p[:, 0], p[:, 1]) * n + np.maximum(p[:, 0], p[:, 1])


def edge_values(mesh: QuadMesh, pairs, values=math.inf, label=None, n_labels=None):
    """Float (n_edges,) over ``mesh.edges``: the sharpness of the interior edges among ``pairs``, 0 elsewhere.

    Parameters
    ----------
    mesh : QuadMesh
    pairs : array_like of int, shape (k, 2)
        Edges as pairs of vertex labels.
    values : float or array_like of float, shape (k,)
    label : ndarray of int, shape (n,), optional
        The label of every vertex of ``mesh`` (default: its index), ``n_labels`` their range.

    Examples
    --------
    >>> from ccproof.mesh.examples import grid
    >>> g = grid(2, 2)
    >>> s = edge_values(g, [[1, 4], [0, 1]], [2.5, 3.0])      # (0, 1) is a boundary edge: sharp anyway
    >>> sorted(s[s > 0].tolist())
    [2.5]
    """
    out = np.zeros(mesh.n_edges)
    pairs = np.asarray(pairs if pairs is not None else [], dtype=np.int64).reshape(-1, 2)
    if not pairs.size:
        return out
    if label is None:
        label, n_labels = np.arange(mesh.n_vertices), mesh.n_vertices
    vals = np.broadcast_to(np.asarray(values, dtype=np.float64), (pairs.shape[0],))
    ref = _pair_keys(pairs, n_labels)
    order = np.argsort(ref, kind="stable")
    ref, vals = ref[order], vals[order]
    key = _pair_keys(label[mesh.edges], n_labels)
    pos = np.minimum(np.searchsorted(ref, key), ref.size - 1)
    hit = (ref[pos] == key) & ~mesh.is_boundary_edge
    out[hit] = vals[pos[hit]]
    return out


class TaggedQuadMesh(QuadMesh):
    """An all-quad control mesh with edge and vertex sharpness and hole faces (module docstring).

    Parameters
    ----------
    vertices : array_like, shape (n, 3)
    faces : array_like of int, shape (m, 4)
    creases : (pairs, values), optional
        Sharp edges as vertex pairs (k, 2) and their sharpness (scalar or (k,); ``inf`` infinitely sharp,
        OpenSubdiv's >= 10). Boundary edges are infinitely sharp anyway.
    corners : (vertices, values), optional
        Vertex sharpness.
    holes : array_like of int, optional
        Hole faces: part of the topology (the rules of their neighbours do not change), not of the surface.

    Attributes
    ----------
    edge_sharpness : ndarray, shape (n_edges,)
        Over ``edges``: 0 smooth, ``inf`` infinitely sharp (values >= 10 are stored as ``inf``).
    vertex_sharpness : ndarray, shape (n,)
    hole : ndarray of bool, shape (m,)
    global_steps : int
        The Catmull-Clark steps :func:`~ccproof.apps.control_file.read_control_mesh` took on the file (0 otherwise).
    file_vertex : ndarray of int64, shape (n,), or None
        On the split mesh of a non-manifold file (:func:`~ccproof.apps.control_file.read_control_mesh`): the
        vertex every control vertex is a copy of, labels ``0 .. r-1`` (without global steps the file's used
        vertices in the file's order; after them the vertices of the file's refined mesh, :func:`copy_labels`). None
        when every control vertex is its own (a manifold file, or any other construction).

    Examples
    --------
    >>> from ccproof.mesh.examples import grid
    >>> g = grid(2, 2)
    >>> t = TaggedQuadMesh(g.vertices, g.faces, creases=([[1, 4], [4, 7]], [2.0, 12.0]), holes=[3])
    >>> sorted(t.edge_sharpness[t.edge_sharpness > 0].tolist()), int(t.hole.sum()), t.has_tags
    ([2.0, inf], 1, True)
    """

    def __init__(self, vertices, faces, *, creases=None, corners=None, holes=None, _halfedges=None):
        super().__init__(vertices, faces, _halfedges=_halfedges)
        es = np.zeros(self.n_edges) if creases is None else edge_values(self, *creases)
        self.edge_sharpness = np.where(es >= INFINITE, math.inf, es)
        vs = np.zeros(self.n_vertices)
        if corners is not None:
            v = np.asarray(corners[0], dtype=np.int64)
            vs[v] = np.broadcast_to(np.asarray(corners[1], dtype=np.float64), v.shape)
        self.vertex_sharpness = np.where(vs >= INFINITE, math.inf, vs)
        self.hole = np.zeros(self.n_faces, dtype=bool)
        if holes is not None:
            self.hole[np.asarray(holes, dtype=np.int64)] = True
        self.global_steps = 0
        self.file_vertex = None

    @property
    def has_tags(self):
        return bool((self.edge_sharpness > 0).any() or (self.vertex_sharpness > 0).any() or self.hole.any())

    def with_vertices(self, vertices):
        """Same connectivity and tags, new control points (shape (n, 3))."""
        plain = QuadMesh.with_vertices(self, vertices)
        new = object.__new__(TaggedQuadMesh)
        new.__dict__.update(plain.__dict__)
        return new

    def __repr__(self):
        return ("Tagged" + super().__repr__()[:-1] + f", {int((self.edge_sharpness > 0).sum())} sharp edges, "
                f"{int((self.vertex_sharpness > 0).sum())} sharp vertices, {int(self.hole.sum())} holes)")


def refuse_tags(mesh, name):
    """Raise :class:`~ccproof.errors.MeshError` naming the first tag of a control mesh that still has some.

    For a consumer that uses the untagged rules only (none of the commands now). Vertex numbers are the
    control mesh's (the file's without its unused vertices, when no step was taken).

    Examples
    --------
    >>> from ccproof.mesh.examples import grid
    >>> g = grid(2, 2)
    >>> refuse_tags(g, "g.obj")            # a plain QuadMesh: nothing to refuse
    >>> refuse_tags(TaggedQuadMesh(g.vertices, g.faces, holes=[3]), "g.obj")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    ccproof.errors.MeshError: g.obj: face 3 is a hole: this command uses the untagged Catmull-Clark rules (...)
    """
    if not getattr(mesh, "has_tags", False):
        return
    if (mesh.edge_sharpness > 0).any():
        e = int(np.flatnonzero(mesh.edge_sharpness > 0)[0])
        a, b = mesh.edges[e].tolist()
        what = f"edge ({a}, {b}) is sharp ({mesh.edge_sharpness[e]:g}: a crease tag, or a non-manifold edge)"
    elif (mesh.vertex_sharpness > 0).any():
        v = int(np.flatnonzero(mesh.vertex_sharpness > 0)[0])
        what = f"vertex {v} is a sharp corner ({mesh.vertex_sharpness[v]:g})"
    else:
        what = f"face {int(np.flatnonzero(mesh.hole)[0])} is a hole"
    raise MeshError(f"{name}: {what}: this command uses the untagged Catmull-Clark rules (`ccproof arap` and "
                    "`ccproof eval` take tags)")


def tags_of(mesh):
    """``(edge_sharpness, vertex_sharpness)`` of a control mesh (zeros on a plain :class:`QuadMesh`)."""
    es = getattr(mesh, "edge_sharpness", None)
    if es is None or not isinstance(es, np.ndarray):
        return np.zeros(mesh.n_edges), np.zeros(mesh.n_vertices)
    return es, mesh.vertex_sharpness


def _semi(x):
    return (x > 0) & np.isfinite(x)


def vertex_rules(mesh: QuadMesh, edge_sharpness, vertex_sharpness):
    """The vertex rules of a tagged quad mesh, and which vertices are stationary.

    Parameters
    ----------
    mesh : QuadMesh
    edge_sharpness : ndarray, shape (n_edges,)
        Tagged interior edges (boundary edges count as infinitely sharp in any case).
    vertex_sharpness : ndarray, shape (n,)

    Returns
    -------
    n_sharp : ndarray of int64, shape (n,)
        Sharp edges (boundary or tagged) at every vertex.
    corner, crease, dart : ndarray of bool, shape (n,)
        Sdc's vertex rule: a sharp vertex or three or more sharp edges: corner; two: crease; one: dart
        (the smooth vertex rule, with a midpoint on its sharp edge).
    crease_nbrs : ndarray of int64, shape (n, 2)
        The far ends of the two sharp edges of a crease vertex (-1 elsewhere).
    stationary : ndarray of bool, shape (n,)
        No semi-sharp edge at the vertex and no semi-sharp vertex sharpness: its rule and those of its edges
        are the same at every further level (then the closed-form limit masks hold).

    Examples
    --------
    The middle vertex 4 of a 2 x 2 grid with a crease through it; vertex 1 is on the boundary and on
    the crease (three sharp edges: a corner):

    >>> from ccproof.mesh.examples import grid
    >>> g = grid(2, 2)
    >>> ns, corner, crease, dart, nb, st = vertex_rules(g, edge_values(g, [[1, 4], [4, 7]]), np.zeros(9))
    >>> bool(crease[4]), sorted(nb[4].tolist()), bool(corner[1]), int(ns[4]), bool(st.all())
    (True, [1, 7], True, 2, True)
    """
    n = mesh.n_vertices
    a, b = mesh.edges[:, 0], mesh.edges[:, 1]
    sh = mesh.is_boundary_edge | (edge_sharpness > 0)
    ns = np.bincount(a[sh], minlength=n) + np.bincount(b[sh], minlength=n)
    corner = (vertex_sharpness > 0) | (ns >= 3)
    crease = ~corner & (ns == 2)
    dart = ~corner & (ns == 1)
    src = np.r_[a[sh], b[sh]]
    tgt = np.r_[b[sh], a[sh]]
    order = np.argsort(src, kind="stable")
    src, tgt = src[order], tgt[order]
    start = np.searchsorted(src, np.arange(n))
    nb = np.full((n, 2), -1, dtype=np.int64)
    cv = np.flatnonzero(crease)
    nb[cv, 0] = tgt[start[cv]]
    nb[cv, 1] = tgt[start[cv] + 1]
    semi = _semi(edge_sharpness)
    moving = _semi(vertex_sharpness)
    moving[a[semi]] = True
    moving[b[semi]] = True
    return ns, corner, crease, dart, nb, ~moving


def _fan_complex(mesh: QuadMesh, v, edge_sharpness, vertex_sharpness):
    """The faces around ``v`` as a :class:`ccproof.mesh.rules.Complex` in local labels (``v`` is label 0),
    with the sharpness of the edges at ``v`` and of ``v``; and the local -> global vertex map."""
    from ccproof.mesh.rules import Complex, Options

    c = mesh.fan_corners[mesh.fan_ptr[v]: mesh.fan_ptr[v] + mesh.face_count[v]]
    F = mesh.faces[(c // 4)[:, None], ((c % 4)[:, None] + np.arange(4)[None, :]) % 4]  # each face from v
    glob, loc = np.unique(F, return_inverse=True)
    order = np.argsort(glob != v, kind="stable")  # v -> label 0
    rank = np.empty_like(order)
    rank[order] = np.arange(order.size)
    faces = rank[loc.reshape(F.shape)]
    gl = glob[order]
    tags = {}
    nbrs = np.r_[F[:, 1], F[:, 3]]
    pos = mesh.halfedges.edge_index_of(np.full(nbrs.size, v), nbrs)  # the edges (v, u): mesh.edges' numbering
    for u, e in zip(nbrs.tolist(), pos.tolist()):
        s = float(edge_sharpness[e])
        if s > 0 and not mesh.is_boundary_edge[e]:
            lu = int(rank[np.searchsorted(glob, u)])
            tags[(0, lu)] = s
    vs = float(vertex_sharpness[v])
    cx = Complex(faces.tolist(), tags, {0: vs} if vs > 0 else {}, Options(), level=1, n_vertices=gl.size)
    return cx, gl


def tagged_step(mesh: QuadMesh, edge_sharpness=None, vertex_sharpness=None):
    """One Catmull-Clark step of a quad mesh with edge and vertex sharpness, as a sparse operator.

    :func:`ccproof.mesh.step.catmark_operator` (the one vectorized step; ``CREASE_UNIFORM``, boundary
    ``EDGE_ONLY``) in the quad mesh's edge numbering: a sharp edge's point is its midpoint (blended with the
    smooth rule below sharpness 1), a crease vertex (two sharp edges, boundary edges counted)
    ``(3/4) V + (1/8)(e0 + e1)`` along them, a corner (a sharp vertex, three or more sharp edges) stays,
    with Sdc's fractional weight where the rule changes. Without tags the operator is
    :func:`~ccproof.mesh.subdivision_matrix`'s.

    Parameters
    ----------
    mesh : QuadMesh
        n vertices, E edges, m faces.
    edge_sharpness : ndarray, shape (E,), optional
    vertex_sharpness : ndarray, shape (n,), optional
        Default: :func:`tags_of` ``(mesh)``.

    Returns
    -------
    S : scipy.sparse.csr_matrix, shape (n + E + m, n)
        Rows laid out as :func:`ccproof.mesh.child_faces` numbers the new vertices.
    child_creases : (ndarray of int64, shape (k, 2), ndarray, shape (k,))
        The halves of the sharp edges in the new vertex numbers, and their sharpness (``CREASE_UNIFORM``:
        ``s - 1``; 0 dropped).
    child_corners : (ndarray of int64, shape (j,), ndarray, shape (j,))

    Examples
    --------
    A crease through the middle of a 2 x 2 grid: the edge point of edge (1, 4) is the midpoint, the
    crease vertex 4 moves along the crease only; with sharpness 0.5 the rules blend:

    >>> from ccproof.mesh.examples import grid
    >>> g = grid(2, 2)
    >>> S, (ce, cs), _ = tagged_step(g, edge_values(g, [[1, 4], [4, 7]]), np.zeros(9))
    >>> e = int(np.flatnonzero((np.sort(g.edges, axis=1) == [1, 4]).all(axis=1))[0])
    >>> S[9 + e].toarray()[0, [1, 4]].tolist(), S[4].toarray()[0, [1, 4, 7]].tolist(), ce.shape, cs.tolist()
    ([0.5, 0.5], [0.125, 0.75, 0.125], (4, 2), [inf, inf, inf, inf])
    >>> S, (ce, cs), _ = tagged_step(g, edge_values(g, [[1, 4], [4, 7]], 0.5), np.zeros(9))
    >>> S[9 + e].toarray()[0, [1, 4]].tolist(), ce.shape
    ([0.4375, 0.4375], (0, 2))
    """
    from ccproof.mesh.step import catmark_operator

    if edge_sharpness is None:
        edge_sharpness, vertex_sharpness = tags_of(mesh)
    es = np.asarray(edge_sharpness, dtype=np.float64)
    vs = np.asarray(vertex_sharpness, dtype=np.float64)
    n = mesh.n_vertices
    st = catmark_operator(n, mesh.faces.reshape(-1), np.full(mesh.n_faces, 4, dtype=np.int64),
                          halfedges=mesh.halfedges, edge_of_halfedge=mesh.edge_of_halfedge, edge_sharpness=es,
                          vertex_sharpness=vs)
    pairs, cs = st.child_creases
    tagged = es[pairs[:, 1] - n] > 0  # the halves of the tagged edges (boundary edges are sharp anyway)
    return st.S, (pairs[tagged], cs[tagged]), st.child_corners


@functools.lru_cache(maxsize=4096)
def _ring_limit(faces, edge_tags, vertex_tag):
    """Exact limit mask (floats, one weight per ring label) of label 0 of a fan ``faces`` (each ``(0, a, d, b)``)
    with the sharpness ``edge_tags`` (``((0, a), s), ...``) of its edges and ``vertex_tag`` of 0."""
    import flint

    from ccproof.mesh.rules import Complex, Options, refine_complex

    N = 1 + max(max(f) for f in faces)
    M = flint.fmpq_mat(N, N, [int(i == j) for i in range(N) for j in range(N)])
    tags, vs = dict(edge_tags), vertex_tag
    for _ in range(64):  # sharpness < 10 decays by 1 per step
        cx = Complex(list(faces), tags, {0: vs} if vs > 0 else {}, Options(), level=1, n_vertices=N)
        inc = [e for e, h in enumerate(cx.edges) if cx.org[h] == 0 or cx.dst(h) == 0]
        st, _, ces, cvs = refine_complex(cx, vertices=[0], edges=inc)
        nv, ne = cx.n_vertices, len(cx.edges)
        child = {0: 0}  # ring label -> its child in the child ring (vertex, edge and face points)
        for g, f in enumerate(faces):
            for x, c in ((f[1], nv + cx.edge_index[(0, f[1])]), (f[3], nv + cx.edge_index[(0, f[3])]),
                         (f[2], nv + ne + g)):
                if child.setdefault(x, c) != c:
                    raise MeshError(f"ring vertex {x} of a fan plays two parts (a fan whose faces share a far corner)")
        A = flint.fmpq_mat(N, N)
        for x in range(N):
            for j, w in st[child[x]].items():
                A[x, j] = w
        if all(t == 0 or math.isinf(t) for t in tags.values()) and (vs == 0 or math.isinf(vs)):
            Bt = (A - flint.fmpq_mat(N, N, [int(i == j) for i in range(N) for j in range(N)])).transpose()
            for j in range(N):
                Bt[N - 1, j] = 1
            lvec = Bt.solve(flint.fmpq_mat(N, 1, [0] * (N - 1) + [1]))
            l_row = flint.fmpq_mat(1, N, [lvec[i, 0] for i in range(N)]) * M
            num, den = l_row.numer_denom()
            q = int(den)
            return tuple(int(p) / q for p in num.entries())
        M = A * M
        tags = {(0, f): ces.get((0, nv + cx.edge_index[(0, f)]), 0.0) for (_, f) in tags}
        tags = {k: t for k, t in tags.items() if t > 0}
        vs = cvs.get(0, 0.0)
    raise MeshError("a sharpness that does not decay (internal error)")


def moving_limit_rows(mesh: QuadMesh, verts, edge_sharpness, vertex_sharpness):
    """Exact limit masks of vertices with semi-sharp tags (not stationary), as sparse rows.

    The vertex's fan is subdivided with the rules of :mod:`ccproof.mesh.rules` (``CREASE_UNIFORM``: its
    ring's next ring depends only on its own rule and its edges') until its tags are 0 or infinite, then the
    stationary ring matrix's exact left eigenvector of eigenvalue 1 is applied; the product is exact
    (rationals), rounded once.

    Parameters
    ----------
    mesh : QuadMesh
    verts : array_like of int, shape (k,)
    edge_sharpness, vertex_sharpness : ndarray
        As in :func:`tagged_step`.

    Returns
    -------
    scipy.sparse.csr_matrix, shape (k, n)

    Examples
    --------
    The middle of a 2 x 2 grid with a crease of sharpness 1 through it: after one step the crease is smooth,
    so the limit lies between the crease mask's ``(e0 + 4 V + e1) / 6`` and the smooth mask's:

    >>> from ccproof.mesh.examples import grid
    >>> g = grid(2, 2)
    >>> R = moving_limit_rows(g, [4], edge_values(g, [[1, 4], [4, 7]], 1.0), np.zeros(9)).toarray()[0]
    >>> round(float(R.sum()), 15), bool(4 / 9 < R[4] < 4 / 6), bool(R[1] > R[3])
    (1.0, True, True)
    """
    import scipy.sparse as sp

    verts = np.asarray(verts, dtype=np.int64)
    rows, cols, vals = [], [], []
    for r, v in enumerate(verts.tolist()):
        cx, gl = _fan_complex(mesh, v, edge_sharpness, vertex_sharpness)
        key = tuple(sorted(cx.edge_sharpness.items()))
        mask = _ring_limit(tuple(cx.faces), key, float(cx.vertex_sharpness.get(0, 0.0)))
        rows.append(np.full(gl.size, r))
        cols.append(gl)
        vals.append(np.asarray(mask))
    if not rows:
        return sp.csr_matrix((0, mesh.n_vertices))
    return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                         shape=(verts.size, mesh.n_vertices))


def subdivide_control(mesh: QuadMesh) -> QuadMesh:
    """One Catmull-Clark step of a control mesh, tags carried (:func:`tagged_step`; holes to their children).

    Parameters
    ----------
    mesh : QuadMesh or TaggedQuadMesh

    Returns
    -------
    QuadMesh or TaggedQuadMesh
        Child ``4 f + i`` at corner ``i`` of face ``f`` (:func:`ccproof.mesh.child_faces`); a
        ``file_vertex`` labelling carried to the children (:func:`copy_labels`).

    Examples
    --------
    >>> from ccproof.mesh.examples import grid
    >>> g = grid(2, 2)
    >>> t = subdivide_control(TaggedQuadMesh(g.vertices, g.faces, creases=([[1, 4], [4, 7]], 1.5), holes=[0]))
    >>> t.n_faces, t.edge_sharpness[t.edge_sharpness > 0].tolist(), int(t.hole.sum())
    (16, [0.5, 0.5, 0.5, 0.5], 4)
    """
    from ccproof.mesh import child_faces, subdivide
    from ccproof.mesh.halfedges import HalfEdges

    if not isinstance(mesh, TaggedQuadMesh):
        return subdivide(mesh)
    S, creases, corners = tagged_step(mesh)
    he = HalfEdges.refined(mesh.halfedges, edge_of_halfedge=mesh.edge_of_halfedge)  # derived, not paired again
    child = TaggedQuadMesh(S @ mesh.vertices, child_faces(mesh), creases=creases, corners=corners,
                           holes=np.flatnonzero(np.repeat(mesh.hole, 4)), _halfedges=he)
    lab = getattr(mesh, "file_vertex", None)
    if lab is not None:  # the children of the copies that are one vertex of the refined file
        import scipy.sparse as sp

        E = sp.csr_matrix((np.ones(lab.size), (np.arange(lab.size), lab)))
        child.file_vertex = copy_labels(S @ E, kinds=(mesh.n_vertices, mesh.n_vertices + mesh.n_edges))
    return child


def copy_labels(C, kinds=None, rows=None):
    """Labels of the rows of a sparse matrix: rows with the same entries (the same point for every state) and
    the same kind get one label.

    Parameters
    ----------
    C : scipy.sparse matrix, shape (n, r)
        Every control point as a combination of free points (a subdivision operator times the 0/1
        expansion of the copies).
    kinds : (int, int), optional
        The step layout (:func:`ccproof.mesh.child_faces`): rows below ``kinds[0]`` are vertex points,
        below ``kinds[1]`` edge points, the rest face points; points of different kinds never share a label
        (a degenerate face's edge point can equal a corner's vertex point and still be another vertex).
    rows : array_like of int, shape (n,), optional
        The step-layout index of every row of ``C`` (default: its index).

    Returns
    -------
    ndarray of int64, shape (n,)
        Labels ``0 .. k-1`` in the order of first appearance.

    Examples
    --------
    >>> import scipy.sparse as sp
    >>> C = sp.csr_matrix(np.array([[1, 0], [0.5, 0.5], [1, 0], [0.5, 0.5]]))
    >>> copy_labels(C).tolist(), copy_labels(C, kinds=(1, 4)).tolist()
    ([0, 1, 0, 1], [0, 1, 2, 1])
    """
    C = C.tocsr(copy=True)
    C.sum_duplicates()
    C.sort_indices()
    rows = np.arange(C.shape[0]) if rows is None else np.asarray(rows, dtype=np.int64)
    kind = np.zeros(C.shape[0], dtype=np.int64) if kinds is None else (
        (rows >= kinds[0]).astype(np.int64) + (rows >= kinds[1]))
    seen: dict = {}
    out = np.empty(C.shape[0], dtype=np.int64)
    ptr, ind, dat = C.indptr, C.indices, C.data
    for i in range(C.shape[0]):
        key = (int(kind[i]), ind[ptr[i]:ptr[i + 1]].tobytes(), dat[ptr[i]:ptr[i + 1]].tobytes())
        out[i] = seen.setdefault(key, len(seen))
    return out
