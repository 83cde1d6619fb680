"""A polygon complex with sharpness tags, as Python lists: the topology :func:`ccproof.mesh.rules.refine_complex`
reads (a configuration's local faces, or a whole mesh's: :meth:`ccproof.mesh.polymesh.PolyMesh.complex`).

Its half-edges are paired here, independently of :class:`~ccproof.mesh.halfedges.HalfEdges` (a dict of the
directed edges, or a sort for large complexes): the exact stencils built on it are the reference the
vectorized step (which reads ``HalfEdges``) is checked against.
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from ccproof.mesh.crease import INFINITE, child_sharpness_at_vertex

__all__ = ["Complex"]

#: complexes of at least this many faces get their half-edge lists from numpy (the whole mesh); the many
#: small local complexes of the evaluator keep the plain loop (faster below this size)
_VECTORIZED_FACES = 64


class Complex:
    """A polygon complex with sharpness tags: the input of :func:`refine_complex`.

    Parameters
    ----------
    faces : sequence of sequence of int
        Vertex labels of each face in counter-clockwise order; labels 0..n-1.
    edge_sharpness : dict[(int, int), float]
        Sharpness of edges (key ``(min, max)``), float32 values, ``math.inf`` for infinite. Missing
        edges are smooth. Boundary edges (one face) are infinitely sharp whatever the tag.
    vertex_sharpness : dict[int, float]
        Missing vertices have sharpness 0.
    options : Options
    level : int
        Subdivision level of the complex (the ``TRI_SUB_SMOOTH`` weights apply at level 0 only).
    n_vertices : int, optional
        Number of vertex labels (default: the largest label + 1).

    Notes
    -----
    No validation: a complex cut out of a valid mesh has outer vertices whose faces do not all
    belong to it; rules are only correct at vertices whose whole fan is in the complex, and at edges
    whose faces all are. Callers keep track of which new points are exact.

    Examples
    --------
    The 2 x 2 grid: 9 vertices, 12 edges, 8 boundary half-edges (no twin):

    >>> from ccproof.mesh.examples import grid
    >>> from ccproof.mesh.rules import Options
    >>> cx = Complex(grid(2, 2).faces, {}, {}, Options())
    >>> cx.n_vertices, len(cx.edges), sum(t < 0 for t in cx.twin)
    (9, 12, 8)
    """

    def __init__(self, faces, edge_sharpness, vertex_sharpness, options, level=0, n_vertices=None):
        if isinstance(faces, np.ndarray):
            faces = faces.tolist()
        self.faces = [tuple(map(int, f)) for f in faces]
        self.edge_sharpness = edge_sharpness
        self.vertex_sharpness = vertex_sharpness
        self.options = options
        self.level = level
        nv = 1 + max(max(f) for f in self.faces) if n_vertices is None else int(n_vertices)
        self.n_vertices = nv
        self._fans = {}
        if len(self.faces) >= _VECTORIZED_FACES:
            self._topology_numpy()
            return
        start, org, face_of, nxt, prv = [], [], [], [], []
        for g, f in enumerate(self.faces):
            s, n = len(org), len(f)
            start.append(s)
            org.extend(f)
            face_of.extend([g] * n)
            nxt.extend(range(s + 1, s + n))
            nxt.append(s)
            prv.append(s + n - 1)
            prv.extend(range(s, s + n - 1))
        self.start = start
        self.org = org
        self.face_of = face_of
        self.nxt = nxt
        self.prv = prv
        dst = [org[x] for x in nxt]
        directed = dict(zip(zip(org, dst), range(len(org))))
        self.twin = [directed.get((b, a), -1) for a, b in zip(org, dst)]
        eid, edges, he_edge = {}, [], []
        for h, (a, b) in enumerate(zip(org, dst)):
            k = (a, b) if a < b else (b, a)
            e = eid.get(k)
            if e is None:
                e = eid[k] = len(edges)
                edges.append(h)
            he_edge.append(e)
        self.edge_index = eid
        self.edges = edges
        self.he_edge = he_edge
        corners = [[] for _ in range(nv)]
        for h, v in enumerate(org):
            corners[v].append(h)
        self.corners = corners

    def _topology_numpy(self):
        """The lists of ``__init__`` computed with numpy (large complexes: the whole mesh): the same
        values (twins: the last half-edge of a repeated directed edge, as the dict of the loop keeps;
        edges numbered by first occurrence; corners of a vertex in increasing order)."""
        nv = self.n_vertices
        sizes = np.fromiter(map(len, self.faces), dtype=np.int64, count=len(self.faces))
        org = np.fromiter(itertools.chain.from_iterable(self.faces), dtype=np.int64, count=int(sizes.sum()))
        H = org.size
        start = np.r_[0, np.cumsum(sizes)[:-1]].astype(np.int64)
        face_of = np.repeat(np.arange(sizes.size, dtype=np.int64), sizes)
        pos = np.arange(H, dtype=np.int64) - start[face_of]
        nxt = start[face_of] + (pos + 1) % sizes[face_of]
        prv = start[face_of] + (pos - 1) % sizes[face_of]
        dst = org[nxt]
        key = org * nv + dst
        order = np.argsort(key, kind="stable")
        sk = key[order]
        rk = dst * nv + org
        i = np.searchsorted(sk, rk, side="right") - 1  # the last half-edge with that directed key
        ok = i >= 0
        ok[ok] = sk[i[ok]] == rk[ok]
        twin = np.where(ok, order[np.maximum(i, 0)], -1)
        lo, hi = np.minimum(org, dst), np.maximum(org, dst)
        ukey, first, inv = np.unique(lo * nv + hi, return_index=True, return_inverse=True)
        by_first = np.argsort(first, kind="stable")
        rank = np.empty(ukey.size, dtype=np.int64)
        rank[by_first] = np.arange(ukey.size)
        edges = first[by_first]
        self.start, self.org, self.face_of = start.tolist(), org.tolist(), face_of.tolist()
        self.nxt, self.prv, self.twin = nxt.tolist(), prv.tolist(), twin.tolist()
        self.edges = edges.tolist()
        self.he_edge = rank[inv.reshape(-1)].tolist()
        self.edge_index = dict(zip(zip(lo[edges].tolist(), hi[edges].tolist()), range(edges.size)))
        by_vertex = np.argsort(org, kind="stable")
        bounds = np.r_[0, np.cumsum(np.bincount(org, minlength=nv))].tolist()
        flat = by_vertex.tolist()
        self.corners = [flat[a:b] for a, b in zip(bounds[:-1], bounds[1:])]

    # -------------------------------------------------------------- topology
    def dst(self, h):
        return self.org[self.nxt[h]]

    def ccw(self, c):
        """Next corner counter-clockwise around ``org(c)``, or -1."""
        return self.twin[self.prv[c]]

    def cw(self, c):
        t = self.twin[c]
        return -1 if t < 0 else self.nxt[t]

    def fan(self, v):
        """Corners around ``v`` counter-clockwise (an open fan starts at its clockwise end).

        Returns ``(corners, closed)`` or ``(None, None)`` if the faces at ``v`` form several fans.
        """
        if v in self._fans:
            return self._fans[v]
        cs = self.corners[v]
        if not cs:
            res = (None, None)
        else:
            c = cs[0]
            out = [c]
            d = self.ccw(c)
            while d >= 0 and d != c:
                out.append(d)
                d = self.ccw(d)
            if d == c:
                res = (out, True) if len(out) == len(cs) else (None, None)
            else:
                d = c
                while self.cw(d) >= 0:
                    d = self.cw(d)
                out = [d]
                e = self.ccw(d)
                while e >= 0:
                    out.append(e)
                    e = self.ccw(e)
                res = (out, False) if len(out) == len(cs) else (None, None)
        self._fans[v] = res
        return res

    def sharpness(self, e):
        """Sharpness of edge ``e`` (index into ``edges``); boundary edges are infinite."""
        h = self.edges[e]
        if self.twin[h] < 0:
            return math.inf
        a, b = self.org[h], self.dst(h)
        s = self.edge_sharpness.get((a, b) if a < b else (b, a), 0.0)
        return math.inf if s >= INFINITE else s

    def vsharp(self, v):
        s = self.vertex_sharpness.get(v, 0.0)
        return math.inf if s >= INFINITE else s

    def vertex_edges(self, v):
        """Edges at ``v`` in fan order (the outgoing half-edge of every corner, then for an open
        fan the incoming boundary edge of the last corner) and their far vertices, or None."""
        fan, closed = self.fan(v)
        if fan is None:
            return None
        es = [self.he_edge[c] for c in fan]
        nb = [self.dst(c) for c in fan]
        if not closed:
            p = self.prv[fan[-1]]
            es.append(self.he_edge[p])
            nb.append(self.org[p])
        return es, nb, fan, closed

    def child_edge_sharpness(self, v):
        """dict edge -> child sharpness of its half at ``v`` (Sdc rules at vertex ``v``), or None."""
        ve = self.vertex_edges(v)
        if ve is None:
            return None
        es = ve[0]
        cs = child_sharpness_at_vertex([self.sharpness(e) for e in es], self.options.crease_method == "chaikin")
        return dict(zip(es, cs))
