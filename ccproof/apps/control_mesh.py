"""The control mesh of the applications: every mesh ``ccproof eval`` reads, as an all-quad mesh.

ARAP (hsh10) and the dynamic surfaces (qmv98) work on all-quad Catmull-Clark control meshes. A mesh with
triangles or n-gons (any format of :func:`ccproof.mesh.io.read_mesh`: OBJ, PLY, OFF, STL, VTK, ...) is
subdivided once with the Catmull-Clark rules first: every n-gon becomes n quads and the limit surface is
unchanged (it is the step every Catmull-Clark evaluator takes on such a mesh anyway). Vertices that no face
uses (common in scans) are dropped, the others keep their order.

Meshes with OpenSubdiv tags (creases, corners, holes, boundary modes) and non-manifold meshes (which
OpenSubdiv, and :attr:`~ccproof.mesh.polymesh.PolyMesh.manifold`, turn into tagged manifold ones: their
non-manifold edges and vertices infinitely sharp) become a :class:`TaggedQuadMesh`: the rules of
:mod:`ccproof.mesh.rules` (OpenSubdiv's Sdc) are applied to the whole mesh, one global step at a time
(:meth:`PolyMesh.refine <ccproof.mesh.polymesh.PolyMesh.refine>`), while a face is not a quad or a
sharpness is semi-sharp (0 < s < 10: it decays by 1 per step, after ceil(s) steps it is 0); what remains
are infinitely sharp edges and vertices and hole faces, whose rules are *stationary* (the same at every
further level): an infinitely sharp edge's edge point is its midpoint, a vertex with two sharp edges takes
the crease rule ``(3/4) V + (1/8)(e0 + e1)``, with more (or a sharp vertex) it stays (corner), with one
(a dart) or none the smooth rule. :func:`tagged_step` is that step as a sparse operator on any quad mesh
with those tags (the chart levels of ARAP, :func:`subdivide_control`). ``EDGE_AND_CORNER`` corners and
``TRI_SUB_SMOOTH`` act at level 0 only: they are made explicit (sharp vertices) or taken by the first
global step. The limit surface is the one ``ccproof eval`` evaluates (tests/apps/test_control_mesh.py
compares them).
"""

from __future__ import annotations

import math
import os

import numpy as np

from ccproof.errors import MeshError
from ccproof.mesh import QuadMesh
from ccproof.rule_weights import crease_vertex_weights, sharp_edge_weight

__all__ = ["read_control_mesh", "children_labels", "TaggedQuadMesh", "tagged_step", "subdivide_control",
           "refuse_tags", "MAX_TAGGED_FACES"]

#: most faces the global tagged steps of :func:`read_control_mesh` may make (Python rules: ~50 us a face)
MAX_TAGGED_FACES = 200_000


def _pair_keys(pairs, n):
    p = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    return np.minimum(p[:, 0], p[:, 1]) * n + np.maximum(p[:, 0], p[:, 1])


def edge_mask(mesh: QuadMesh, pairs):
    """Bool (n_edges,) over ``mesh.edges``: the interior edges among the vertex pairs ``pairs`` (k, 2)."""
    if pairs is None or len(pairs) == 0:
        return np.zeros(mesh.n_edges, dtype=bool)
    n = mesh.n_vertices
    return np.isin(_pair_keys(mesh.edges, n), _pair_keys(pairs, n)) & ~mesh.is_boundary_edge


