"""Local triangle complexes and one exact Loop step on them (OpenSubdiv's Sdc Loop rules, infinitely
sharp tags).

A :class:`TriComplex` is a set of counter-clockwise triangles in local vertex labels with the tags
that the rules read: infinitely sharp edges, corner vertices, the boundary interpolation, and the
vertices whose fan is *complete* (all their mesh triangles present: only there the vertex rules apply
and a missing triangle means a boundary). :func:`loop_step` subdivides a complex once, exactly, and
returns the children's stencils; :func:`canonical_ring` lists the one-ring of a triangle (every
triangle sharing a vertex with it) in a deterministic order whose key identifies isomorphic rings.
"""

from __future__ import annotations

from ccproof.errors import MeshError
from ccproof.evaluate.loop.box_spline import DIRS, NET
from ccproof.mesh.scheme import LOOP

__all__ = ["TriComplex", "loop_step", "canonical_ring", "regular_net", "SMOOTH", "CREASE", "CORNER"]

SMOOTH, CREASE, CORNER = "smooth", "crease", "corner"


class TriComplex:
    """Counter-clockwise triangles with tags (see the module docstring).

    Parameters
    ----------
    triangles : sequence of (a, b, c)
    sharp : iterable of (a, b)
        Infinitely sharp edges (either orientation).
    corners : iterable of int
        Infinitely sharp vertices.
    complete : iterable of int or None
        Vertices whose fan is complete (None: every vertex).
    boundary : {"edge_only", "edge_and_corner"}
        OpenSubdiv's boundary interpolation: with "edge_and_corner" a boundary vertex of one triangle
        is a corner.

    Examples
    --------
    An octahedron's vertex has a closed fan of four:

    >>> T = [(0, 2, 4), (2, 1, 4), (1, 3, 4), (3, 0, 4), (2, 0, 5), (1, 2, 5), (3, 1, 5), (0, 3, 5)]
    >>> cx = TriComplex(T)
    >>> cx.fan(4, 0), cx.rule(4)
    (([0, 2, 1, 3], True), ('smooth', [0, 2, 1, 3]))
    """

    def __init__(self, triangles, sharp=(), corners=(), complete=None, boundary="edge_only"):
        self.triangles = tuple(tuple(int(x) for x in t) for t in triangles)
        self.opp = {}
        for a, b, c in self.triangles:
            for e, x in (((a, b), c), ((b, c), a), ((c, a), b)):
                if e in self.opp:
                    raise MeshError(f"edge {e} is used twice in the same direction (non-manifold or misoriented)")
                self.opp[e] = x
        self.first = {}
        for a, b in self.opp:
            self.first.setdefault(a, b)
        self.n_vertices = 1 + max((max(t) for t in self.triangles), default=-1)
        self.sharp = frozenset((min(a, b), max(a, b)) for a, b in sharp)
        self.corners = frozenset(int(v) for v in corners)
        self.complete = None if complete is None else frozenset(complete)
        self.boundary = boundary

    def is_complete(self, v):
        return self.complete is None or v in self.complete

    def fan(self, v, start):
        """Neighbours of ``v`` counter-clockwise from ``start`` (an open fan from its clockwise end,
        ``start`` included), and whether the fan is closed."""
        out, w = [start], start
        while True:
            w = self.opp.get((v, w))
            if w is None:
                break
            if w == start:
                return out, True
            out.append(w)
        w = start
        while True:  # clockwise from start: triangle (v, x, w) has x before w
            w = self.opp.get((w, v))
            if w is None:
                return out, False
            out.insert(0, w)

    def is_sharp(self, a, b):
        """Infinitely sharp: tagged, or a boundary edge (one triangle)."""
        return (min(a, b), max(a, b)) in self.sharp or (a, b) not in self.opp or (b, a) not in self.opp

    def rule(self, v):
        """(rule, fan) of a complete vertex: its Sdc rule and its neighbours (counter-clockwise)."""
        fan, closed = self.fan(v, self.first[v])
        n_sharp = sum(self.is_sharp(v, w) for w in fan)
        if v in self.corners or n_sharp > 2 or (not closed and len(fan) == 2 and self.boundary == "edge_and_corner"):
            return CORNER, fan
        return (CREASE if n_sharp == 2 else SMOOTH), fan

    def sector(self, v, start):
        """Neighbours of ``v`` counter-clockwise in the sector of edge (v, start) (bounded by sharp edges and
        the boundary; the whole fan at a smooth vertex without sharp edges): (list, index of start)."""
        out, w = [start], start
        while not (self.is_sharp(v, w) and w != start):
            w = self.opp.get((v, w))
            if w is None or w == start:
                break
            out.append(w)
        i, w = 0, start
        while not self.is_sharp(v, w):
            w = self.opp.get((w, v))
            if w is None or w in out:
                break
            out.insert(0, w)
            i += 1
        return out, i

    def is_regular(self, v, start):
        """Corner v of a triangle with next vertex ``start`` is regular: smooth of valence 6 without sharp
        edges, or a crease (boundary) vertex with three triangles in the triangle's sector."""
        rule, fan = self.rule(v)
        if rule == SMOOTH:
            return len(fan) == 6 and not any(self.is_sharp(v, w) for w in fan)
        return rule == CREASE and len(self.sector(v, start)[0]) == 4


