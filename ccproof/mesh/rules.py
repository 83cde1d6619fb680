"""One Catmull-Clark step with OpenSubdiv's Sdc rules (creases, corners, boundary), as exact stencils.

This is the single rule implementation of the tagged meshes: :func:`refine_complex` turns a polygon
complex with edge and vertex sharpness into the stencils of every new point (exact rational
weights, ``flint.fmpq``) plus the child faces and their sharpness: the exact reference. The exact rows
of :func:`ccproof.mesh.polymesh.PolyMesh.subdivision_operator` (``exact=True``) and the exact
local matrices of :mod:`ccproof.evaluate` are read from these stencils; the float step (``V1 == S @ V0``:
:meth:`~ccproof.mesh.polymesh.PolyMesh.refine`, ``subdivision_operator()``, :mod:`ccproof.mesh.subdivision`)
is the vectorized step of :mod:`ccproof.mesh.step` (tests/mesh/test_step.py checks it and ``refine``
against these stencils bit for bit), which takes its weights from the same rule functions
of :mod:`ccproof.rule_weights` (:func:`face_point_weight`, :func:`smooth_edge_weights`,
:func:`sharp_edge_weight`, :func:`smooth_vertex_weights`, :func:`crease_vertex_weights`, re-exported
here; :mod:`ccproof.mesh.step` evaluates them exactly and rounds each row once): one rule
implementation, exact or float by the number ``one`` it is given. The proof branch's ring matrices
(:mod:`ccproof.algebra.subdivision`) read them too.

Rules (Sdc ``SCHEME_CATMARK``, OpenSubdiv 3.6 ``sdc/scheme.h``, ``sdc/catmarkScheme.h``,
``sdc/crease.cpp``; sharpness ``s`` is IEEE float32 as in OpenSubdiv, ``s >= 10`` is infinite,
boundary edges are infinitely sharp):

* face point: the centroid of the face's vertices;
* edge point: smooth ``(a + b + f0 + f1) / 4`` (f0, f1 the new face points; with
  ``TRI_SUB_SMOOTH`` at level 0 a triangle gets the face weight 0.47) if ``s <= 0``; the midpoint
  if ``s > 0`` and both child edges stay sharp; otherwise ``s * midpoint + (1 - s) * smooth``;
* vertex point, by the rule of the vertex (vertex sharpness > 0 or more than two sharp edges:
  *corner*, ``V``; two sharp edges: *crease*, ``(3/4) V + (1/8)(e0 + e1)`` along them; one (dart)
  or none: *smooth*, ``((k - 2) V + sum e_j / k + sum f_j / k) / k``); when the rule of the child
  vertex differs, ``w * parent mask + (1 - w) * child mask`` with Sdc's fractional weight ``w``
  (mean parent sharpness of the features that become smooth, clamped to 1);
* child sharpness: ``CREASE_UNIFORM``: ``s - 1`` (0 below); ``CREASE_CHAIKIN``: at an end vertex
  with ``m >= 2`` semi-sharp edges ``0.75 s + 0.25 mean(other semi-sharp) - 1``; vertex
  sharpness ``s - 1``.

Layout of the refined complex (as :mod:`ccproof.mesh.subdivision`): new vertex ``v < n`` is the
vertex point of ``v``, ``n + e`` the edge point of edge ``e`` (order of first appearance in the face
list), ``n + E + f`` the face point of face ``f``; child ``offset(f) + k`` of an n-sided face is the
quad ``(v_k', e_{k,k+1}', f', e_{k-1,k}')``.
"""

from __future__ import annotations

import functools
import itertools
import math

import numpy as np

from ccproof.rule_weights import (
    crease_limit_weights,
    crease_vertex_weights,
    face_point_weight,
    sharp_edge_weight,
    smooth_edge_weights,
    smooth_limit_weights,
    smooth_vertex_weights,
)