class TaggedQuadMesh(QuadMesh):
    """An all-quad control mesh with infinitely sharp edges and vertices and hole faces (module docstring).

    Parameters
    ----------
    vertices : array_like, shape (n, 3)
    faces : array_like of int, shape (m, 4)
    sharp_edges : array_like of int, shape (k, 2), optional
        Infinitely sharp edges as vertex pairs (boundary edges are sharp anyway).
    sharp_vertices : array_like of int, optional
        Infinitely sharp vertices (corners).
    holes : array_like of int, optional
        Hole faces: part of the topology (the rules of their neighbours do not change), not of the surface.

    Attributes
    ----------
    sharp_edge : ndarray of bool, shape (n_edges,)
        Over ``edges``: the tagged interior edges.
    sharp_vertex : ndarray of bool, shape (n,)
    hole : ndarray of bool, shape (m,)
    global_steps : int
        The Catmull-Clark steps :func:`read_control_mesh` took on the file (0 otherwise).

    Examples
    --------
    >>> from ccproof.mesh.examples import grid
    >>> g = grid(2, 2)
    >>> t = TaggedQuadMesh(g.vertices, g.faces, sharp_edges=[[1, 4], [4, 7]], holes=[3])
    >>> int(t.sharp_edge.sum()), int(t.hole.sum()), t.has_tags
    (2, 1, True)
    """

    def __init__(self, vertices, faces, *, sharp_edges=None, sharp_vertices=None, holes=None):
        super().__init__(vertices, faces)
        self.sharp_edge = edge_mask(self, sharp_edges)
        self.sharp_vertex = np.zeros(self.n_vertices, dtype=bool)
        if sharp_vertices is not None:
            self.sharp_vertex[np.asarray(sharp_vertices, dtype=np.int64)] = True
        self.hole = np.zeros(self.n_faces, dtype=bool)
        if holes is not None:
            self.hole[np.asarray(holes, dtype=np.int64)] = True
        self.global_steps = 0

    @property
    def has_tags(self):
        return bool(self.sharp_edge.any() or self.sharp_vertex.any() or self.hole.any())

    def with_vertices(self, vertices):
        """Same connectivity and tags, new control points (shape (n, 3))."""
        plain = QuadMesh.with_vertices(self, vertices)
        new = object.__new__(TaggedQuadMesh)
        new.__dict__.update(plain.__dict__)
        return new

    def __repr__(self):
        return ("Tagged" + super().__repr__()[:-1] + f", {int(self.sharp_edge.sum())} sharp edges, "
                f"{int(self.sharp_vertex.sum())} sharp vertices, {int(self.hole.sum())} holes)")


def refuse_tags(mesh, name):
    """Raise :class:`~ccproof.errors.MeshError` naming the first tag of a control mesh that still has some.

    For the consumers that use the untagged rules only (the dynamic fit's elements). Vertex numbers are the
    control mesh's (the file's without its unused vertices, when no step was taken).

    Examples
    --------
    >>> from ccproof.mesh.examples import grid
    >>> g = grid(2, 2)
    >>> refuse_tags(g, "g.obj")            # a plain QuadMesh: nothing to refuse
    >>> refuse_tags(TaggedQuadMesh(g.vertices, g.faces, holes=[3]), "g.obj")
    Traceback (most recent call last):
    ...
    ccproof.errors.MeshError: g.obj: face 3 is a hole: this command uses the untagged Catmull-Clark rules (`ccproof arap` and `ccproof eval` take tags)
    """
    if not getattr(mesh, "has_tags", False):
        return
    if mesh.sharp_edge.any():
        a, b = mesh.edges[np.flatnonzero(mesh.sharp_edge)[0]].tolist()
        what = f"edge ({a}, {b}) is infinitely sharp (a crease tag, or a non-manifold edge)"
    elif mesh.sharp_vertex.any():
        what = f"vertex {int(np.flatnonzero(mesh.sharp_vertex)[0])} is an infinitely sharp corner"
    else:
        what = f"face {int(np.flatnonzero(mesh.hole)[0])} is a hole"
    raise MeshError(f"{name}: {what}: this command uses the untagged Catmull-Clark rules (`ccproof arap` and "
                    "`ccproof eval` take tags)")


def tags_of(mesh):
    """``(sharp_edge, sharp_vertex)`` of a control mesh (all False on a plain :class:`QuadMesh`)."""
    se = getattr(mesh, "sharp_edge", None)
    if se is None:
        return np.zeros(mesh.n_edges, dtype=bool), np.zeros(mesh.n_vertices, dtype=bool)
    return se, mesh.sharp_vertex


