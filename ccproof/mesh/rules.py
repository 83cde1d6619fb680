"""One Catmull-Clark step with OpenSubdiv's Sdc rules (creases, corners, boundary), as exact stencils.

This is the single rule implementation of the tagged meshes: :func:`refine_complex` turns a polygon
complex with edge and vertex sharpness into the stencils of every new point (exact rational
weights, ``flint.fmpq``) plus the child faces and their sharpness: the exact reference. The exact rows
of :func:`ccproof.mesh.polymesh.PolyMesh.subdivision_operator` (``exact=True``) and the exact
local matrices of :mod:`ccproof.evaluate` are read from these stencils; the float step (``V1 == S @ V0``:
:meth:`~ccproof.mesh.polymesh.PolyMesh.refine`, ``subdivision_operator()``, :mod:`ccproof.mesh.subdivision`)
is the vectorized step of :mod:`ccproof.mesh.step` (tests/mesh/test_step.py checks it and ``refine``
against these stencils bit for bit). Both read the weights through the scheme
:data:`ccproof.mesh.scheme.CATMARK` (the rule functions of :mod:`ccproof.rule_weights`:
:func:`face_point_weight`, :func:`smooth_edge_weights`, :func:`sharp_edge_weight`,
:func:`smooth_vertex_weights`, :func:`crease_vertex_weights`, re-exported here; :mod:`ccproof.mesh.step`
evaluates them exactly and rounds each row once): one rule implementation, exact or float by the number
``one`` it is given. The proof branch's ring matrices (:mod:`ccproof.algebra.subdivision`) read them too.
The topology is :class:`~ccproof.mesh.complex.Complex`'s, the crease rules and the rule table (which vertex and
edge rule applies where, and how a parent's and a child's masks blend: the one the float step reads) those of
:mod:`ccproof.mesh.crease` (re-exported here).

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
import math

import numpy as np

from ccproof.mesh.complex import Complex
from ccproof.mesh.crease import (
    CORNER,
    CREASE,
    DART,
    INFINITE,
    SMOOTH,
    becomes_smooth,
    child_sharpness_at_vertex,
    decrement,
    mask_kind,
    midpoint_weight,
    rule_blend,
    rule_code,
    vertex_rule,
)
from ccproof.mesh.scheme import CATMARK
from ccproof.rule_weights import (  # re-exported (the rule functions CATMARK wraps)
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
           "crease_limit_weights", "to_float", "SMOOTH", "DART", "CREASE", "CORNER"]

BOUNDARY_MODES = ("edge_only", "edge_and_corner", "none")
CREASE_METHODS = ("uniform", "chaikin")
TRIANGLE_RULES = ("catmark", "smooth")

_F32 = np.float32


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


def _fractional_weight(pv, cv, pe, ce, uniform):
    """Sdc ``ComputeFractionalWeightAtVertex`` in float32."""
    count, total = 0, _F32(0.0)
    if becomes_smooth(pv, cv, False):
        count, total = 1, _F32(pv)
    for p, c in zip(pe, ce):
        if becomes_smooth(p, c, uniform):
            total = _F32(total + _F32(p))
            count += 1
    if count == 0:
        return 0 * exact_one()
    w = _F32(total / _F32(count))
    return exact_one() if w > 1 else _exact(w)


def _add(out, c, s):
    for v, w in s.items():
        out[v] = out.get(v, 0) + c * w


def _vertex_mask(cx, v, fan, nb, fpts, kind, sh):
    """Sdc vertex-point mask of ``v`` for one :func:`~ccproof.mesh.crease.mask_kind` (0 smooth or dart, 2 crease
    along the sharp edges, 3 corner)."""
    one = exact_one()
    if kind == 0:
        wv, we, wf = CATMARK.vertex_point(len(fan), one)
        m = {v: wv}
        for c in fan:
            _add(m, wf, fpts[cx.face_of[c]])
            u = cx.dst(c)
            m[u] = m.get(u, 0) + we
        return m
    if kind == 2:
        wv, we = CATMARK.crease_vertex(one)
        m = {v: wv}
        for u, s in zip(nb, sh):
            if s > 0.0:
                m[u] = m.get(u, 0) + we
        return m
    return {v: CATMARK.corner_vertex(one)[0]}


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
        w = CATMARK.face_point(len(f), one)
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
        ce = child_sharpness_at_vertex(pe, not uniform)
        csharp[v] = dict(zip(es, ce))
        pv = cx.vsharp(v)
        if opts.boundary == "edge_and_corner" and not closed and len(fan) == 1 and cx.level == 0:
            pv = math.inf
        cv = decrement(pv)
        prule = rule_code(pv, sum(1 for s in pe if s > 0.0))  # the rule table the float step reads too
        crule = rule_code(cv, sum(1 for s in ce if s > 0.0))
        cp, cc = rule_blend(prule, crule, _fractional_weight(pv, cv, pe, ce, uniform), exact_one())
        m = _vertex_mask(cx, v, fan, nb, fpts, mask_kind(prule), pe)
        if cc != 0:  # else cp = 1
            out = {}
            _add(out, cp, m)
            _add(out, cc, _vertex_mask(cx, v, fan, nb, fpts, mask_kind(crule), ce))
            m = out
        vpts[v] = {u: x for u, x in m.items() if x != 0}
    return vpts, csharp


def _edge_stencils(cx, edge_list, fpts, csharp, uniform):
    """The edge-point stencils of :func:`refine_complex` (None where not wanted or not computable)."""
    E, opts = len(cx.edges), cx.options
    one = exact_one()
    half = CATMARK.sharp_edge(one)
    epts = [None] * E
    tri_smooth = opts.triangle_subdivision == "smooth" and cx.level == 0
    for e in edge_list:
        h = cx.edges[e]
        a, b = cx.org[h], cx.dst(h)
        t = cx.twin[h]
        s = cx.sharpness(e)
        if t < 0 and midpoint_weight(s, True) == 1.0:  # a boundary edge (infinitely sharp)
            epts[e] = {a: half, b: half}
            continue
        faces = [cx.face_of[h], cx.face_of[t]]
        vw, fw = CATMARK.edge_point(one)
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
            ca = cb = decrement(s)
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
        pw = midpoint_weight(s, ca > 0.0 and cb > 0.0)  # the edge rule table the float step reads too
        if pw == 1.0:
            epts[e] = {a: half, b: half}
            continue
        pw = _exact(pw)
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
        d = decrement(s)
        if d > 0.0:
            cvs[v] = d
    return ces, cvs