__all__ = ["Options", "Complex", "refine_complex", "INFINITE", "BOUNDARY_MODES", "CREASE_METHODS",
           "TRIANGLE_RULES", "vertex_rule", "exact_one", "face_point_weight", "smooth_edge_weights",
           "sharp_edge_weight", "smooth_vertex_weights", "crease_vertex_weights", "smooth_limit_weights",
           "crease_limit_weights", "to_float"]

#: OpenSubdiv's Sdc::Crease::SHARPNESS_INFINITE: sharpness at or above it is infinite
INFINITE = 10.0

#: complexes of at least this many faces get their half-edge lists from numpy (the whole mesh); the many
#: small local complexes of the evaluator keep the plain loop (faster below this size)
_VECTORIZED_FACES = 64
BOUNDARY_MODES = ("edge_only", "edge_and_corner", "none")
CREASE_METHODS = ("uniform", "chaikin")
TRIANGLE_RULES = ("catmark", "smooth")

SMOOTH, DART, CREASE, CORNER = "smooth", "dart", "crease", "corner"

_F32 = np.float32
_ONE = _F32(1.0)


@functools.lru_cache(maxsize=1)
def exact_one():
    """The exact rational 1 (``flint.fmpq``): the ``one`` that makes the rule functions exact.

    python-flint's rationals are used instead of :class:`fractions.Fraction` for speed (the
    local refinements of the evaluator are exact); imported on first use (``import ccproof``
    stays cheap).

    Returns
    -------
    flint.fmpq
        The rational 1; pass it as ``one`` to the rule functions below (or ``1.0`` for floats).

    Examples
    --------
    >>> one = exact_one()
    >>> one / 3 * 3 == 1, type(one).__name__
    (True, 'fmpq')
    """
    import flint

    return flint.fmpq(1)


def _exact(x):
    """The exact rational value of a float (a float32 sharpness or the 0.47 triangle weight)."""
    p, q = float(x).as_integer_ratio()
    return exact_one() * p / q


def to_float(w):
    """Correctly rounded float of an exact weight.

    Parameters
    ----------
    w : int, float, flint.fmpq or fractions.Fraction

    Returns
    -------
    float
        Python's int division of numerator by denominator (correctly rounded).

    Examples
    --------
    >>> from fractions import Fraction
    >>> to_float(exact_one() / 3) == 1 / 3, to_float(Fraction(1, 10)) == 0.1, to_float(2)
    (True, True, 2.0)
    """
    q = getattr(w, "q", None)
    if q is not None:  # flint.fmpq
        return int(w.p) / int(q)
    if isinstance(w, (int, float)):
        return float(w)
    return w.numerator / w.denominator


class Options:
    """Sdc options: boundary interpolation, creasing method, triangle subdivision.

    Parameters
    ----------
    boundary : {"edge_only", "edge_and_corner", "none"}
        ``VTX_BOUNDARY_EDGE_ONLY`` (default), ``VTX_BOUNDARY_EDGE_AND_CORNER``, ``VTX_BOUNDARY_NONE``.
    crease_method : {"uniform", "chaikin"}
    triangle_subdivision : {"catmark", "smooth"}

    Notes
    -----
    OpenSubdiv's ``Sdc::Options`` (docs/evaluate.md "Tagged polygon meshes (OpenSubdiv's features)").

    Examples
    --------
    >>> Options().key()
    ('edge_only', 'uniform', 'catmark')
    >>> Options(boundary="edges")
    Traceback (most recent call last):
    ...
    ccproof.errors.MeshError: boundary interpolation must be one of (...), got 'edges'
    """

    __slots__ = ("boundary", "crease_method", "triangle_subdivision")

    def __init__(self, boundary="edge_only", crease_method="uniform", triangle_subdivision="catmark"):
        from ccproof.errors import MeshError

        if boundary not in BOUNDARY_MODES:
            raise MeshError(f"boundary interpolation must be one of {BOUNDARY_MODES}, got {boundary!r}")
        if crease_method not in CREASE_METHODS:
            raise MeshError(f"crease method must be one of {CREASE_METHODS}, got {crease_method!r}")
        if triangle_subdivision not in TRIANGLE_RULES:
            raise MeshError(f"triangle subdivision must be one of {TRIANGLE_RULES}, got {triangle_subdivision!r}")
        self.boundary = boundary
        self.crease_method = crease_method
        self.triangle_subdivision = triangle_subdivision

    def key(self):
        return (self.boundary, self.crease_method, self.triangle_subdivision)

    def __eq__(self, other):
        return isinstance(other, Options) and self.key() == other.key()

    def __hash__(self):
        return hash(self.key())

    def __repr__(self):
        return "Options(boundary={!r}, crease_method={!r}, triangle_subdivision={!r})".format(*self.key())


