"""The Catmull-Clark step with OpenSubdiv's Sdc rules, vectorized, as one sparse operator.

:func:`catmark_operator` is the float step of every caller: :meth:`ccproof.mesh.polymesh.PolyMesh.refine`
and ``subdivision_operator()`` (the tagged polygon meshes; the evaluator's setup refines with it), the
untagged quad step of :func:`ccproof.mesh.subdivision_matrix` and the applications' tagged step
(:func:`ccproof.apps.control_mesh.tagged_step`); each caller passes its mesh's
:class:`~ccproof.mesh.halfedges.HalfEdges` (``halfedges=``), which the step reads instead of pairing the
half-edges again. It assembles, over the whole
mesh with numpy, the rules that :func:`ccproof.mesh.rules.refine_complex` states as exact stencils
(the reference of the tests for the assembly; both read one rule table, :func:`~ccproof.mesh.crease.rule_code`,
:func:`~ccproof.mesh.crease.rule_blend` and :func:`~ccproof.mesh.crease.midpoint_weight`, which the
OpenSubdiv comparisons check; its fast path for untagged meshes is :func:`ccproof.mesh.step_fast.catmark_step`;
the weights are read through the scheme,
:data:`ccproof.mesh.scheme.CATMARK`, the same rule functions of :mod:`ccproof.rule_weights`, evaluated in
rationals and rounded once per row; the step only splits faces, so another quad-splitting scheme is
another :class:`~ccproof.mesh.scheme.Scheme` value):

* face point: the centroid;
* edge point: boundary edges are infinitely sharp (the midpoint); an interior edge of sharpness
  ``s``: smooth ``(a + b + f0 + f1) / 4`` if ``s <= 0`` (``TRI_SUB_SMOOTH`` at level 0: face weight
  0.47 at a triangle), the midpoint if both child halves stay sharp, else
  ``s * midpoint + (1 - s) * smooth``;
* vertex point: Sdc's rule of the vertex (a sharp vertex or three or more sharp edges: corner; two:
  crease along them; one or none: smooth); when the child's rule differs,
  ``w * parent mask + (1 - w) * child mask`` with Sdc's fractional weight ``w`` (float32, summed in
  the order of the vertex's fan, as :func:`~ccproof.mesh.rules.refine_complex` sums);
* child sharpness: ``CREASE_UNIFORM`` ``s - 1``, ``CREASE_CHAIKIN`` the average rule at each end;
  vertex sharpness ``s - 1``; ``VTX_BOUNDARY_EDGE_AND_CORNER`` makes a one-face boundary vertex an
  infinitely sharp corner at level 0; holes pass to the children.

The rules are bmz04 Fig. 1 (docs/readings.md R1) with OpenSubdiv's Sdc crease, corner and boundary rules
(``sdc/catmarkScheme.h``, ``sdc/crease.cpp``; docs/evaluate.md "Tagged polygon meshes").

Layout (that of :mod:`ccproof.mesh.rules` and :mod:`ccproof.mesh.subdivision`): new vertex ``v < n``
is the vertex point of ``v``, ``n + e`` the edge point of edge ``e``, ``n + E + f`` the face point
of face ``f``; child ``offsets[f] + k`` of face ``f`` is ``(v_k', e_{k,k+1}', f', e_{k-1,k}')``.
The mesh must be manifold (:attr:`ccproof.mesh.polymesh.PolyMesh.manifold` is); an unused vertex
gets an empty row.

Every weight is the correctly rounded value of the exact stencil: a row's terms (a dyadic coefficient, 1
or a float32 fractional weight or sharpness, times a rule's rational weight) are scaled by the row's
common denominator ``R`` (``8 k^2 lcm(face sizes)`` at a vertex of valence k, ``4 lcm(s0, s1)`` at an
edge, ``s`` at a face), which makes each an integer times a dyadic, summed exactly in float64, and
divided by ``R`` once. That holds while ``R`` times the float32 coefficients' 2^24 stays below 2^53
(every real valence and face size). ``TRI_SUB_SMOOTH``'s 0.47 (a float64 weight) times a float32 midpoint
weight needs more bits: those edge points' weights are computed in rationals, once per distinct midpoint
weight and pair of face sizes, and rounded once (:func:`_tri_smooth_rows`).
"""

