"""Local triangle complexes and one exact Loop step on them (OpenSubdiv's Sdc Loop rules, infinitely
sharp tags).

A :class:`TriComplex` is a set of counter-clockwise triangles in local vertex labels with the tags
that the rules read: infinitely sharp edges, corner vertices, the boundary interpolation, and the
vertices whose fan is *complete* (all their mesh triangles present: only there the vertex rules apply
and a missing triangle means a boundary). :func:`loop_step` subdivides a complex once, exactly, and
returns the children's stencils; :func:`canonical_triangle_ring` lists the one-ring of a triangle (every
triangle sharing a vertex with it) in a deterministic order whose key identifies isomorphic rings.
"""

from __future__ import annotations

import math
import struct

from ccproof.errors import MeshError
from ccproof.evaluate.loop.box_spline import DIRS, NET
from ccproof.mesh.scheme import LOOP

__all__ = ["TriComplex", "loop_step", "canonical_triangle_ring", "regular_triangle_net", "SMOOTH", "CREASE", "CORNER"]

SMOOTH, CREASE, CORNER = "smooth", "crease", "corner"


def classify(vertex_sharpness, edge_sharpness, boundary_corner=False):
    """Sdc's vertex rule: corner (tagged, more than two sharp edges, or a boundary vertex of one triangle
    with ``edge_and_corner``), crease (two sharp edges) or smooth (none or one: a dart).

    >>> classify(0.0, [0.0, 2.5, 0.0, math.inf]), classify(0.5, []), classify(0.0, [1.0, 0.0])
    ('crease', 'corner', 'smooth')
    """
    n_sharp = sum(x > 0 for x in edge_sharpness)
    if vertex_sharpness > 0 or n_sharp > 2 or boundary_corner:
        return CORNER
    return CREASE if n_sharp == 2 else SMOOTH


class TriComplex:
    """Counter-clockwise triangles with tags (see the module docstring).

    Parameters
    ----------
    triangles : sequence of (a, b, c)
    sharp : dict (a, b) -> sharpness, or iterable of (a, b) (infinitely sharp)
        Tagged edges (either orientation; sharpness > 0, ``math.inf`` for infinitely sharp).
    corners : dict v -> sharpness, or iterable of int (infinitely sharp)
        Tagged vertices.
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
        pairs = sharp.items() if isinstance(sharp, dict) else ((e, math.inf) for e in sharp)
        self.sharp = {(min(a, b), max(a, b)): float(x) for (a, b), x in pairs if x > 0}
        items = corners.items() if isinstance(corners, dict) else ((v, math.inf) for v in corners)
        self.corners = {int(v): float(x) for v, x in items if x > 0}
        self.complete = None if complete is None else frozenset(complete)
        self.boundary = boundary
        #: the ends of the tagged edges (a ring without them has no tagged edge)
        self.sharp_vertices = frozenset(v for e in self.sharp for v in e)
        self._rules, self._regular = {}, {}  # rule(v), is_regular(v, start): a complex is not changed once built

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

    def sharpness(self, a, b):
        """The edge's sharpness: its tag, infinite on a boundary edge (one triangle), else 0."""
        if (a, b) not in self.opp or (b, a) not in self.opp:
            return math.inf
        return self.sharp.get((min(a, b), max(a, b)), 0.0)

    def is_sharp(self, a, b):
        """Sharp (Sdc's ``IsSharp``): sharpness > 0."""
        return self.sharpness(a, b) > 0

    def rule(self, v):
        """(rule, fan) of a complete vertex: its Sdc rule and its neighbours (counter-clockwise)."""
        hit = self._rules.get(v)
        if hit is None:
            fan, closed = self.fan(v, self.first[v])
            hit = self._rules[v] = (classify(self.corners.get(v, 0.0), [self.sharpness(v, w) for w in fan],
                                             not closed and len(fan) == 2 and self.boundary == "edge_and_corner"),
                                    fan)
        return hit[0], list(hit[1])

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
        hit = self._regular.get((v, start))
        if hit is None:
            rule, fan = self.rule(v)
            if rule == SMOOTH:
                hit = len(fan) == 6 and not any(self.is_sharp(v, w) for w in fan)
            else:
                hit = rule == CREASE and all(self.sharpness(v, w) in (0, math.inf) for w in fan) and \
                    len(self.sector(v, start)[0]) == 4
            self._regular[(v, start)] = hit
        return hit


def vertex_stencil(cx, v, one):
    """The Sdc Loop vertex point of complete vertex ``v``: dict label -> weight.

    Semi-sharp tags (Sdc, uniform creasing): the rule of the parent (its sharp edges and its corner tag) and
    of the child (sharpness less 1); where they differ, ``w P + (1 - w) C`` with ``w`` the mean parent
    sharpness of the tags that become smooth (at most 1), ``w`` and ``1 - w`` rounded to float32 as Sdc
    computes them.
    """
    rule, fan = cx.rule(v)
    if rule == SMOOTH:
        return _rule_mask(cx, v, SMOOTH, fan, (), one)
    vs = cx.corners.get(v, 0.0)
    es = [cx.sharpness(v, w) for w in fan]
    cvs = LOOP.child_sharpness(vs)
    ces = [LOOP.child_sharpness(x) for x in es]
    bcorner = rule == CORNER and classify(vs, es) != CORNER  # edge_and_corner's boundary corner: it stays
    crule = classify(cvs, ces, bcorner)
    sharp_now = [w for w, x in zip(fan, es) if x > 0]
    pmask = _rule_mask(cx, v, rule, fan, sharp_now, one)
    if crule == rule:
        return pmask
    trans = ([vs] if vs > 0 and cvs <= 0 else []) + [x for x, c in zip(es, ces) if x > 0 and c <= 0]
    w = 0.0
    for x in sorted(trans):  # in float32, as Sdc's Crease::ComputeFractionalWeightAtVertex (its order: its edges')
        w = _f32(w + x)
    w = min(_f32(w / len(trans)), 1.0) if trans else 0.0
    cmask = _rule_mask(cx, v, crule, fan, [u for u, x in zip(fan, ces) if x > 0], one)
    out = {}
    for m, f in ((pmask, one * w), (cmask, one * _f32(1 - w))):
        for x, y in m.items():
            out[x] = out.get(x, 0) + f * y
    return out


