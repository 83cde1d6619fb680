"""Certified nearest point (interval arithmetic, python-flint ``arb``): a proof that no other part of
the limit surface is closer, or an honest verdict that this could not be shown.

Method (branch and bound on convex hulls of control nets):

* Every Catmull-Clark rule (face, edge, vertex and the ``VTX_BOUNDARY_EDGE_ONLY`` boundary rules) is
  a convex combination, and the limit surface over a face depends only on the face's one-ring (the
  vertices of the faces sharing a vertex with it). Hence the limit surface over a face, or over a
  dyadic sub-square of it, lies in the **convex hull of the one-ring** of that (sub)face. The one-ring
  of a child face is computed from the parent's one-ring alone (the points whose stencils lie in
  it: the exact stencils of :func:`ccproof.evaluate.local.refine_key`, the rules of
  :mod:`ccproof.mesh.rules`), here in ``arb`` ball arithmetic from the exact float coordinates of
  the mesh: every point is an enclosure of the true control point.
* A *piece* is a dyadic sub-square (face, level L, box) with its one-ring. Lower bound of the
  distance from X to the piece: the largest of the distance to the box around its points and of the
  half-space bounds ``min_j <a, X - c_j> / |a|`` along the direction ``a = X - P`` of the float
  answer and ``min_j <w, c_j - X> / |w|`` along the direction ``w`` from X to the piece's centre.
  Upper bound: the distance to the nearest of the limit points of the 4 corners of the piece (exact
  limit masks, surface points), at most ``max_j |X - c_j|``.
* ``d_up``: the upper bound of the piece of level ``up_level`` containing the float answer
  (face, u, v). Starting from all base faces, pieces whose lower bound exceeds ``d_up`` are
  excluded; the others are split into their 4 children, down to level ``max_level``.
* Pieces are split until they lie within ``radius`` (3-D) of the float answer P or reach
  ``max_level``. Verdict: **certified** if every remaining piece lies within ``separation`` of P:
  then every surface point at distance <= d_up from X, in particular the nearest one, lies in the
  remaining pieces; their parameter boxes enclose the nearest parameter and ``[min lb, d_up]``
  encloses the distance. **ambiguous** if a remaining piece farther than ``separation`` from P has an
  upper bound within ``ambiguity`` of ``d_up``: another part of the surface is as close to within
  that tolerance (e.g. the centre of a sphere-like surface). **uncertified** otherwise (the budget of
  pieces or levels ran out).

Supported meshes: quad meshes of :class:`~ccproof.mesh.QuadMesh` (boundary rule
``VTX_BOUNDARY_EDGE_ONLY``); other meshes raise a :class:`~ccproof.errors.CCProofError`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import NamedTuple

from ccproof.errors import CCProofError
from ccproof.evaluate.local import canonical_ring, refine_key, ring_key
from ccproof.mesh.rules import Complex, Options
from ccproof.rule_weights import crease_limit_weights, smooth_limit_weights

__all__ = ["CertifiedClosest", "CertifyLimits", "certify_closest"]

#: level of the piece giving the upper bound d_up
UP_LEVEL = 24
#: deepest level of the branch and bound
MAX_LEVEL = 22
#: pieces examined at most per point
MAX_PIECES = 20000
#: precision of the ball arithmetic (bits)
PREC = 106


@dataclass
class CertifiedClosest:
    """Verdict of :func:`certify_closest` for one point.

    Attributes
    ----------
    verdict : str
        ``"certified"``, ``"ambiguous"`` or ``"uncertified"``.
    distance_lo, distance_hi : float
        Rigorous enclosure of the distance from X to the surface (``distance_lo`` is the lower bound
        over the remaining pieces; valid as an enclosure only when certified; ``distance_hi`` is
        always a rigorous upper bound).
    parameter_radius : float
        The nearest parameter lies within this max-norm radius of the float (u, v) in ``face``
        (certified only; NaN otherwise, inf if the remaining pieces extend into other faces, which
        are listed in ``boxes``).
    boxes : list of (face, (u_lo, u_hi), (v_lo, v_hi))
        Parameter boxes of the remaining pieces (certified: they contain the nearest parameter).
    pieces : int
        Pieces examined.
    message : str

    Examples
    --------
    >>> from ccproof.evaluate import limit_surface
    >>> from ccproof.mesh.examples import cube
    >>> c = certify_closest(limit_surface(cube()), [0.0, 0.0, 2.0], 1, 0.5, 0.5)
    >>> isinstance(c, CertifiedClosest), c.verdict, c.parameter_radius < 1e-5
    (True, 'certified', True)
    """

    verdict: str
    distance_lo: float
    distance_hi: float
    parameter_radius: float
    boxes: list = field(default_factory=list)
    pieces: int = 0
    message: str = ""


# ------------------------------------------------------------------------------ local nets
class _Piece:
    __slots__ = ("faces", "pts", "c", "face", "u0", "v0", "h", "level", "lb", "ub", "far")

    def __init__(self, faces, pts, c, face, u0, v0, h, level):
        self.faces, self.pts, self.c = faces, pts, c
        self.face, self.u0, self.v0, self.h, self.level = face, u0, v0, h, level


def _one_ring_faces(faces, c):
    vs = set(faces[c])
    return [g for g, F in enumerate(faces) if vs.intersection(F)]


def _refine(piece, q, arb):
    """The child of ``piece`` at corner ``q`` of its centre face, with its own one-ring.

    The exact stencils of one local step (:func:`ccproof.evaluate.local.refine_key`: the rules of
    :mod:`ccproof.mesh.rules` in exact rationals) applied to the ball enclosures of the ring's
    points: every new point is an enclosure of the true control point.
    """
    cx = Complex(piece.faces, {}, {}, Options())
    ring, fk, nr = canonical_ring(cx, piece.c, 0)
    _, stencils, child = refine_key(ring_key(cx, ring, fk, nr), nr)
    # child q of the centre face (face 0 of the ring, read from its corner 0) is its child at corner
    # q; corner r of that child lies at the sub-square's lowest (u, v) corner: the new corner 0
    cring, cfaces, _ = canonical_ring(child, q, (0, 3, 2, 1)[q])
    pts = [piece.pts[i] for i in ring]
    new_pts = []
    for w in cring:
        st = stencils[w]
        if st is None:  # pragma: no cover - the child's one-ring uses only exact points
            raise CCProofError("internal error: a point of the child's one-ring is outside the local refinement")
        new_pts.append([sum((pts[j][k] * x for j, x in st.items()), arb(0)) for k in range(3)])
    h = piece.h / 2
    du, dv = ((0, 0), (1, 0), (1, 1), (0, 1))[q]
    return _Piece(list(cfaces), new_pts, 0, piece.face, piece.u0 + du * h, piece.v0 + dv * h, h, piece.level + 1)


def _bounds(piece, X, a, an, arb):
    """Lower and upper bounds (floats, rigorous) of the distance from X to the piece's hull."""
    lo = [min(p[k].lower() for p in piece.pts) for k in range(3)]
    hi = [max(p[k].upper() for p in piece.pts) for k in range(3)]
    d2 = arb(0)
    for k in range(3):
        if X[k] < lo[k]:
            d2 += _sq(lo[k] - X[k])
        elif X[k] > hi[k]:
            d2 += _sq(X[k] - hi[k])
    lb_box = _sqrt_lo(d2)
    hs = min((sum((a[k] * (X[k] - p[k]) for k in range(3)), arb(0)) / an).lower() for p in piece.pts)
    # half-space bound along the direction from X to the piece's centre (tight for far pieces)
    w = [arb(float(sum((p[k] for p in piece.pts), arb(0)).mid()) / len(piece.pts) - float(X[k].mid()))
         for k in range(3)]
    wn2 = sum((t * t for t in w), arb(0))
    if wn2 > 0:
        wn = wn2.sqrt()
        hs = max(hs, min((sum((w[k] * (p[k] - X[k]) for k in range(3)), arb(0)) / wn).lower() for p in piece.pts))
    ub = max(_sqrt_up(sum((_sq(X[k] - p[k]) for k in range(3)), arb(0))) for p in piece.pts)
    for L in _corner_limits(piece, arb):
        ub = min(ub, _sqrt_up(sum((_sq(X[k] - L[k]) for k in range(3)), arb(0))))
    return max(lb_box, hs, arb(0).lower()), ub