from __future__ import annotations

from fractions import Fraction
from typing import NamedTuple

import numpy as np

from ccproof.mesh.crease import (
    INFINITE,
    becomes_smooth,
    chaikin_sharpness,
    decrement,
    mask_kind,
    midpoint_weight,
    rule_blend,
    rule_code,
)
from ccproof.mesh.rules import Options
from ccproof.mesh.scheme import CATMARK
from ccproof.mesh.step_topology import step_topology, vertex_fans

__all__ = ["catmark_operator", "Step", "StepOptions"]

_F32 = np.float32


class StepOptions(NamedTuple):
    """How :func:`catmark_operator` takes the step and what it returns.

    Attributes
    ----------
    sdc : ccproof.mesh.rules.Options, optional
        The Sdc options (default ``Options()``).
    level : int
        The level of the mesh (``TRI_SUB_SMOOTH`` and ``EDGE_AND_CORNER`` act at level 0).
    columns : array_like of int, shape (n,), optional
        The column of every vertex (default: its index): vertices sharing a column have their terms
        summed exactly, before the one division (the copies of a split non-manifold vertex:
        :meth:`ccproof.mesh.polymesh.PolyMesh.subdivision_operator`).
    n_columns : int, optional
        Number of columns (default: ``max(columns) + 1``, or n).
    sparse : bool
        Build ``S`` (scipy); False: ``S`` is None and scipy is not imported (``csr`` holds the operator).

    Examples
    --------
    >>> StepOptions(level=1, sparse=False)
    StepOptions(sdc=None, level=1, columns=None, n_columns=None, sparse=False)
    """

    sdc: object = None
    level: int = 0
    columns: object = None
    n_columns: object = None
    sparse: bool = True

    def column_count(self, n):
        """The operator's number of columns on a mesh of ``n`` vertices.

        >>> StepOptions().column_count(5), StepOptions(columns=[0, 1, 1]).column_count(3)
        (5, 2)
        """
        if self.n_columns is not None:
            return int(self.n_columns)
        return n if self.columns is None else int(np.max(self.columns, initial=-1)) + 1


class Step(NamedTuple):
    """The result of :func:`catmark_operator`.

    Attributes
    ----------
    S : scipy.sparse.csr_matrix, shape (n + E + m, n)
        ``V1 = S @ V0``.
    faces : ndarray of int64, shape (H, 4)
        The child quads (H = sum of the face sizes).
    edges : ndarray of int64, shape (E, 2)
        The parent edges ``(a, b)`` in the numbering of the edge points (``a`` the origin of the
        edge's first half-edge).
    child_creases : (ndarray of int64, shape (k, 2), ndarray of float64, shape (k,))
        Sharp child edges ``(v, n + e)`` (the halves of sharp parent edges) and their sharpness.
    child_corners : (ndarray of int64, shape (j,), ndarray of float64, shape (j,))
        Sharp child vertices and their sharpness.
    child_holes : ndarray of bool, shape (H,)
    csr : (ndarray of int64, shape (N + 1,), ndarray of int64, shape (nnz,), ndarray of float64, shape (nnz,))
        ``S`` as CSR arrays ``(indptr, indices, data)`` (N = n + E + m rows, increasing columns in each
        row, no zero): what ``S`` wraps, and the operator without scipy (:func:`apply_csr`).
    """

    S: object
    faces: np.ndarray
    edges: np.ndarray
    child_creases: tuple
    child_corners: tuple
    child_holes: np.ndarray
    csr: tuple


def _f32_sums(seg, val, n):
    """Per segment ``seg`` (sorted in summation order), the float32 sum of ``val`` taken left to right
    from float32 0 (Sdc's loops), and the count of terms."""
    count = np.bincount(seg, minlength=n)
    start = np.r_[0, np.cumsum(count)][:-1]
    rank = np.arange(seg.size) - start[seg]
    total = np.zeros(n, dtype=_F32)
    for j in range(int(count.max()) if seg.size else 0):
        sel = rank == j
        total[seg[sel]] = total[seg[sel]] + val[sel].astype(_F32)
    return total, count