def _is_sharp(s):
    return s > 0.0


def _is_infinite(s):
    return s >= INFINITE


def _is_semi_sharp(s):
    return 0.0 < s < INFINITE


def _decrement(s):
    if s <= 0.0:
        return 0.0
    if s >= INFINITE:
        return math.inf
    if s > 1.0:
        return float(_F32(s) - _ONE)
    return 0.0


def _child_sharpness_at_vertex(edge_sharpness, chaikin):
    """Sdc ``SubdivideEdgeSharpnessesAroundVertex``: child sharpness of every edge at one vertex."""
    if not chaikin or len(edge_sharpness) < 2:
        return [_decrement(s) for s in edge_sharpness]
    semi = [s for s in edge_sharpness if _is_semi_sharp(s)]
    if not semi:
        return list(edge_sharpness)
    total = _F32(0.0)
    for s in semi:
        total = _F32(total + _F32(s))
    out = []
    for s in edge_sharpness:
        if s <= 0.0:
            out.append(0.0)
        elif s >= INFINITE:
            out.append(math.inf)
        elif len(semi) == 1:
            out.append(_decrement(s))
        else:
            avg = _F32((total - _F32(s)) / _F32(len(semi) - 1))
            c = _F32(_F32(_F32(0.75) * _F32(s)) + _F32(_F32(0.25) * avg)) - _ONE
            out.append(float(c) if c > 0 else 0.0)
    return out


def vertex_rule(vertex_sharpness, edge_sharpness):
    """Sdc ``DetermineVertexVertexRule``: 'corner', 'crease', 'dart' or 'smooth'.

    Parameters
    ----------
    vertex_sharpness : float
    edge_sharpness : sequence of float
        Sharpness of the edges at the vertex.

    Returns
    -------
    str
        A sharp vertex or three or more sharp edges: corner; two: crease; one: dart; none: smooth.

    Examples
    --------
    >>> import math
    >>> [vertex_rule(0.0, e) for e in ([0, 0, 0, 0], [math.inf, 0, 0, 0], [2, 0, 2, 0], [1, 1, 1, 0])]
    ['smooth', 'dart', 'crease', 'corner']
    >>> vertex_rule(1.0, [0, 0, 0, 0])
    'corner'
    """
    if vertex_sharpness > 0.0:
        return CORNER
    n = sum(1 for s in edge_sharpness if s > 0.0)
    return (SMOOTH, DART, CREASE)[n] if n <= 2 else CORNER


def _fractional_weight(pv, cv, pe, ce, uniform):
    """Sdc ``ComputeFractionalWeightAtVertex`` in float32."""
    count, total = 0, _F32(0.0)
    if pv > 0.0 and cv <= 0.0:
        count, total = 1, _F32(pv)
    for p, c in zip(pe, ce):
        if uniform:
            hit = p > 0.0 and p <= 1.0
        else:
            hit = p > 0.0 and c <= 0.0
        if hit:
            total = _F32(total + _F32(p))
            count += 1
    if count == 0:
        return 0 * exact_one()
    w = _F32(total / _F32(count))
    return exact_one() if w > 1 else _exact(w)


def _add(out, c, s):
    for v, w in s.items():
        out[v] = out.get(v, 0) + c * w


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
        cs = _child_sharpness_at_vertex([self.sharpness(e) for e in es], self.options.crease_method == "chaikin")
        return dict(zip(es, cs))