def _sq(x):
    # x * x, not x ** 2: python-flint's power of a ball containing 0 is NaN
    return x * x


def _sqrt_up(s):
    """Upper bound of sqrt over a ball s (of a sum of squares, which may straddle 0 by round-off)."""
    up = s.upper()
    return up.sqrt().upper() if up > 0 else up * 0


def _sqrt_lo(s):
    lo = s.lower()
    return lo.sqrt().lower() if lo > 0 else lo * 0


def _corner_limits(piece, arb):
    """Limit points (surface points, in arb) of the 4 corners of the piece's centre face: the masks
    of :func:`ccproof.rule_weights.smooth_limit_weights` (interior) and
    :func:`ccproof.rule_weights.crease_limit_weights` (boundary), in balls."""
    faces, pts = piece.faces, piece.pts
    out = []
    for w in faces[piece.c]:
        e, d, cnt = [], [], {}
        for F in faces:
            if w in F:
                i = F.index(w)
                e += [F[(i + 1) % 4], F[(i - 1) % 4]]
                d.append(F[(i + 2) % 4])
        for b in e:
            cnt[b] = cnt.get(b, 0) + 1
        V = pts[w]
        bnd = [b for b, n in cnt.items() if n == 1]
        if bnd:
            e0, e1 = pts[bnd[0]], pts[bnd[1]]
            cV, ce = crease_limit_weights(arb(1))
            out.append([cV * V[k] + ce * (e0[k] + e1[k]) for k in range(3)])
        else:
            wV, we, wd = smooth_limit_weights(len(cnt), arb(1))
            se = [sum((pts[b][k] for b in cnt), arb(0)) for k in range(3)]
            sd = [sum((pts[b][k] for b in d), arb(0)) for k in range(3)]
            out.append([wV * V[k] + we * se[k] + wd * sd[k] for k in range(3)])
    return out