def _csr(rows, cols, vals, R, ncols):
    """CSR arrays ``(indptr, indices, data)`` of the terms ``vals`` at ``(rows, cols)``: the terms of an
    entry summed (exactly: integers times dyadics), divided by the row's common denominator ``R[row]``
    once, zeros dropped; columns increasing in each row."""
    N = R.size
    key = rows * max(ncols, 1) + cols
    order = np.argsort(key, kind="stable")
    key = key[order]
    start = np.flatnonzero(np.r_[True, key[1:] != key[:-1]]) if key.size else np.zeros(0, dtype=np.int64)
    data = np.add.reduceat(vals[order], start) if key.size else np.zeros(0)
    r = key[start] // max(ncols, 1)
    data = data / R[r]
    keep = data != 0
    r, data = r[keep], data[keep]
    indptr = np.r_[0, np.cumsum(np.bincount(r, minlength=N))].astype(np.int64)
    return indptr, (key[start] % max(ncols, 1))[keep].astype(np.int64), data


def _tri_smooth_rows(te, t, pw, columns, scheme):
    """The rows of the ``TRI_SUB_SMOOTH`` edge points ``te`` as final, correctly rounded weights.

    Their face weight ``(w0 + w1) / 2`` (``w = 0.47`` at a triangle, a float64 weight: 2^-54 granular)
    with a float32 midpoint weight ``pw`` needs more bits than the integer scaling holds: each entry's
    exact value is a sum ``c0 * end + c1 * rest1 + c2 * rest2`` of the row's three exact weights (an end,
    any other vertex of the first face, of the second; c counts the terms a column gathers: copies of a
    vertex merged by ``columns``), computed in rationals once per distinct (pw, face sizes, counts) and
    rounded once.

    Returns
    -------
    rows, cols : ndarray of int64, shape (k,)
    vals : ndarray of float64, shape (k,)
    """
    n, a, b, h1, h2, face, sz, off, pos, idx = t.n, t.a, t.b, t.h1, t.h2, t.face, t.sz, t.off, t.pos, t.idx
    one = Fraction(1)
    half = scheme.sharp_edge(one)
    vw0, fw0 = scheme.edge_point(one)
    s1, s2 = sz[face[h1[te]]], sz[face[h2[te]]]
    pws, pinv = np.unique(pw[te], return_inverse=True)
    B = int(max(s1.max(), s2.max())) + 1
    ckey, cinv = np.unique((pinv.reshape(-1) * B + s1) * B + s2, return_inverse=True)
    cinv = cinv.reshape(-1)
    combo = [(float(pws[x // (B * B)]), int(x // B % B), int(x % B)) for x in ckey.tolist()]
    # terms: (edge position, column, kind 0 end / 1 first face / 2 second face)
    t_e, t_c, t_k = [np.arange(te.size)] * 2, [a[te], b[te]], [np.zeros(te.size, dtype=np.int64)] * 2
    for kind, h in ((1, h1[te]), (2, h2[te])):
        f = face[h]
        for j in range(2, int(sz[f].max())):
            sel = np.flatnonzero(sz[f] > j)
            t_e.append(sel)
            t_c.append(idx[off[f[sel]] + (pos[h[sel]] + j) % sz[f[sel]]])
            t_k.append(np.full(sel.size, kind, dtype=np.int64))
    t_e, t_c, t_k = (np.concatenate(x) for x in (t_e, t_c, t_k))
    if columns is not None:
        t_c = np.asarray(columns, dtype=np.int64)[t_c]
    ncol = int(t_c.max()) + 1
    key = t_e * ncol + t_c
    ukey, ginv = np.unique(key, return_inverse=True)
    ginv = ginv.reshape(-1)
    counts = np.zeros((ukey.size, 3), dtype=np.int64)
    np.add.at(counts, (ginv, t_k), 1)
    ge = ukey // ncol
    C = int(counts.max()) + 1
    spec, sinv = np.unique(((cinv[ge] * C + counts[:, 0]) * C + counts[:, 1]) * C + counts[:, 2],
                           return_inverse=True)
    tri_w = Fraction(0.470)
    w = []
    for x in spec.tolist():
        ci, c0, c1, c2 = x // C ** 3, x // C ** 2 % C, x // C % C, x % C
        p, z1, z2 = combo[ci]
        P = Fraction(p)
        fw = ((tri_w if z1 == 3 else fw0) + (tri_w if z2 == 3 else fw0)) / 2
        vw = (1 - 2 * fw) / 2
        rest1 = (1 - P) * fw * scheme.face_point(z1, one)
        rest2 = (1 - P) * fw * scheme.face_point(z2, one)
        end = P * half + (1 - P) * vw + rest1 + rest2
        w.append(float(c0 * end + c1 * rest1 + c2 * rest2))
    return n + te[ge], ukey % ncol, np.asarray(w, dtype=np.float64)[sinv.reshape(-1)]


def _ratios(rule, x):
    """``(numerators, denominators)``, int64 arrays like ``x``, of the exact rule weight ``rule(x_i)``."""
    x = np.asarray(x, dtype=np.int64)
    u, inv = np.unique(x, return_inverse=True)
    w = [rule(int(v)) for v in u.tolist()]
    t = np.array([q.numerator for q in w], dtype=np.int64)
    d = np.array([q.denominator for q in w], dtype=np.int64)
    return t[inv.reshape(x.shape)], d[inv.reshape(x.shape)]


def catmark_operator(n, indices, sizes, *, halfedges=None, edge_of_halfedge=None, edge_sharpness=None,
                     vertex_sharpness=None, holes=None, options=None, scheme=CATMARK):
    """One step of a quad-splitting scheme (Catmull-Clark) on a tagged manifold polygon mesh, as a sparse
    operator (module docstring).

    Parameters
    ----------
    n : int
        Number of vertices.
    indices : array_like of int, shape (H,)
        The faces' vertices, face after face, counter-clockwise.
    sizes : array_like of int, shape (m,)
        Face sizes (>= 3).
    halfedges : ccproof.mesh.halfedges.HalfEdges, optional
        The caller's ``mesh.halfedges`` of these faces (ValueError otherwise): the step's topology (no pairing
        of half-edges here); built from the faces when None. A non-manifold edge is refused (MeshError).
    edge_of_halfedge : array_like of int, shape (H,), optional
        The edge points' numbering (0..E-1); default: by first occurrence along the faces (:class:`Complex
        <ccproof.mesh.complex.Complex>`'s); ``halfedges.edge_of``: the QuadMesh numbering.
    edge_sharpness : ndarray, shape (E,), or dict[(int, int), float], optional
        Sharpness per edge of that numbering, or a dict keyed by ``(min, max)`` vertex pairs; ``>= 10``
        infinite. Boundary edges are infinitely sharp whatever the tag.
    vertex_sharpness : ndarray, shape (n,), or dict[int, float], optional
    holes : array_like of bool, shape (m,), optional
    options : StepOptions, optional
        The Sdc options, the mesh's level, the output's columns and whether to build ``S``.
    scheme : ccproof.mesh.scheme.Scheme
        The rules' weights (:data:`~ccproof.mesh.scheme.CATMARK`); a scheme that splits faces into quads
        (ValueError otherwise, naming it).

    Returns
    -------
    Step
        ``S`` (n + E + m, n_columns) and its arrays, the child faces, the edges, the child tags and holes.

    Examples
    --------
    One quad: corners take the crease rule along the boundary, edges their midpoints:

    >>> st = catmark_operator(4, [0, 1, 2, 3], [4])
    >>> st.S.shape, st.S[0].toarray()[0].tolist(), st.S[4].toarray()[0].tolist(), st.faces[0].tolist()
    ((9, 4), [0.75, 0.125, 0.0, 0.125], [0.5, 0.5, 0.0, 0.0], [0, 4, 8, 7])

    A crease of sharpness 0.5 across the middle of two quads blends its edge point (half the midpoint,
    half the smooth rule); its halves are smooth after the step, those of the boundary edges stay sharp:

    >>> st = catmark_operator(6, [0, 1, 4, 3, 1, 2, 5, 4], [4, 4], edge_sharpness={(1, 4): 0.5})
    >>> e = int(np.flatnonzero((st.edges == [1, 4]).all(axis=1))[0])
    >>> st.S[6 + e].toarray()[0].tolist(), len(st.child_creases[1]), 2 * (len(st.edges) - 1)
    ([0.03125, 0.4375, 0.03125, 0.03125, 0.4375, 0.03125], 12, 12)

    The rules are the scheme's: Loop's split faces into triangles, not this step's quads:

    >>> from ccproof.mesh.scheme import LOOP
    >>> catmark_operator(3, [0, 1, 2], [3], scheme=LOOP)
    Traceback (most recent call last):
    ...
    ValueError: catmark_operator: scheme 'loop' splits faces into triangles, not quads
    """
    o = StepOptions() if options is None else options
    if scheme.split != "quad":
        raise ValueError(f"catmark_operator: scheme {scheme.name!r} splits faces into {scheme.split}s, not quads")
    sdc = Options() if o.sdc is None else o.sdc
    chaikin = sdc.crease_method == "chaikin"
    t = step_topology(n, indices, sizes, halfedges, edge_of_halfedge)
    es = _edge_tags(t, edge_sharpness)
    vs = _vertex_tags(n, vertex_sharpness)
    fans = vertex_fans(t)
    pe = es[fans.inc_e]
    ce = _child_edge_sharpness(pe, fans.inc_v, n, chaikin)
    coef, cv = _vertex_coefficients(t, fans, vs, pe, ce, chaikin, sdc.boundary == "edge_and_corner" and o.level == 0)
    ncols = o.column_count(n)
    rows = _Rows(t, fans, scheme)
    rows.face_points()
    rows.vertex_points(coef, pe, ce)
    tri_e = rows.edge_points(es, ce, chaikin, sdc.triangle_subdivision == "smooth" and o.level == 0)
    csr = rows.csr(ncols, o.columns, tri_e)
    S = _scipy_csr(csr, (n + t.E + t.m, ncols)) if o.sparse else None
    faces = np.stack([t.org, n + t.he_edge, n + t.E + t.face, n + t.he_edge[t.prv]], axis=1)
    return Step(S, faces, np.stack([t.a, t.b], axis=1), *_child_tags(t, fans, ce, cv, holes), csr)


def _scipy_csr(csr, shape):
    import scipy.sparse as sp

    return sp.csr_matrix((csr[2], csr[1], csr[0]), shape=shape)


def _child_tags(t, fans, ce, cv, holes):
    """(child creases, child corners, child holes) of :class:`Step`."""
    keep = ce > 0
    child_creases = (np.stack([fans.inc_v[keep], t.n + fans.inc_e[keep]], axis=1).reshape(-1, 2), ce[keep])
    cvs = np.where(fans.k > 0, cv, 0.0)
    sharp_v = np.flatnonzero(cvs > 0)
    child_holes = np.zeros(t.H, dtype=bool) if holes is None else np.repeat(np.asarray(holes, dtype=bool), t.sz)
    return child_creases, (sharp_v, cvs[sharp_v]), child_holes


def _edge_tags(t, edge_sharpness):
    """Sharpness per edge (E,): the tags (an array in the edge numbering, or a dict by vertex pair), ``>= 10``
    infinite, boundary edges infinite."""
    E = t.E
    if isinstance(edge_sharpness, dict):
        es = np.zeros(E)
        if edge_sharpness:  # the pairs looked up among the mesh's edges (sorted there once)
            keys = np.array(list(edge_sharpness.keys()), dtype=np.int64).reshape(-1, 2)
            e = t.halfedges.edge_index_of(keys[:, 0], keys[:, 1])
            ok = e >= 0
            es[t.renum[e[ok]]] = np.asarray(list(edge_sharpness.values()), dtype=np.float64)[ok]
    elif edge_sharpness is None:
        es = np.zeros(E)
    else:
        es = np.array(edge_sharpness, dtype=np.float64).reshape(E)
    es = np.where(es >= INFINITE, np.inf, np.maximum(es, 0.0))
    es[~t.two] = np.inf
    return es


def _vertex_tags(n, vertex_sharpness):
    """Sharpness per vertex (n,): the tags (an array or a dict), ``>= 10`` infinite."""
    if isinstance(vertex_sharpness, dict):
        vs = np.zeros(n)
        if vertex_sharpness:
            vs[np.array(list(vertex_sharpness), dtype=np.int64)] = list(vertex_sharpness.values())
    elif vertex_sharpness is None:
        vs = np.zeros(n)
    else:
        vs = np.array(vertex_sharpness, dtype=np.float64).reshape(n)
    return np.where(vs >= INFINITE, np.inf, np.maximum(vs, 0.0))


def _child_edge_sharpness(pe, inc_v, n, chaikin):
    """Child sharpness of every edge at every vertex (Sdc SubdivideEdgeSharpnessesAroundVertex), per incidence."""
    ce = decrement(pe)
    if chaikin:
        semi = (pe > 0) & np.isfinite(pe)
        total, nsemi = _f32_sums(inc_v[semi], pe[semi], n)
        nedge = np.bincount(inc_v, minlength=n)
        many = semi & (nsemi[inc_v] >= 2) & (nedge[inc_v] >= 2)
        if many.any():
            ce[many] = chaikin_sharpness(pe[many], total[inc_v[many]], nsemi[inc_v[many]])
    return ce


def _vertex_coefficients(t, fans, vs, pe, ce, chaikin, corners_at_level0):
    """((a_smooth, a_crease_p, a_crease_c, a_corner), child vertex sharpness): per vertex the coefficient of
    each mask in its vertex point (Sdc's rule of the parent and of the child, blended by the fractional
    weight ``w``, Sdc ComputeFractionalWeightAtVertex in float32 in fan order)."""
    n, k, inc_v = t.n, fans.k, fans.inc_v
    pv = vs.copy()
    if corners_at_level0:  # EDGE_AND_CORNER: a one-face boundary vertex is a corner
        pv[fans.is_bv & (k == 1)] = np.inf
    cv = decrement(pv)
    prule = rule_code(pv, np.bincount(inc_v[pe > 0], minlength=n))  # the rule table refine_complex reads too
    crule = rule_code(cv, np.bincount(inc_v[ce > 0], minlength=n))
    p, c = mask_kind(prule), mask_kind(crule)
    blend = (p != 0) & (c != p)
    hit = becomes_smooth(pe, ce, not chaikin) & blend[inc_v]
    vhit = blend & becomes_smooth(pv, cv, False)
    seg = np.r_[np.flatnonzero(vhit), inc_v[hit]]
    val = np.r_[pv[vhit], pe[hit]]
    oo = np.argsort(seg, kind="stable")  # the vertex's own sharpness first, then its edges in fan order
    total, cnt = _f32_sums(seg[oo], val[oo], n)
    w = np.zeros(n)
    has = cnt > 0
    w32 = (total[has] / cnt[has].astype(_F32)).astype(_F32)
    w[has] = np.minimum(w32.astype(np.float64), 1.0)
    cp, cc = rule_blend(prule, crule, w, 1.0)  # the weights of the parent's and the child's masks
    a_smooth = (p == 0) * cp + (c == 0) * cc
    a_crease_p = (p == 2) * cp
    a_crease_c = (c == 2) * cc
    a_corner = (p == 3) * cp + (c == 3) * cc
    for x in (a_smooth, a_crease_p, a_crease_c, a_corner):
        x[k == 0] = 0.0  # unused vertices: no row
    return (a_smooth, a_crease_p, a_crease_c, a_corner), cv


class _Rows:
    """The terms of the step's rows, appended in order (face, vertex, edge points: the order fixes the sums).

    Every weight is a sum of terms coef * t / d (coef a dyadic float: 1, a fractional weight, a sharpness;
    t / d a rule's rational weight): summed exactly as integers over the row's common denominator ``R``,
    then divided once (the correctly rounded weight, as refine_complex's to_float of its exact stencil).
    """

    def __init__(self, t, fans, scheme):
        self.t, self.fans, self.scheme = t, fans, scheme
        self.rows, self.cols, self.vals = [], [], []
        one = Fraction(1)  # the scheme's rules in exact rationals, one value per distinct size or valence
        self.face_t, self.face_d = _ratios(lambda x: scheme.face_point(x, one), t.sz)  # (m,)
        kk = np.maximum(fans.k, 1)
        self.wv, self.we, self.wf = (_ratios(lambda x, i=i: scheme.vertex_point(x, one)[i], kk) for i in range(3))
        self.wcv, self.wcn = scheme.crease_vertex(one)
        (self.wco,) = scheme.corner_vertex(one)
        self.half = scheme.sharp_edge(one)
        self.vw0, self.fw0 = scheme.edge_point(one)
        self.R = self._denominators()

    def _denominators(self):
        """The common denominator of every row: a face's; at a vertex, of its smooth, crease and corner
        weights; at an edge, of the midpoint's and the smooth rule's."""
        t, fans, face_d = self.t, self.fans, self.face_d
        lf = np.ones(t.n, dtype=np.int64)
        if t.H:
            used = np.flatnonzero(fans.k > 0)
            lf[used] = np.lcm.reduceat(face_d[t.face[fans.fan]], fans.ptr[used])
        n, E, two, h1, h2 = t.n, t.E, t.two, t.h1, t.h2
        return np.concatenate([
            np.lcm.reduce([self.wv[1], self.we[1], self.wf[1] * lf, np.full(n, self.wcv.denominator),
                           np.full(n, self.wcn.denominator), np.full(n, self.wco.denominator)]),
            np.lcm.reduce([np.full(E, self.half.denominator), np.full(E, self.vw0.denominator),
                           self.fw0.denominator * face_d[t.face[h1]],
                           self.fw0.denominator * np.where(two, face_d[t.face[h2]], 1)]),
            face_d]).astype(np.int64)

    def scaled(self, r, coef, tn, d):
        """``coef * tn / d`` times the common denominator ``R[r]`` of row ``r``: exact (a dyadic times an integer)."""
        q, bad = np.divmod(self.R[r], d)
        if bad.any():
            raise AssertionError("internal: a rule weight's denominator does not divide its row's")
        return coef * (tn * q).astype(np.float64)

    def put(self, r, c, x):
        self.rows.append(r)
        self.cols.append(c)
        self.vals.append(x)

    def add(self, r, c, coef, tn, d):
        r = np.asarray(r, dtype=np.int64)
        self.put(r, np.broadcast_to(np.asarray(c, dtype=np.int64), r.shape),
                 np.broadcast_to(self.scaled(r, coef, tn, d), r.shape))

    def add_face_rest(self, r, h, x):
        """Row ``r`` gets ``x`` on every vertex of the face of half-edge ``h`` but ``org(h)``, ``dst(h)``
        (the rest of a face point spelled out; the caller merges those two into its own terms)."""
        t = self.t
        f = t.face[h]
        for j in range(2, int(t.sz[f].max()) if f.size else 0):
            sel = t.sz[f] > j
            hj = t.off[f] + (t.pos[h] + j) % t.sz[f]
            if sel.all():
                self.put(r, t.idx[hj], x)
            else:
                self.put(r[sel], t.idx[hj[sel]], x[sel])

    def face_points(self):
        """The centroids (R = the face's denominator: the weight's numerator)."""
        t = self.t
        self.put(t.n + t.E + t.face, t.idx, self.face_t[t.face].astype(np.float64))

    def vertex_points(self, coef, pe, ce):
        """The smooth, crease (parent's and child's) and corner masks with their coefficients."""
        a_smooth, a_crease_p, a_crease_c, a_corner = coef
        self._smooth_vertices(a_smooth)
        inc_v, inc_u = self.fans.inc_v, self.fans.inc_u
        for c, sh in ((a_crease_p, pe), (a_crease_c, ce)):
            cr = np.flatnonzero(c != 0)
            if not cr.size:
                continue
            self.add(cr, cr, c[cr], self.wcv.numerator, self.wcv.denominator)
            sel = (c[inc_v] != 0) & (sh > 0)
            self.add(inc_v[sel], inc_u[sel], c[inc_v[sel]], self.wcn.numerator, self.wcn.denominator)
        co = np.flatnonzero(a_corner != 0)
        self.add(co, co, a_corner[co], self.wco.numerator, self.wco.denominator)

    def _smooth_vertices(self, a_smooth):
        t = self.t
        sm = np.flatnonzero(a_smooth != 0)
        if not sm.size:
            return
        (wv_t, wv_d), (we_t, we_d), (wf_t, wf_d) = self.wv, self.we, self.wf
        c = np.flatnonzero(a_smooth[t.org] != 0)  # corners at those vertices: one edge and one face each
        v = t.org[c]
        f = t.face[c]
        xf = self.scaled(v, a_smooth[v], wf_t[v] * self.face_t[f], wf_d[v] * self.face_d[f])  # each face vertex
        diag = np.bincount(v, weights=xf, minlength=t.n)  # v is in each of its faces
        diag[sm] += self.scaled(sm, a_smooth[sm], wv_t[sm], wv_d[sm])
        self.put(sm, sm, diag[sm])
        # the edge neighbour of the corner, which is also the next vertex of its face
        self.put(v, t.dst[c], self.scaled(v, a_smooth[v], we_t[v], we_d[v]) + xf)
        self.add_face_rest(v, c, xf)

    def edge_points(self, es, ce, chaikin, tri_smooth):
        """Midpoints blended with the smooth rule by the midpoint weight ``pw``; returns the ``TRI_SUB_SMOOTH``
        edges (level 0, a triangle on a side, not both halves sharp), whose rows :meth:`csr` adds."""
        t, fans = self.t, self.fans
        a, b, two, h1, h2 = t.a, t.b, t.two, t.h1, t.h2
        er = t.n + np.arange(t.E)
        if chaikin:  # the child sharpness of the edge's half at each end
            ce_end = np.zeros((t.E, 2))
            first_end = fans.inc_v == a[fans.inc_e]
            ce_end[fans.inc_e[first_end], 0] = ce[first_end]
            ce_end[fans.inc_e[~first_end], 1] = ce[~first_end]
            both = (ce_end > 0).all(axis=1)
        else:
            both = decrement(es) > 0
        pw = midpoint_weight(es, ~two | both)  # the edge rule table refine_complex reads too
        tri_e = np.zeros(t.E, dtype=bool)
        if tri_smooth and two.any():
            tri_e[two] = ((t.sz[t.face[h1[two]]] == 3) | (t.sz[t.face[h2[two]]] == 3)) & (pw[two] != 1.0)
        ms = np.flatnonzero((pw != 0) & ~tri_e)
        for end in (a, b):
            self.add(er[ms], end[ms], pw[ms], self.half.numerator, self.half.denominator)
        smooth_e = np.flatnonzero((pw != 1.0) & two & ~tri_e)
        if smooth_e.size:
            self._smooth_edges(er[smooth_e], smooth_e, 1.0 - pw[smooth_e])  # exact: pw is a float32 in [0, 1]
        self.pw = pw
        return tri_e

    def _smooth_edges(self, r, e, q):
        t, fw0, vw0 = self.t, self.fw0, self.vw0
        f1, f2 = t.face[t.h1[e]], t.face[t.h2[e]]
        x1 = self.scaled(r, q, fw0.numerator * self.face_t[f1], fw0.denominator * self.face_d[f1])  # face vertices
        x2 = self.scaled(r, q, fw0.numerator * self.face_t[f2], fw0.denominator * self.face_d[f2])
        xend = self.scaled(r, q, vw0.numerator, vw0.denominator) + x1 + x2  # the ends are in both faces
        for end in (t.a, t.b):
            self.put(r, end[e], xend)
        self.add_face_rest(r, t.h1[e], x1)
        self.add_face_rest(r, t.h2[e], x2)

    def csr(self, ncols, columns, tri_e):
        """The CSR arrays of the rows (vertex copies merged by ``columns``), with the ``TRI_SUB_SMOOTH`` rows."""
        t = self.t
        rows, cols, vals = (np.concatenate(x) for x in (self.rows, self.cols, self.vals))
        if columns is not None:
            cols = np.asarray(columns, dtype=np.int64)[cols]
        R = self.R
        if tri_e.any():  # final weights: these rows are not divided
            tr, tc, tv = _tri_smooth_rows(np.flatnonzero(tri_e), t, self.pw, columns, self.scheme)
            rows, cols, vals = np.r_[rows, tr], np.r_[cols, tc], np.r_[vals, tv]
            R[t.n + np.flatnonzero(tri_e)] = 1
        return _csr(rows, cols, vals, R, ncols)