def _vertex_mask(cx, v, fan, nb, fpts, rule, sh):
    """Sdc vertex-point mask of ``v`` for one rule (smooth/dart, crease along the sharp edges, corner)."""
    one = exact_one()
    if rule in (SMOOTH, DART):
        wv, we, wf = smooth_vertex_weights(len(fan), one)
        m = {v: wv}
        for c in fan:
            _add(m, wf, fpts[cx.face_of[c]])
            u = cx.dst(c)
            m[u] = m.get(u, 0) + we
        return m
    if rule == CREASE:
        wv, we = crease_vertex_weights(one)
        m = {v: wv}
        for u, s in zip(nb, sh):
            if s > 0.0:
                m[u] = m.get(u, 0) + we
        return m
    return {v: one}


def refine_complex(cx, vertices=None, edges=None):
    """One step of the Sdc Catmark rules on a :class:`Complex`, as exact stencils.

    Parameters
    ----------
    cx : Complex
    vertices : iterable of int, optional
        Vertices whose vertex point (and child sharpness) to compute; default: every vertex with a
        single fan. Others get ``None``.
    edges : iterable of int, optional
        Edges whose edge point to compute; default: all (an edge point needs the child sharpness at
        both ends, so only edges whose end vertices have a single fan are computed).

    Returns
    -------
    stencils : list of (dict[int, flint.fmpq] or None), length n + E + F
        New vertex as a combination of old vertices (layout in the module docstring).
    children : list of tuple of 4 int
        Child quads, ``offset(f) + k`` for corner k of face f (offsets = cumulative face sizes).
    child_edge_sharpness : dict[(int, int), float]
        Sharpness of the child edges that are sharp and could be computed (halves of parent edges
        at computed vertices).
    child_vertex_sharpness : dict[int, float]
        Decremented vertex sharpness of the vertex points.

    Notes
    -----
    bmz04 Fig. 1 (docs/readings.md R1) with OpenSubdiv's Sdc crease, corner and boundary rules
    (docs/evaluate.md "Tagged polygon meshes (OpenSubdiv's features)").

    Examples
    --------
    A single quad: its boundary edges are infinitely sharp, so a corner gets the crease rule
    ``(3/4) V + (1/8)(e0 + e1)``, the edges their midpoints and the face its centroid:

    >>> cx = Complex([[0, 1, 2, 3]], {}, {}, Options())
    >>> stencils, children, ces, cvs = refine_complex(cx)
    >>> len(stencils), stencils[0], stencils[4], stencils[8]
    (9, {0: 3/4, 1: 1/8, 3: 1/8}, {0: 1/2, 1: 1/2}, {0: 1/4, 1: 1/4, 2: 1/4, 3: 1/4})
    >>> children[0], ces[(0, 4)]
    ((0, 4, 8, 7), inf)
    """
    n = cx.n_vertices
    E = len(cx.edges)
    opts = cx.options
    uniform = opts.crease_method == "uniform"
    one = exact_one()
    fpts = []
    for f in cx.faces:
        w = face_point_weight(len(f), one)
        fpts.append({v: w for v in f})
    want_v = range(n) if vertices is None else sorted(set(vertices))
    vpts, csharp = _vertex_stencils(cx, want_v, fpts, uniform)
    edge_list = range(E) if edges is None else sorted(set(edges))
    epts = _edge_stencils(cx, edge_list, fpts, csharp, uniform)
    stencils = vpts + epts + fpts
    children = []
    for g, f in enumerate(cx.faces):
        fp = n + E + g
        s0, k = cx.start[g], len(f)
        for i in range(k):
            h = s0 + i
            children.append((f[i], n + cx.he_edge[h], fp, n + cx.he_edge[s0 + (i - 1) % k]))
    ces, cvs = _child_tags(cx, want_v, csharp)
    return stencils, children, ces, cvs