def _corner_piece(piece, u, v, arb):
    h = piece.h / 2
    q = (int(u >= piece.u0 + h), int(v >= piece.v0 + h))
    return _refine(piece, {(0, 0): 0, (1, 0): 1, (1, 1): 2, (0, 1): 3}[q], arb)


def _ring_boxes(F, Vx, vf):
    import numpy as np

    lo = np.empty((F.shape[0], 3))
    hi = np.empty((F.shape[0], 3))
    for g, row in enumerate(F.tolist()):
        ring = set().union(*(vf[w] for w in row))
        verts = np.unique(F[sorted(ring)])
        lo[g], hi[g] = Vx[verts].min(0), Vx[verts].max(0)
    return lo, hi


class CertifyLimits(NamedTuple):
    """The tolerances and budgets of :func:`certify_closest`.

    Attributes
    ----------
    radius : float, optional
        Pieces are split until they lie within this 3-D radius of the float answer P (or reach
        ``max_level``); default (None) 1e-6 of the bounding box diagonal.
    separation : float, optional
        Certified if every remaining piece lies within this distance of P (default 1e-3 of the
        diagonal; the enclosure actually reached is reported); remaining pieces farther away make
        the point ambiguous or uncertified.
    ambiguity : float, optional
        Tolerance of the ambiguity verdict (default 1e-9 of the diagonal).
    up_level : int
        Level of the piece giving the upper bound d_up (:data:`UP_LEVEL`).
    max_level, max_pieces : int
        Deepest level of the branch and bound (:data:`MAX_LEVEL`), pieces examined at most (:data:`MAX_PIECES`).

    >>> CertifyLimits(max_level=4).max_pieces == MAX_PIECES
    True
    """

    radius: float | None = None
    separation: float | None = None
    ambiguity: float | None = None
    up_level: int = UP_LEVEL
    max_level: int = MAX_LEVEL
    max_pieces: int = MAX_PIECES


