"""The half-edge arrays one Catmull-Clark step reads (:func:`ccproof.mesh.step.catmark_operator`): faces,
twins and edges (:func:`step_topology`, read from the mesh's :class:`~ccproof.mesh.halfedges.HalfEdges`, the
one pairing of half-edges: the caller's, or built once when it passes none)
and the fans of corners around every vertex with the vertex-edge incidences in fan order (:func:`vertex_fans`:
the order in which :func:`ccproof.mesh.rules.refine_complex` sums).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ccproof.errors import MeshError

__all__ = ["StepTopology", "step_topology", "Fans", "vertex_fans"]


class StepTopology(NamedTuple):
    """The half-edge arrays of one step: faces (``idx``, ``sz``, ``off``; per half-edge ``face``, ``pos``,
    ``nxt``, ``prv``, ``org``, ``dst``, ``twin``), edges (``he_edge`` per half-edge; per edge its smallest
    half-edge ``h1``, the other ``h2`` (-1 on a boundary), ``two``, ends ``a``, ``b``); the
    :class:`~ccproof.mesh.halfedges.HalfEdges` read, and ``renum``, the step's number of each of its edges."""

    n: int
    H: int
    m: int
    E: int
    idx: np.ndarray
    sz: np.ndarray
    off: np.ndarray
    face: np.ndarray
    pos: np.ndarray
    nxt: np.ndarray
    prv: np.ndarray
    org: np.ndarray
    dst: np.ndarray
    twin: np.ndarray
    he_edge: np.ndarray
    h1: np.ndarray
    h2: np.ndarray
    two: np.ndarray
    halfedges: object
    renum: np.ndarray

    @property
    def a(self):
        return self.org[self.h1]

    @property
    def b(self):
        return self.dst[self.h1]


def step_topology(n, indices, sizes, he, edge_of_halfedge):
    """The :class:`StepTopology` of the faces ``indices``/``sizes``, read from their half-edges ``he``
    (:class:`~ccproof.mesh.halfedges.HalfEdges`; built here when None: the one pairing of half-edges); a
    non-manifold edge refused by name.

    Examples
    --------
    >>> t = step_topology(6, [0, 1, 4, 3, 1, 2, 5, 4], [4, 4], None, None)
    >>> t.E, t.twin.tolist(), np.stack([t.a, t.b], axis=1)[t.he_edge[1]].tolist()
    (7, [-1, 7, -1, -1, -1, -1, -1, 1], [1, 4])
    >>> step_topology(5, [0, 1, 2, 1, 0, 3, 0, 1, 4], [3, 3, 3], None, None)
    Traceback (most recent call last):
    ...
    ccproof.errors.MeshError: edge (0, 1) has 3 faces: the step needs a manifold mesh (take PolyMesh.manifold)
    """
    idx = np.asarray(indices, dtype=np.int64).reshape(-1)
    sz = np.asarray(sizes, dtype=np.int64).reshape(-1)
    m, H = sz.size, idx.size
    off = np.r_[0, np.cumsum(sz)].astype(np.int64)
    if he is None:
        from ccproof.mesh.halfedges import HalfEdges

        he = HalfEdges(idx, off, n)
    elif (he.org.size != H or he.sizes.size != m or he.n_vertices != n
          or not np.array_equal(he.sizes, sz) or not np.array_equal(he.org, idx)):
        raise ValueError("halfedges: not the half-edges of this mesh")  # (its twins would be other half-edges')
    if not he.edge_manifold:
        _refuse_nonmanifold_edge(he)
    face = he.__dict__.get("face_of")  # (built by HalfEdges on mixed face sizes)
    if face is None:
        face = np.repeat(np.arange(m), sz)
    pos = np.arange(H) - off[face]
    org = idx
    twin, he_edge, h1, h2, renum = _pairs_of_halfedges(he, edge_of_halfedge, H)
    return StepTopology(n, H, m, h1.size, idx, sz, off, face, pos, he.nxt, he.prv, org, idx[he.nxt], twin,
                        he_edge, h1, h2, h2 >= 0, he, renum)


def _refuse_nonmanifold_edge(he):
    """MeshError naming the first edge of ``he`` with more than two faces, or two faces that do not pair."""
    count = he.edge_face_count
    many = np.flatnonzero(count > 2)
    e = int(many[0]) if many.size else int(np.flatnonzero((count == 2) & (he.twin[he.edge_halfedge] < 0))[0])
    a, b = he.edges[e].tolist()
    why = f"has {int(count[e])} faces" if many.size else "has 2 faces that do not pair (one direction, or one face)"
    raise MeshError(f"edge ({a}, {b}) {why}: the step needs a manifold mesh (take PolyMesh.manifold)")