def vertex_rules(mesh: QuadMesh, sharp_edge, sharp_vertex):
    """The stationary rule of every vertex and its crease neighbours.

    Parameters
    ----------
    mesh : QuadMesh
    sharp_edge : ndarray of bool, shape (n_edges,)
        Tagged interior edges (boundary edges count as sharp in any case).
    sharp_vertex : ndarray of bool, shape (n,)

    Returns
    -------
    n_sharp : ndarray of int64, shape (n,)
        Sharp edges (boundary or tagged) at every vertex.
    corner, crease, dart : ndarray of bool, shape (n,)
        Sdc's vertex rule: a sharp vertex or three or more sharp edges: corner; two: crease; one: dart
        (the smooth vertex rule, with a midpoint on its sharp edge).
    crease_nbrs : ndarray of int64, shape (n, 2)
        The far ends of the two sharp edges of a crease vertex (-1 elsewhere).

    Examples
    --------
    The middle vertex 4 of a 2 x 2 grid with a crease through it; vertex 1 is on the boundary and on
    the crease (three sharp edges: a corner):

    >>> from ccproof.mesh.examples import grid
    >>> g = grid(2, 2)
    >>> ns, corner, crease, dart, nb = vertex_rules(g, edge_mask(g, [[1, 4], [4, 7]]), np.zeros(9, bool))
    >>> bool(crease[4]), sorted(nb[4].tolist()), bool(corner[1]), int(ns[4])
    (True, [1, 7], True, 2)
    """
    n = mesh.n_vertices
    a, b = mesh.edges[:, 0], mesh.edges[:, 1]
    sh = mesh.is_boundary_edge | sharp_edge
    ns = np.bincount(a[sh], minlength=n) + np.bincount(b[sh], minlength=n)
    corner = sharp_vertex | (ns >= 3)
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
    return ns, corner, crease, dart, nb


def tagged_step(mesh: QuadMesh, sharp_edge=None, sharp_vertex=None):
    """One Catmull-Clark step of a quad mesh with infinitely sharp edges and vertices, as a sparse operator.

    The untagged operator (:func:`ccproof.mesh.subdivision_matrix`, the rules of :mod:`ccproof.rule_weights`)
    with the rows of the tagged points replaced (module docstring; the Sdc rules of :mod:`ccproof.mesh.rules`
    for infinite sharpness): a sharp edge's point is its midpoint, a crease vertex (two sharp edges, boundary
    edges counted) ``(3/4) V + (1/8)(e0 + e1)`` along them, a corner (a sharp vertex, three or more sharp
    edges) stays. Without tags the operator is :func:`~ccproof.mesh.subdivision_matrix`'s, unchanged.

    Parameters
    ----------
    mesh : QuadMesh
        n vertices, E edges, m faces.
    sharp_edge : ndarray of bool, shape (E,), optional
    sharp_vertex : ndarray of bool, shape (n,), optional
        Default: :func:`tags_of` ``(mesh)``.

    Returns
    -------
    S : scipy.sparse.csr_matrix, shape (n + E + m, n)
        Rows laid out as :func:`ccproof.mesh.child_faces` numbers the new vertices.
    child_sharp_edges : ndarray of int64, shape (2 k, 2)
        The halves of the sharp edges, in the new vertex numbers.
    child_sharp_vertices : ndarray of int64, shape (j,)

    Examples
    --------
    A crease through the middle of a 2 x 2 grid: the edge point of edge (1, 4) is the midpoint, the
    crease vertex 4 moves along the crease only:

    >>> from ccproof.mesh.examples import grid
    >>> g = grid(2, 2)
    >>> S, ce, cv = tagged_step(g, edge_mask(g, [[1, 4], [4, 7]]), np.zeros(9, bool))
    >>> e = int(np.flatnonzero((np.sort(g.edges, axis=1) == [1, 4]).all(axis=1))[0])
    >>> S[9 + e].toarray()[0, [1, 4]].tolist(), S[4].toarray()[0, [1, 4, 7]].tolist(), ce.shape
    ([0.5, 0.5], [0.125, 0.75, 0.125], (4, 2))
    """
    import scipy.sparse as sp

    from ccproof.mesh import subdivision_matrix

    if sharp_edge is None:
        sharp_edge, sharp_vertex = tags_of(mesh)
    S = subdivision_matrix(mesh)
    n = mesh.n_vertices
    se = np.flatnonzero(sharp_edge)
    if not se.size and not sharp_vertex.any():
        return S, np.zeros((0, 2), dtype=np.int64), np.zeros(0, dtype=np.int64)
    _, corner, crease, _, nb = vertex_rules(mesh, sharp_edge, sharp_vertex)
    a, b = mesh.edges[se, 0], mesh.edges[se, 1]
    touched = np.zeros(n, dtype=bool)
    touched[a] = touched[b] = True
    touched |= sharp_vertex
    cor = np.flatnonzero(touched & corner)
    cre = np.flatnonzero(touched & crease)
    er = n + se
    replace = np.ones(S.shape[0])
    replace[np.r_[cor, cre, er]] = 0.0
    wv, wn = crease_vertex_weights(1.0)
    half = sharp_edge_weight(1.0)
    rows = np.r_[cor, cre, cre, cre, er, er]
    cols = np.r_[cor, cre, nb[cre, 0], nb[cre, 1], a, b]
    vals = np.r_[np.ones(cor.size), np.full(cre.size, wv), np.full(2 * cre.size, wn), np.full(2 * er.size, half)]
    out = (sp.diags(replace) @ S + sp.coo_matrix((vals, (rows, cols)), shape=S.shape)).tocsr()
    out.eliminate_zeros()
    child_edges = np.r_[np.c_[a, er], np.c_[b, er]]
    return out, child_edges, np.flatnonzero(sharp_vertex)