def vertex_stencil(cx, v, one):
    """The Sdc Loop vertex point of complete vertex ``v``: dict label -> weight."""
    rule, fan = cx.rule(v)
    if rule == CORNER:
        return {v: one}
    if rule == CREASE:
        wV, we = LOOP.crease_vertex(one)
        s = {v: wV}
        for w in fan:
            if cx.is_sharp(v, w):
                s[w] = we
        return s
    wV, we = LOOP.vertex_point(len(fan), one)
    s = {v: wV}
    for w in fan:
        s[w] = s.get(w, 0) + we
    return s


def limit_stencil(cx, v, one):
    """The limit position of complete vertex ``v`` (Sdc Loop limit masks): dict label -> weight."""
    rule, fan = cx.rule(v)
    if rule == CORNER:
        return {v: one}
    if rule == CREASE:
        wV, we = LOOP.crease_limit(one)
        s = {v: wV}
        for w in fan:
            if cx.is_sharp(v, w):
                s[w] = we
        return s
    wV, we = LOOP.limit(len(fan), one)
    s = {v: wV}
    for w in fan:
        s[w] = s.get(w, 0) + we
    return s


def _edge_stencil(cx, a, b, one):
    if cx.is_sharp(a, b):
        w = LOOP.sharp_edge(one)
        return {a: w, b: w}
    we, wo = LOOP.edge_point(one)
    s = {a: we, b: we}
    for x in (cx.opp[(a, b)], cx.opp[(b, a)]):
        s[x] = s.get(x, 0) + wo
    return s


def loop_step(cx, one):
    """One Loop step of a complex: (child complex, stencils).

    Child labels: the parent's vertices keep theirs; edge (a, b) gets ``n + i`` in the order the
    edges first appear in the triangles. Triangle (a, b, c) with edge points ab, bc, ca has the
    children (a, ab, ca), (ab, b, bc), (ca, bc, c) and (bc, ca, ab), in that order: in the parameter
    of the parent (P(0,0) = a, P(1,0) = b, P(0,1) = c) they are the images of (2u, 2v), (2u - 1, 2v),
    (2u, 2v - 1) and (1 - 2u, 1 - 2v). ``stencils[child label]`` is a dict parent label -> weight, or
    None where the rules need triangles the complex does not hold.

    Examples
    --------
    >>> from fractions import Fraction
    >>> T = [(0, 2, 4), (2, 1, 4), (1, 3, 4), (3, 0, 4), (2, 0, 5), (1, 2, 5), (3, 1, 5), (0, 3, 5)]
    >>> child, st = loop_step(TriComplex(T), Fraction(1))
    >>> len(child.triangles), child.n_vertices, [str(w) for w in st[4].values()]
    (32, 18, ['33/64', '31/256', '31/256', '31/256', '31/256'])
    """
    n = cx.n_vertices
    edge_label, stencils = {}, [None] * n
    for v in range(n):
        if cx.is_complete(v) and v in cx.first:
            stencils[v] = vertex_stencil(cx, v, one)
    tris, sharp = [], []
    for a, b, c in cx.triangles:
        ab, bc, ca = (_label(edge_label, n, x, y) for x, y in ((a, b), (b, c), (c, a)))
        tris += [(a, ab, ca), (ab, b, bc), (ca, bc, c), (bc, ca, ab)]
    stencils += [None] * len(edge_label)
    for (a, b), e in edge_label.items():
        full = (a, b) in cx.opp and (b, a) in cx.opp
        if full or cx.is_complete(a) or cx.is_complete(b):
            stencils[e] = _edge_stencil(cx, a, b, one)
        if (a, b) in cx.sharp:
            sharp += [(a, e), (e, b)]
    complete = None if cx.complete is None else \
        {v for v in cx.complete} | {e for (a, b), e in edge_label.items() if stencils[e] is not None}
    child = TriComplex(tris, sharp, cx.corners, complete, cx.boundary)
    return child, stencils