def _pairs_of_halfedges(he, edge_of_halfedge, H):
    """(twin, he_edge, h1, h2, renum) from the mesh's pairing: twins across its manifold edges, each edge's
    smallest half-edge ``first``; edges numbered by first occurrence unless ``edge_of_halfedge`` renumbers
    them; ``renum`` the step's number of every edge of ``he``."""
    twin, first = he.twin, he.edge_halfedge
    if edge_of_halfedge is None:  # numbered by first occurrence: the order of the edges' first half-edges
        is_first = np.zeros(H, dtype=bool)
        is_first[first] = True
        renum = (np.cumsum(is_first) - 1)[first]
        he_edge = renum[he.edge_of]
    else:
        he_edge = np.asarray(edge_of_halfedge, dtype=np.int64).reshape(-1)
        renum = he_edge[first]
    E = first.size
    h1 = np.empty(E, dtype=np.int64)
    h1[renum] = first  # the smallest half-edge of every edge
    count = np.empty(E, dtype=np.int64)
    count[renum] = he.edge_face_count
    h2 = np.where(count == 2, twin[h1], -1)
    return twin, he_edge, h1, h2, renum


class Fans(NamedTuple):
    """Per vertex its number of faces ``k``, its corners counter-clockwise (``fan[ptr[v]:ptr[v+1]]``), the
    boundary half-edges ``bh``, ``is_bv``; the incidences (vertex ``inc_v``, edge ``inc_e``, other end ``inc_u``)
    in fan order."""

    k: np.ndarray
    fan: np.ndarray
    ptr: np.ndarray
    bh: np.ndarray
    is_bv: np.ndarray
    inc_v: np.ndarray
    inc_e: np.ndarray
    inc_u: np.ndarray


def vertex_fans(t):
    """The :class:`Fans`: corners around each vertex counter-clockwise, from the clockwise-most (boundary) or
    the smallest corner (interior), the order of refine_complex's sums; the incidences in that order (the
    outgoing edge of every corner, then for a boundary vertex the incoming boundary edge)."""
    n, H, org, dst, twin = t.n, t.H, t.org, t.dst, t.twin
    k = np.bincount(org, minlength=n)  # faces at each vertex
    rot = twin[t.prv]
    start = np.full(n, H, dtype=np.int64)
    np.minimum.at(start, org, np.arange(H))
    bh = np.flatnonzero(twin < 0)
    start[org[bh]] = bh
    is_bv = np.zeros(n, dtype=bool)
    is_bv[org[bh]] = True
    ptr = np.r_[0, np.cumsum(k)]
    fan = np.empty(H, dtype=np.int64)
    cur = start.copy()
    for j in range(int(k.max()) if n else 0):
        sel = np.flatnonzero(k > j)
        if (cur[sel] < 0).any():
            v = int(sel[cur[sel] < 0][0])
            raise MeshError(f"vertex {v}: its faces form more than one fan (take PolyMesh.manifold)")
        fan[ptr[sel] + j] = cur[sel]
        cur[sel] = rot[cur[sel]]
    # the incidences by vertex, each vertex's fan first, then its incoming boundary edges (placed, not sorted)
    nb_in = np.bincount(dst[bh], minlength=n)
    ptr2 = np.r_[0, np.cumsum(k + nb_in)]
    at_fan = np.arange(H) + (ptr2 - ptr)[:-1][org[fan]]
    if bh.size and nb_in.max() > 1:  # (two open fans at a vertex: refused by the walk above already)
        v = int(np.flatnonzero(nb_in > 1)[0])
        raise MeshError(f"vertex {v}: its faces form more than one fan (take PolyMesh.manifold)")
    at_bh = ptr2[dst[bh]] + k[dst[bh]]
    inc_v, inc_e, inc_u = (np.empty(H + bh.size, dtype=np.int64) for _ in range(3))
    inc_v[at_fan], inc_v[at_bh] = org[fan], dst[bh]
    inc_e[at_fan], inc_e[at_bh] = t.he_edge[fan], t.he_edge[bh]
    inc_u[at_fan], inc_u[at_bh] = dst[fan], org[bh]
    return Fans(k, fan, ptr, bh, is_bv, inc_v, inc_e, inc_u)