def subdivide_control(mesh: QuadMesh) -> QuadMesh:
    """One Catmull-Clark step of a control mesh, tags carried (:func:`tagged_step`; holes to their children).

    Parameters
    ----------
    mesh : QuadMesh or TaggedQuadMesh

    Returns
    -------
    QuadMesh or TaggedQuadMesh
        Child ``4 f + i`` at corner ``i`` of face ``f`` (:func:`ccproof.mesh.child_faces`).

    Examples
    --------
    >>> from ccproof.mesh.examples import grid
    >>> g = grid(2, 2)
    >>> t = subdivide_control(TaggedQuadMesh(g.vertices, g.faces, sharp_edges=[[1, 4], [4, 7]], holes=[0]))
    >>> t.n_faces, int(t.sharp_edge.sum()), int(t.hole.sum())
    (16, 4, 4)
    """
    from ccproof.mesh import child_faces, subdivide

    if not isinstance(mesh, TaggedQuadMesh):
        return subdivide(mesh)
    S, ce, cv = tagged_step(mesh)
    return TaggedQuadMesh(S @ mesh.vertices, child_faces(mesh), sharp_edges=ce, sharp_vertices=cv,
                          holes=np.flatnonzero(np.repeat(mesh.hole, 4)))


def _sharpest_semi_sharp(poly):
    """``(words, s)`` of the largest semi-sharp tag (0 < s < 10) of a PolyMesh, or None."""
    bnd = set(map(tuple, poly.edges[poly.is_boundary_edge].tolist()))  # sharp anyway: the tag does nothing
    tags = [(s, f"edge ({a}, {b})") for (a, b), s in sorted(poly.edge_sharpness.items())
            if 0.0 < s < 10.0 and (a, b) not in bnd]
    tags += [(s, f"vertex {v}") for v, s in sorted(poly.vertex_sharpness.items()) if 0.0 < s < 10.0]
    if not tags:
        return None
    s, what = max(tags, key=lambda t: t[0])
    return f"{what} of sharpness {s:g}", s