def _label(edge_label, n, a, b):
    key = (min(a, b), max(a, b))
    if key not in edge_label:
        edge_label[key] = n + len(edge_label)
    return edge_label[key]


def canonical_ring(cx, tri):
    """The one-ring of triangle ``tri = (a, b, c)`` (its corners complete): (labels, key).

    Labels: a, b, c, then the fans of a (from b), b (from c) and c (from a), each new vertex at its
    first appearance. The key (ring triangles, sharp edges and corners in ring labels, boundary mode)
    is equal for isomorphic tagged rings: the cache key of everything computed per configuration.
    """
    a, b, c = tri
    pos, ring = {}, []

    def add(x):
        if x not in pos:
            pos[x] = len(ring)
            ring.append(x)

    for x in tri:
        add(x)
    fans = []
    for x, start in ((a, b), (b, c), (c, a)):
        fan, closed = cx.fan(x, start)
        fans.append((x, fan, closed))
        for w in fan:
            add(w)
    T = set()
    for x, fan, closed in fans:
        pairs = list(zip(fan, fan[1:])) + ([(fan[-1], fan[0])] if closed else [])
        for p, q in pairs:
            t = (pos[x], pos[p], pos[q])
            i = t.index(min(t))
            T.add(t[i:] + t[:i])
    sharp = sorted(tuple(sorted((pos[p], pos[q]))) for p, q in cx.sharp if p in pos and q in pos)
    corners = sorted(pos[v] for v in cx.corners if v in pos)
    return ring, (tuple(sorted(T)), tuple(sharp), tuple(corners), cx.boundary)


def key_complex(key):
    """The complex of a ring key (its three first vertices complete)."""
    tris, sharp, corners, boundary = key
    return TriComplex(tris, sharp, corners, (0, 1, 2), boundary)


def regular_net(cx, tri):
    """The 12 control points (box_spline.NET order) of a triangle whose corners are regular, as stencils
    (dict label -> weight), or None.

    Lattice points across a sharp line (boundary or crease) are ghosts ``a + b - m``: a, b the two
    points of the line next to it, m its mirror image ``a + b - x`` (they reproduce the crease rules:
    the Loop edge point of (a, b) with the ghost is the midpoint, the vertex point 3/4, 1/8, 1/8).
    """
    pos = {}
    for i, (base, start) in enumerate((((0, 0), tri[1]), ((1, 0), tri[2]), ((0, 1), tri[0]))):
        pos.setdefault(base, tri[i])
        fan, k = cx.sector(tri[i], start)
        for j, w in enumerate(fan):
            d = DIRS[(2 * i + j - k) % 6]
            p = (base[0] + d[0], base[1] + d[1])
            if pos.setdefault(p, w) != w:
                return None
    rows = []
    for x in NET:
        if x in pos:
            rows.append({pos[x]: 1})
            continue
        g = _ghost(cx, pos, x)
        if g is None:
            return None
        rows.append(g)
    return rows


def _ghost(cx, pos, x):
    for j in range(6):
        a = (x[0] + DIRS[j][0], x[1] + DIRS[j][1])
        b = (x[0] + DIRS[(j + 1) % 6][0], x[1] + DIRS[(j + 1) % 6][1])
        m = (a[0] + b[0] - x[0], a[1] + b[1] - x[1])
        if a in pos and b in pos and m in pos and cx.is_sharp(pos[a], pos[b]):
            s = {pos[a]: 1}
            s[pos[b]] = s.get(pos[b], 0) + 1
            s[pos[m]] = s.get(pos[m], 0) - 1
            return s
    return None