def certify_closest(surface, x, face, u, v, limits=None):
    """Certify that the limit point at (face, u, v) is (within enclosures) the nearest one to ``x``.

    Parameters
    ----------
    surface : LimitSurface
        Of a quad mesh (its ``mesh`` must have ``faces`` (m, 4) and ``vertices`` (n, 3)).
    x : array_like, shape (3,)
    face, u, v : the float answer (e.g. from :func:`~ccproof.evaluate.closest.closest_points`).
    limits : CertifyLimits, optional
        Tolerances and budgets (None: the defaults of :class:`CertifyLimits`).

    Returns
    -------
    CertifiedClosest

    Notes
    -----
    Branch and bound on convex hulls of one-rings in ``arb`` ball arithmetic (the module docstring;
    docs/closest.md "Certified mode: method").

    Examples
    --------
    Above the centre of the cube's top face the nearest limit point is (0, 0, 68/81), at distance
    94/81 (one Catmull-Clark step and the limit mask by hand); the enclosure contains it:

    >>> from ccproof.evaluate import limit_surface
    >>> from ccproof.mesh.examples import cube
    >>> c = certify_closest(limit_surface(cube()), [0.0, 0.0, 2.0], 1, 0.5, 0.5)
    >>> c.verdict, c.distance_lo <= 94 / 81 <= c.distance_hi, c.distance_hi - c.distance_lo < 1e-9
    ('certified', True, True)
    """
    import flint
    import numpy as np

    mesh = getattr(surface, "mesh", surface)
    F = np.asarray(getattr(mesh, "faces", None)) if getattr(mesh, "faces", None) is not None else None
    if F is None or F.ndim != 2 or F.shape[1] != 4:
        raise CCProofError("certified closest points support quad meshes only (faces of 4 vertices)")
    Vx = np.asarray(mesh.vertices, dtype=np.float64)
    x = np.asarray(x, dtype=np.float64).reshape(3)
    face, u, v = int(face), float(u), float(v)
    diag = float(np.linalg.norm(Vx.max(0) - Vx.min(0)))
    limits = CertifyLimits() if limits is None else limits
    radius = 1e-6 * diag if limits.radius is None else float(limits.radius)
    ambiguity = 1e-9 * diag if limits.ambiguity is None else float(limits.ambiguity)
    separation = 1e-3 * diag if limits.separation is None else float(limits.separation)
    up_level, max_level, max_pieces = limits.up_level, limits.max_level, limits.max_pieces
    old = flint.ctx.prec
    flint.ctx.prec = PREC
    try:
        arb = flint.arb
        geo = _target(surface, x, face, u, v, arb)
        # vertex -> faces
        vf = {}
        for g, row in enumerate(F.tolist()):
            for w in row:
                vf.setdefault(w, set()).add(g)
        # upper bound: the piece at level up_level containing (u, v)
        pc = _base_piece(F, Vx, vf, face, arb)
        for _ in range(up_level):
            pc = _corner_piece(pc, u, v, arb)
        d_up = _bounds(pc, *geo[:3], arb)[1]
        active = _candidates(F, Vx, vf, x, geo, arb, d_up)
        active, n_pieces = _subdivide(active, geo, arb, d_up, radius, (max_level, max_pieces),
                                      F.shape[0] + up_level)
        return _verdict(active, geo, arb, d_up, (face, u, v), n_pieces,
                        (separation, ambiguity, max_level, max_pieces))
    finally:
        flint.ctx.prec = old


def _target(surface, x, face, u, v, arb):
    """(X, a, |a|, P) as arb balls: the point ``x``, the direction of the distance from the limit point P at
    (face, u, v) (the normal there when x = P), its length, P."""
    import numpy as np

    X = [arb(float(t)) for t in x]
    P = surface.evaluate([face], [u], [v], 0)["P"][0]
    a_f = x - P
    if not np.any(a_f):
        a_f = np.asarray(surface.evaluate([face], [u], [v], 1)["Pu"][0], dtype=np.float64)
        a_f = np.cross(a_f, surface.evaluate([face], [u], [v], 1)["Pv"][0])
    a = [arb(float(t)) for t in a_f]
    an = sum((t * t for t in a), arb(0)).sqrt()
    Pa = [arb(float(t)) for t in P]
    return X, a, an, Pa


def _candidates(F, Vx, vf, x, geo, arb, d_up):
    """The base pieces whose lower bound of the distance to ``x`` is at most ``d_up``, after a float prefilter of
    the base faces (box of the one-ring; the margin covers the rounding)."""
    import numpy as np

    ring_lo, ring_hi = _ring_boxes(F, Vx, vf)
    gap = np.maximum(np.maximum(ring_lo - x, x - ring_hi), 0.0)
    lbf = np.sqrt((gap * gap).sum(axis=1)) * (1 - 1e-12)
    active = []
    for g in np.flatnonzero(lbf <= float(d_up) * (1 + 1e-12)).tolist():
        p = _base_piece(F, Vx, vf, g, arb)
        p.lb, p.ub = _bounds(p, *geo[:3], arb)
        if p.lb <= d_up:
            active.append(p)
    return active