def read_control_mesh(path: str | os.PathLike[str]) -> tuple[QuadMesh, np.ndarray | None]:
    """Read a polygon mesh and make it all quads (module docstring).

    Parameters
    ----------
    path : str or os.PathLike
        Any file :func:`ccproof.mesh.io.read_mesh` reads.

    Returns
    -------
    mesh : QuadMesh or TaggedQuadMesh
        The mesh itself when it is all quads (without semi-sharp tags), else the mesh subdivided (the same
        limit surface: once for n-gons, ceil(s) times for the largest semi-sharp sharpness s); without unused
        vertices. A :class:`TaggedQuadMesh` when the file has OpenSubdiv tags or is not manifold.
    origin : ndarray of int64, shape (mesh.n_faces,), or None
        None when the file's faces are kept; else the face of the file every control face lies on
        (children in order: :func:`children_labels`).

    Raises
    ------
    MeshError
        What :func:`~ccproof.mesh.io.read_mesh` raises; semi-sharp tags that would need more than
        :data:`MAX_TAGGED_FACES` faces (names the sharpest one).

    Examples
    --------
    A square pyramid (one quad, four triangles) as ASCII PLY: 5 + 8 + 5 = 18 vertices and 4 + 4 * 3 = 16
    quads after one step:

    >>> import os, tempfile
    >>> tmp = tempfile.TemporaryDirectory()          # removed when the example ends
    >>> p = os.path.join(tmp.name, "pyramid.ply")
    >>> with open(p, "w") as fh:
    ...     _ = fh.write("ply\\nformat ascii 1.0\\nelement vertex 5\\nproperty float x\\nproperty float y\\n"
    ...                  "property float z\\nelement face 5\\nproperty list uchar int vertex_indices\\nend_header\\n"
    ...                  "0 0 0\\n1 0 0\\n1 1 0\\n0 1 0\\n0.5 0.5 1\\n"
    ...                  "4 0 3 2 1\\n3 0 1 4\\n3 1 2 4\\n3 2 3 4\\n3 3 0 4\\n")
    >>> mesh, origin = read_control_mesh(p)
    >>> mesh.n_vertices, mesh.n_faces, origin.tolist()
    (18, 16, [0, 0, 0, 0, 1, 1, 1, 2, 2, 2, 3, 3, 3, 4, 4, 4])

    An unused vertex (the sixth) is dropped:

    >>> with open(p, "w") as fh:
    ...     _ = fh.write("ply\\nformat ascii 1.0\\nelement vertex 6\\nproperty float x\\nproperty float y\\n"
    ...                  "property float z\\nelement face 1\\nproperty list uchar int vertex_indices\\nend_header\\n"
    ...                  "0 0 0\\n1 0 0\\n1 1 0\\n0 1 0\\n0.5 0.5 1\\n9 9 9\\n4 0 1 2 3\\n")
    >>> mesh, origin = read_control_mesh(p)
    >>> mesh.n_vertices, mesh.n_faces, origin
    (4, 1, None)

    A cube with a crease of sharpness 2 is subdivided twice (then the crease is smooth); an infinitely sharp
    one is kept as a tag:

    >>> p = os.path.join(tmp.name, "cube.obj")
    >>> cube = ("v -1 -1 1\\nv 1 -1 1\\nv -1 1 1\\nv 1 1 1\\nv -1 1 -1\\nv 1 1 -1\\nv -1 -1 -1\\nv 1 -1 -1\\n"
    ...         "f 1 2 4 3\\nf 3 4 6 5\\nf 5 6 8 7\\nf 7 8 2 1\\nf 2 8 6 4\\nf 7 1 3 5\\n")
    >>> with open(p, "w") as fh:
    ...     _ = fh.write(cube + "t crease 2/1/0 0 1 2.0\\n")
    >>> mesh, origin = read_control_mesh(p)
    >>> type(mesh).__name__, mesh.n_faces, int(mesh.sharp_edge.sum()), origin[:17].tolist()[::4]
    ('TaggedQuadMesh', 96, 0, [0, 0, 0, 0, 1])
    >>> with open(p, "w") as fh:
    ...     _ = fh.write(cube + "t crease 2/1/0 0 1 10\\n")
    >>> mesh, origin = read_control_mesh(p)
    >>> mesh.n_faces, int(mesh.sharp_edge.sum()), origin
    (6, 1, None)
    """
    from ccproof.mesh.io import read_mesh

    poly = read_mesh(path)
    if poly.has_tags or not poly.is_manifold:
        return _tagged_control_mesh(poly, os.fspath(path))
    sizes = np.asarray(poly.sizes, dtype=np.int64)
    idx = np.asarray(poly.indices, dtype=np.int64)
    used = np.unique(idx)
    if used.size < poly.n_vertices:  # unused vertices (a subdivision step cannot even place them): dropped
        from ccproof.mesh.polymesh import PolyMesh

        new = np.full(poly.n_vertices, -1, dtype=np.int64)
        new[used] = np.arange(used.size)
        poly = PolyMesh(np.asarray(poly.vertices)[used], new[idx], sizes=sizes)
    if poly.is_all_quads:
        return QuadMesh(poly.vertices, poly.indices.reshape(-1, 4)), None
    fine, _ = poly.refine(operator=False)
    V, F = np.asarray(fine.vertices, dtype=np.float64), fine.indices.reshape(-1, 4)
    return QuadMesh(V, F), np.repeat(np.arange(sizes.size, dtype=np.int64), sizes)