def _f32(x):
    """``x`` rounded to float32 (OpenSubdiv computes the fractional weights of semi-sharp rules in float)."""
    return struct.unpack("f", struct.pack("f", x))[0]


def _rule_mask(cx, v, rule, fan, sharp, one):
    if rule == CORNER:
        return {v: one}
    if rule == CREASE:
        wV, we = LOOP.crease_vertex(one)
        s = {v: wV}
        for w in sharp:
            s[w] = s.get(w, 0) + we
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
    """Sdc Loop edge point: sharpness > 1 the midpoint, 0 smooth, between the blend with weight s."""
    x = cx.sharpness(a, b)
    w = LOOP.sharp_edge(one)
    if x > 1:
        return {a: w, b: w}
    we, wo = LOOP.edge_point(one)
    s = {a: we, b: we}
    for y in (cx.opp[(a, b)], cx.opp[(b, a)]):
        s[y] = s.get(y, 0) + wo
    if x > 0:  # weights x and 1 - x, the latter in float32 as Sdc
        f, g = one * x, one * _f32(1 - x)
        s = {k: g * y for k, y in s.items()}
        s[a] += f * w
        s[b] += f * w
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
    tris, sharp = [], {}
    for a, b, c in cx.triangles:
        ab, bc, ca = (_label(edge_label, n, x, y) for x, y in ((a, b), (b, c), (c, a)))
        tris += [(a, ab, ca), (ab, b, bc), (ca, bc, c), (bc, ca, ab)]
    stencils += [None] * len(edge_label)
    for (a, b), e in edge_label.items():
        full = (a, b) in cx.opp and (b, a) in cx.opp
        if full or cx.is_complete(a) or cx.is_complete(b):
            stencils[e] = _edge_stencil(cx, a, b, one)
        x = LOOP.child_sharpness(cx.sharp.get((a, b), 0.0))
        if x > 0:
            sharp[(a, e)] = sharp[(e, b)] = x
    complete = None if cx.complete is None else \
        {v for v in cx.complete} | {e for (a, b), e in edge_label.items() if stencils[e] is not None}
    corners = {v: LOOP.child_sharpness(x) for v, x in cx.corners.items()}
    child = TriComplex(tris, sharp, corners, complete, cx.boundary)
    return child, stencils


def _label(edge_label, n, a, b):
    key = (min(a, b), max(a, b))
    if key not in edge_label:
        edge_label[key] = n + len(edge_label)
    return edge_label[key]


def canonical_triangle_ring(cx, tri):
    """The one-ring of triangle ``tri = (a, b, c)`` (its corners complete): (labels, key).

    Labels: a, b, c, then the fans of a (from b), b (from c) and c (from a), each new vertex at its
    first appearance. The key (ring triangles, sharp edges and corners in ring labels, boundary mode)
    is equal for isomorphic tagged rings: the cache key of everything computed per configuration.
    """
    a, b, c = tri
    pos, ring = {a: 0, b: 1, c: 2}, [a, b, c]
    fans = []
    for x, start in ((a, b), (b, c), (c, a)):
        fan, closed = cx.fan(x, start)
        for w in fan:
            if w not in pos:
                pos[w] = len(ring)
                ring.append(w)
        idx = [pos[w] for w in fan]
        if closed:
            idx.append(idx[0])
        fans.append((pos[x], idx))
    T = set()
    for px, idx in fans:
        for p, q in zip(idx, idx[1:]):  # triangle (px, p, q), listed from its lowest label
            T.add((px, p, q) if px < p and px < q else (p, q, px) if p < q else (q, px, p))
    sharp, corners = [], []
    if cx.sharp and not cx.sharp_vertices.isdisjoint(ring):  # the tagged edges of the ring's triangles (each
        # edge once: from its lower label)
        for t in T:
            for i, j in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0])):
                x = cx.sharp.get((min(ring[i], ring[j]), max(ring[i], ring[j])))
                if x is not None and (i < j or (ring[j], ring[i]) not in cx.opp):
                    sharp.append((min(i, j), max(i, j), x))
        sharp = sorted(set(sharp))
    if cx.corners:
        corners = sorted((i, cx.corners[v]) for i, v in enumerate(ring) if v in cx.corners)
    return ring, (tuple(sorted(T)), tuple(sharp), tuple(corners), cx.boundary)


def key_complex(key):
    """The complex of a ring key (its three first vertices complete)."""
    tris, sharp, corners, boundary = key
    return TriComplex(tris, {(a, b): x for a, b, x in sharp}, dict(corners), (0, 1, 2), boundary)


def regular_triangle_net(cx, tri):
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
        if a in pos and b in pos and m in pos and cx.sharpness(pos[a], pos[b]) == math.inf:
            s = {pos[a]: 1}
            s[pos[b]] = s.get(pos[b], 0) + 1
            s[pos[m]] = s.get(pos[m], 0) - 1
            return s
    return None