def _vertex_stencils(cx, want_v, fpts, uniform):
    """(vertex-point stencils of :func:`refine_complex`, None where not wanted or not computable; the child
    sharpness ``{v: {edge: s}}`` of the edges' halves at the wanted vertices)."""
    n, opts = cx.n_vertices, cx.options
    csharp = {}  # v -> {edge: child sharpness of its half at v}
    vpts = [None] * n
    for v in want_v:
        ve = cx.vertex_edges(v)
        if ve is None:
            continue
        es, nb, fan, closed = ve
        pe = [cx.sharpness(e) for e in es]
        ce = _child_sharpness_at_vertex(pe, not uniform)
        csharp[v] = dict(zip(es, ce))
        pv = cx.vsharp(v)
        if opts.boundary == "edge_and_corner" and not closed and len(fan) == 1 and cx.level == 0:
            pv = math.inf
        cv = _decrement(pv)
        prule = vertex_rule(pv, pe)
        crule = vertex_rule(cv, ce)

        m = _vertex_mask(cx, v, fan, nb, fpts, prule, pe)
        if prule not in (SMOOTH, DART) and crule != prule:
            w = _fractional_weight(pv, cv, pe, ce, uniform)
            mc = _vertex_mask(cx, v, fan, nb, fpts, crule, ce)
            out = {}
            _add(out, w, m)
            _add(out, 1 - w, mc)
            m = out
        vpts[v] = {u: x for u, x in m.items() if x != 0}
    return vpts, csharp


def _edge_stencils(cx, edge_list, fpts, csharp, uniform):
    """The edge-point stencils of :func:`refine_complex` (None where not wanted or not computable)."""
    E, opts = len(cx.edges), cx.options
    one = exact_one()
    half = sharp_edge_weight(one)
    epts = [None] * E
    tri_smooth = opts.triangle_subdivision == "smooth" and cx.level == 0
    for e in edge_list:
        h = cx.edges[e]
        a, b = cx.org[h], cx.dst(h)
        t = cx.twin[h]
        s = cx.sharpness(e)
        if s > 0.0 and t < 0:
            epts[e] = {a: half, b: half}
            continue
        faces = [cx.face_of[h], cx.face_of[t]]
        vw, fw = smooth_edge_weights(one)
        if tri_smooth and any(len(cx.faces[g]) == 3 for g in faces):
            w0, w1 = (_exact(0.470) if len(cx.faces[g]) == 3 else fw for g in faces)
            fw = (w0 + w1) / 2
            vw = (1 - 2 * fw) / 2
        smooth = {a: vw, b: vw}
        for g in faces:
            _add(smooth, fw, fpts[g])
        if s <= 0.0:
            epts[e] = smooth
            continue
        if uniform:
            ca = cb = _decrement(s)
        else:
            ends = []
            for u in (a, b):
                d = csharp.get(u)
                if d is None:
                    d = cx.child_edge_sharpness(u)
                if d is None:
                    break
                ends.append(d[e])
            if len(ends) < 2:
                continue  # an end vertex without a single fan in the complex: not computable
            ca, cb = ends
        if ca > 0.0 and cb > 0.0:
            epts[e] = {a: half, b: half}
            continue
        pw = _exact(_F32(s))
        out = {}
        _add(out, 1 - pw, smooth)
        _add(out, pw, {a: half, b: half})
        epts[e] = {u: x for u, x in out.items() if x != 0}
    return epts


def _child_tags(cx, want_v, csharp):
    """(child edge sharpness ``{(v, n + e): s}``, child vertex sharpness ``{v: s}``) of :func:`refine_complex`."""
    n, opts = cx.n_vertices, cx.options
    ces = {}
    for v, d in csharp.items():
        for e, s in d.items():
            if s > 0.0:
                ces[(v, n + e)] = s  # v < n + e always
    cvs = {}
    for v in want_v:
        s = cx.vsharp(v)
        if opts.boundary == "edge_and_corner" and cx.level == 0:
            fan, closed = cx.fan(v)
            if fan is not None and not closed and len(fan) == 1:
                s = math.inf
        d = _decrement(s)
        if d > 0.0:
            cvs[v] = d
    return ces, cvs