def _base_piece(F, Vx, vf, g, arb):
    """The level-0 piece of base face ``g`` (its one-ring, exact points); ``vf``: vertex -> faces."""
    ring = sorted(set().union(*(vf[w] for w in F[g].tolist())))
    verts = sorted({w for h in ring for w in F[h].tolist()})
    loc = {w: i for i, w in enumerate(verts)}
    faces = [tuple(loc[w] for w in F[h].tolist()) for h in ring]
    pts = [[arb(float(t)) for t in Vx[w]] for w in verts]
    return _Piece(faces, pts, ring.index(g), g, 0.0, 0.0, 1.0, 0)


def _spread(piece, Pa, arb):
    """An upper bound of max_j |P - c_j| over the control points c_j of ``piece`` (P = ``Pa``)."""
    return max(_sqrt_up(sum((_sq(Pa[k] - p[k]) for k in range(3)), arb(0))) for p in piece.pts)


def _subdivide(active, geo, arb, d_up, radius, limits, n_pieces):
    """Split the pieces whose hull is farther than ``radius`` from P somewhere, keeping the children whose
    lower bound is at most ``d_up``, until none is left or ``limits`` = (max_level, max_pieces) is met;
    returns (active, n_pieces)."""
    X, a, an, Pa = geo
    max_level, max_pieces = limits

    def far_from_P(piece):
        # the hull is farther than `radius` from P somewhere: max_j |P - c_j| > radius
        return _spread(piece, Pa, arb) > radius

    while True:
        split = [p for p in active if p.level < max_level and far_from_P(p)]
        if not split:
            break
        if n_pieces + 4 * len(split) > max_pieces:
            break
        keep = [p for p in active if not (p.level < max_level and far_from_P(p))]
        for p in split:
            for q in range(4):
                ch = _refine(p, q, arb)
                ch.lb, ch.ub = _bounds(ch, X, a, an, arb)
                n_pieces += 1
                if ch.lb <= d_up:
                    keep.append(ch)
        active = keep
    return active, n_pieces


def _verdict(active, geo, arb, d_up, point, n_pieces, limits):
    """The :class:`CertifiedClosest` of the pieces left; ``point`` = (face, u, v), ``limits`` = (separation,
    ambiguity, max_level, max_pieces)."""
    import numpy as np

    face, u, v = point
    separation, ambiguity, max_level, max_pieces = limits
    Pa = geo[3]
    lo = min((p.lb for p in active), default=d_up)
    boxes = [(p.face, (p.u0, p.u0 + p.h), (p.v0, p.v0 + p.h)) for p in active]
    if not (np.isfinite(float(d_up)) and np.isfinite(float(lo))):
        return CertifiedClosest("uncertified", float("nan"), float("nan"), float("nan"), [], n_pieces,
                                "the enclosures are not finite")
    sp = [float(_spread(p, Pa, arb)) for p in active]
    sep = [p for p, r_ in zip(active, sp) if r_ > separation]
    if not sep:
        same = [b for b in boxes if b[0] == face]
        rad = max((max(abs(b[1][0] - u), abs(b[1][1] - u), abs(b[2][0] - v), abs(b[2][1] - v)) for b in same),
                  default=0.0)
        if len(same) < len(boxes):
            rad = float("inf")
        return CertifiedClosest("certified", float(lo), float(d_up), float(rad), boxes, n_pieces,
                                f"every surface point within {float(d_up):.17g} of x lies within "
                                f"{max(sp, default=0.0):.3g} of P")
    near_min = [p for p in sep if p.ub <= d_up + ambiguity]
    if near_min:
        return CertifiedClosest("ambiguous", float(lo), float(d_up), float("nan"), boxes, n_pieces,
                                f"{len(near_min)} pieces farther than {separation:.3g} from P are within "
                                f"{ambiguity:.3g} of the distance")
    return CertifiedClosest("uncertified", float(lo), float(d_up), float("nan"), boxes, n_pieces,
                            f"{len(sep)} pieces farther than {separation:.3g} from P could not be excluded "
                            f"(levels <= {max_level}, pieces <= {max_pieces})")
