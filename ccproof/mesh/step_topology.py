"""The half-edge arrays one Catmull-Clark step reads (:func:`ccproof.mesh.step.catmark_operator`): faces,
twins and edges (:func:`step_topology`, from the caller's :class:`~ccproof.mesh.halfedges.HalfEdges` when given)
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
    half-edge ``h1``, the other ``h2`` (-1 on a boundary), ``two``, ends ``a``, ``b``)."""

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

    @property
    def a(self):
        return self.org[self.h1]

    @property
    def b(self):
        return self.dst[self.h1]


def step_topology(n, indices, sizes, he, edge_of_halfedge):
    """The :class:`StepTopology` of the faces ``indices``/``sizes``: from the caller's half-edges ``he`` when given
    (and manifold), else paired here (a non-manifold edge refused by name)."""
    idx = np.asarray(indices, dtype=np.int64).reshape(-1)
    sz = np.asarray(sizes, dtype=np.int64).reshape(-1)
    m, H = sz.size, idx.size
    off = np.r_[0, np.cumsum(sz)].astype(np.int64)
    if he is not None and (he.org.size != H or he.sizes.size != m or he.n_vertices != n
                           or not np.array_equal(he.sizes, sz) or not np.array_equal(he.org, idx)):
        raise ValueError("halfedges: not the half-edges of this mesh")  # (its twins would be other half-edges')
    face = None if he is None else he.__dict__.get("face_of")  # (built by HalfEdges on mixed face sizes)
    if face is None:
        face = np.repeat(np.arange(m), sz)
    pos = np.arange(H) - off[face]
    if he is None:
        nxt = off[face] + (pos + 1) % sz[face]
        prv = off[face] + (pos - 1) % sz[face]
    else:
        nxt, prv = he.nxt, he.prv
    org, dst = idx, idx[nxt]
    if he is not None and he.edge_manifold:
        twin, he_edge, h1, h2 = _pairs_of_halfedges(he, edge_of_halfedge, H)
    else:
        twin, he_edge, h1, h2 = _pairs_by_sorting(org, dst, n, edge_of_halfedge, H)
    return StepTopology(n, H, m, h1.size, idx, sz, off, face, pos, nxt, prv, org, dst, twin, he_edge, h1, h2, h2 >= 0)


def _pairs_of_halfedges(he, edge_of_halfedge, H):
    """(twin, he_edge, h1, h2) from the mesh's pairing: twins across its manifold edges, each edge's smallest
    half-edge ``first``; edges numbered by first occurrence unless ``edge_of_halfedge`` renumbers them."""
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
    return twin, he_edge, h1, h2


def _pairs_by_sorting(org, dst, n, edge_of_halfedge, H):
    """(twin, he_edge, h1, h2) by sorting the half-edges by their undirected edge (edges numbered by first
    occurrence unless ``edge_of_halfedge`` numbers them); an edge of more than two faces refused."""
    lo, hi = np.minimum(org, dst), np.maximum(org, dst)
    if edge_of_halfedge is None:
        _, first, inv = np.unique(lo * n + hi, return_index=True, return_inverse=True)
        order = np.argsort(first, kind="stable")
        rank = np.empty(first.size, dtype=np.int64)
        rank[order] = np.arange(first.size)
        he_edge = rank[inv.reshape(-1)]
    else:
        he_edge = np.asarray(edge_of_halfedge, dtype=np.int64).reshape(-1)
    E = int(he_edge.max()) + 1 if H else 0
    count = np.bincount(he_edge, minlength=E)
    if (count > 2).any():
        e = int(np.flatnonzero(count > 2)[0])
        h = int(np.flatnonzero(he_edge == e)[0])
        raise MeshError(f"edge ({int(lo[h])}, {int(hi[h])}) has {int(count[e])} faces: the step needs a "
                        "manifold mesh (take PolyMesh.manifold)")
    by_edge = np.argsort(he_edge, kind="stable")
    estart = np.r_[0, np.cumsum(count)][:-1]
    h1 = by_edge[estart]
    h2 = np.where(count == 2, by_edge[np.minimum(estart + 1, H - 1)], -1)
    twin = np.full(H, -1, dtype=np.int64)
    two = h2 >= 0
    twin[h1[two]], twin[h2[two]] = h2[two], h1[two]
    return twin, he_edge, h1, h2


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
    inc_v = np.r_[org[fan], dst[bh]]
    inc_e = np.r_[t.he_edge[fan], t.he_edge[bh]]
    inc_u = np.r_[dst[fan], org[bh]]
    inc_o = np.r_[np.arange(H), H + np.arange(bh.size)]
    o = np.lexsort((inc_o, inc_v))
    return Fans(k, fan, ptr, bh, is_bv, inc_v[o], inc_e[o], inc_u[o])