def _tagged_control_mesh(poly, name):
    """:func:`read_control_mesh` of a tagged or non-manifold mesh."""
    pm = poly.manifold  # non-manifold edges and vertices: infinitely sharp (same faces, split vertices)
    semi = _sharpest_semi_sharp(pm)
    need = max(math.ceil(semi[1]) if semi else 0, 0 if pm.is_all_quads else 1)  # sharpness - 1 per step
    faces = pm.n_faces if need == 0 else int(np.asarray(pm.sizes).sum()) * 4 ** (need - 1)
    if faces > MAX_TAGGED_FACES:
        raise MeshError(f"{name}: {semi[0]} decays in {need} Catmull-Clark steps, which make {faces:,} faces (the "
                        f"applications take at most {MAX_TAGGED_FACES:,}; semi-sharp tags are resolved by global "
                        "steps there); `ccproof eval` evaluates it, or make the tag smaller or infinite (>= 10)")
    origin = np.arange(pm.n_faces, dtype=np.int64)
    steps = 0
    while not pm.is_all_quads or _sharpest_semi_sharp(pm) is not None:
        origin = np.repeat(origin, np.asarray(pm.sizes, dtype=np.int64))
        pm, _ = pm.refine(operator=False)
        steps += 1
    sharp_v = [v for v, s in pm.vertex_sharpness.items() if s >= 10.0]
    if steps == 0 and pm.options.boundary == "edge_and_corner":  # its level-0 corners, made explicit
        sharp_v += np.flatnonzero(pm.is_boundary_vertex & (pm.face_count == 1)).tolist()
    sharp_e = [e for e, s in pm.edge_sharpness.items() if s >= 10.0]
    idx = np.asarray(pm.indices, dtype=np.int64)
    used = np.unique(idx)
    new = np.full(pm.n_vertices, -1, dtype=np.int64)
    new[used] = np.arange(used.size)
    se = new[np.asarray(sharp_e, dtype=np.int64).reshape(-1, 2)]
    sv = new[np.asarray(sharp_v, dtype=np.int64)]
    mesh = TaggedQuadMesh(np.asarray(pm.vertices)[used], new[idx].reshape(-1, 4), sharp_edges=se[(se >= 0).all(axis=1)],
                          sharp_vertices=sv[sv >= 0], holes=np.flatnonzero(pm.is_hole))
    mesh.global_steps = steps
    return mesh, (origin if steps else None)


def children_labels(labels, origin):
    """Per-face labels of the file's faces carried to the quads of :func:`read_control_mesh`.

    Parameters
    ----------
    labels : array_like of int, shape (n,)
    origin : array_like of int, shape (m,), or None
        The file's face of every control face (None: the same faces).

    Returns
    -------
    ndarray of int64

    Examples
    --------
    >>> children_labels([7, 8], [0, 0, 0, 1, 1, 1, 1]).tolist(), children_labels([7, 8], None).tolist()
    ([7, 7, 7, 8, 8, 8, 8], [7, 8])
    """
    labels = np.asarray(labels, dtype=np.int64)
    return labels if origin is None else labels[np.asarray(origin, dtype=np.int64)]
