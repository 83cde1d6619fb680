"""The characteristic map of Catmull-Clark subdivision, symbolic in c = cos(2 pi/k) (bmz04 section 4.3).

Derivation (docs/readings.md R2-R4):

1. Fourier mode 1. The characteristic map is the limit function of the subdominant eigenvector.
   For Fourier mode 1 the value at position p of sector j is ``R^j x_p`` where ``x_p`` is the value
   in sector 0 and ``R`` is the rotation by 2 pi/k. We write every value in the *normalized frame*:
   coordinates with respect to the edge directions ``e_0 = (1, 0)`` and ``e_1 = (0, 1)`` (R3). In
   that basis the rotation is ``R = [[0, -1], [1, 2c]]`` (since e_2 = 2c e_1 - e_0) and
   ``R^-1 = [[2c, 1], [-1, 0]]``: every entry lies in Q(c).
2. Eigenvector. In mode 1 the centre is 0 and the one-ring block gives x_(1,0) = e_0,
   x_(1,1) = (e_0 + e_1)/(4 lam - 1) with lam the larger root of 16 lam^2 - 2(5+c) lam + 1 (R2).
   The four outer values x_(2,0), x_(2,1), x_(1,2), x_(2,2) solve the linear system
   (lam I - S_outer) x_outer = S_outer,inner x_inner over Q(c, lam).
3. One subdivision step gives the level-1 control points; the 4x4 B-spline nets of the level-1
   faces (1,0), (1,1), (0,1) of sector 0 are the pieces P1, P2, P3 on D1 = [1/2,1]x[0,1/2],
   D2 = [1/2,1]^2, D3 = [0,1/2]x[1/2,1] (R4).
4. Scale so that Phi(1, 0) = (1, 0).

The result: three 4x4 nets of points in Q(c, lam)^2. They are computed once (cached) and
specialized to a valence by :func:`characteristic_map_patches`.
"""

from __future__ import annotations

from fractions import Fraction
from functools import lru_cache

from ccproof.algebra.field import C, QcLam
from ccproof.algebra.subdivision import TWO_RING_POSITIONS, canonical, regular_stencil

#: names of the three layer-0 pieces and their domains in the face parameter (u, v) (R4)
PATCH_DOMAINS = {
    "P1": ((Fraction(1, 2), Fraction(1)), (Fraction(0), Fraction(1, 2))),
    "P2": ((Fraction(1, 2), Fraction(1)), (Fraction(1, 2), Fraction(1))),
    "P3": ((Fraction(0), Fraction(1, 2)), (Fraction(1, 2), Fraction(1))),
}

#: level-1 grid position of the B-spline control point (0, 0) of each piece's 4x4 net;
#: control point [i][j] of piece P sits at level-1 position offset + (i, j)
NET_OFFSETS = {"P1": (0, -1), "P2": (0, 0), "P3": (-1, 0)}

#: the uniform cubic B-spline segment in Bezier form: bezier = M @ bspline (per direction)
BSPLINE_TO_BEZIER = (
    (Fraction(1, 6), Fraction(4, 6), Fraction(1, 6), Fraction(0)),
    (Fraction(0), Fraction(4, 6), Fraction(2, 6), Fraction(0)),
    (Fraction(0), Fraction(2, 6), Fraction(4, 6), Fraction(0)),
    (Fraction(0), Fraction(1, 6), Fraction(4, 6), Fraction(1, 6)),
)

_ZERO = None


def _zero():
    return QcLam(0)


def _vec(x, y):
    return (QcLam(x), QcLam(y))


def _rot(delta, p):
    """Apply R^delta (delta in {-1, 0, 1}) to a point of Q(c, lam)^2 in the normalized frame."""
    x, y = p
    if delta == 0:
        return p
    if delta == 1:  # R = [[0, -1], [1, 2c]]
        return (-y, x + y * (2 * C))
    if delta == -1:  # R^-1 = [[2c, 1], [-1, 0]]
        return (x * (2 * C) + y, -x)
    if delta == 2:
        return _rot(1, _rot(1, p))
    raise ValueError(delta)


def _add(p, q):
    return (p[0] + q[0], p[1] + q[1])


def _scale(s, p):
    s = QcLam(s) if not isinstance(s, QcLam) else s
    return (p[0] * s, p[1] * s)


def _apply_stencil(stencil, values):
    """Mode-1 value of a level-1 vertex of sector 0 from level-0 sector-0 values ``values``."""
    acc = (_zero(), _zero())
    for w, (a, b) in stencil:
        d, a2, b2 = canonical(a, b)
        if (a2, b2) == (0, 0):
            continue  # the centre is 0 in mode 1
        acc = _add(acc, _scale(QcLam(_frac(w)), _rot(d, values[(a2, b2)])))
    return acc


def _frac(w):
    from sympy import Rational

    return Rational(w.numerator, w.denominator)


def _solve(matrix, rhs):
    """Gaussian elimination over Q(c, lam) (matrix: list of rows of QcLam)."""
    n = len(matrix)
    M = [list(row) + [r] for row, r in zip(matrix, rhs)]
    for col in range(n):
        piv = next(r for r in range(col, n) if not M[r][col].is_zero())
        M[col], M[piv] = M[piv], M[col]
        inv = M[col][col].inverse()
        M[col] = [x * inv for x in M[col]]
        for r in range(n):
            if r != col and not M[r][col].is_zero():
                f = M[r][col]
                M[r] = [x - f * y for x, y in zip(M[r], M[col])]
    return [M[i][n] for i in range(n)]


@lru_cache(maxsize=1)
def mode1_eigenvector():
    """Level-0 mode-1 subdominant eigenvector on the two-ring of sector 0, symbolic (steps 1-2).

    bmz04 section 3 (the subdominant eigenvector of the subdivision matrix, Definition 4);
    docs/readings.md R2, R3 (the normalized frame).

    Returns
    -------
    dict
        ``{(a, b): (x, y)}`` for the 6 positions :data:`TWO_RING_POSITIONS`, entries
        :class:`~ccproof.algebra.field.QcLam` in Q(c, lam), normalized by x_(1,0) = (1, 0) (not yet
        scaled so that Phi(1,0) = (1,0)).

    Examples
    --------
    For k = 4 (c = 0, lam = 1/2) the eigenvector is the linear function of the regular grid,
    x_(a,b) = (a, b):

    >>> from fractions import Fraction
    >>> from ccproof.algebra.field import eval_integer_form
    >>> at4 = lambda q: eval_integer_form(q.integer_form(), 0, Fraction(1, 2))
    >>> all((at4(x), at4(y)) == p for p, (x, y) in mode1_eigenvector().items())
    True
    """
    lam = QcLam.lam()
    inner = {(1, 0): _vec(1, 0)}
    f = (4 * lam - 1).inverse()
    inner[(1, 1)] = (f, f)
    outer = [(2, 0), (2, 1), (1, 2), (2, 2)]
    # S x = lam x on the outer positions: the level-1 vertex at grid position p (computed from
    # level-0 values by regular_stencil(p)) equals lam times the level-0 value at position p.
    unknown_index = {p: i for i, p in enumerate(outer)}
    nun = 2 * len(outer)
    rows, rhs = [], []
    for p in outer:
        st = regular_stencil(*p)
        # linear form: sum_w w R^d x_q ; split into known (inner) and unknown (outer) parts
        coeff = [[_zero() for _ in range(nun)] for _ in range(2)]
        known = (_zero(), _zero())
        for w, (a, b) in st:
            d, a2, b2 = canonical(a, b)
            if (a2, b2) == (0, 0):
                continue
            q = (a2, b2)
            wq = QcLam(_frac(w))
            if q in inner:
                known = _add(known, _scale(wq, _rot(d, inner[q])))
            else:
                i = unknown_index[q]
                # R^d applied to the unknown (X, Y): columns of R^d
                e0 = _rot(d, (QcLam(1), _zero()))
                e1 = _rot(d, (_zero(), QcLam(1)))
                for comp in range(2):
                    coeff[comp][2 * i] = coeff[comp][2 * i] + wq * e0[comp]
                    coeff[comp][2 * i + 1] = coeff[comp][2 * i + 1] + wq * e1[comp]
        i = unknown_index[p]
        for comp in range(2):
            row = [-x for x in coeff[comp]]
            row[2 * i + comp] = row[2 * i + comp] + lam
            rows.append(row)
            rhs.append(known[comp])
    sol = _solve(rows, rhs)
    vec = dict(inner)
    for p, i in unknown_index.items():
        vec[p] = (sol[2 * i], sol[2 * i + 1])
    return vec


def _level1_value(values, A, B):
    """Level-1 mode-1 value at sector-0 grid position (A, B) (any position one sector away)."""
    d, A2, B2 = canonical(A, B)
    if (A2, B2) == (0, 0):
        return (_zero(), _zero())
    return _rot(d, _apply_stencil(regular_stencil(A2, B2), values))


@lru_cache(maxsize=1)
def symbolic_bspline_nets():
    """The B-spline nets of P1, P2, P3 in the normalized frame, symbolic in c and lam (R3, R4).

    bmz04 section 4.3 (the characteristic map as three bicubic pieces of layer 0, Fig. 3);
    docs/readings.md R3, R4.

    Returns
    -------
    dict
        ``{"P1": net, "P2": net, "P3": net}``; ``net`` is a 4 x 4 nested list, ``net[i][j] = (x, y)``
        with entries :class:`~ccproof.algebra.field.QcLam`, i along u (the piece's local s), j along v (t).
        Piece P on its domain [u0,u1]x[v0,v1] is the uniform bicubic B-spline of the net with local
        parameters s = (u - u0)/(u1 - u0), t = (v - v0)/(v1 - v0).

    Examples
    --------
    For k = 4 the characteristic map is the identity, so the level-1 B-spline net of P1 (domain
    [1/2, 1] x [0, 1/2]) is the grid of spacing 1/2 with corner (0, -1/2):

    >>> from fractions import Fraction
    >>> from ccproof.algebra.field import eval_integer_form
    >>> at4 = lambda q: eval_integer_form(q.integer_form(), 0, Fraction(1, 2))
    >>> net = symbolic_bspline_nets()["P1"]
    >>> all((at4(net[i][j][0]), at4(net[i][j][1])) == (Fraction(i, 2), Fraction(j - 1, 2))
    ...     for i in range(4) for j in range(4))
    True
    """
    vals = mode1_eigenvector()
    raw = {}
    for name, (oa, ob) in NET_OFFSETS.items():
        raw[name] = [[_level1_value(vals, oa + i, ob + j) for j in range(4)] for i in range(4)]
    # Phi(1, 0) = corner (s, t) = (1, 0) of P1 = the limit of the level-1 vertex at (2, 0):
    # regular limit mask (16 V + 4 sum edge + sum diagonal)/36 of the B-spline net around it.
    net = raw["P1"]
    V = net[2][1]
    edges = [net[1][1], net[3][1], net[2][0], net[2][2]]
    diag = [net[1][0], net[3][0], net[1][2], net[3][2]]
    px = V[0] * 16
    py = V[1] * 16
    for e in edges:
        px, py = px + e[0] * 4, py + e[1] * 4
    for e in diag:
        px, py = px + e[0], py + e[1]
    phi10x, phi10y = px / 36, py / 36
    if not phi10y.is_zero():
        raise AssertionError("Phi(1,0) is not on the first axis of the normalized frame")
    inv = phi10x.inverse()
    return {n: [[_scale(inv, p) for p in row] for row in net_] for n, net_ in raw.items()}


def bspline_to_bezier(net, ops=None):
    """Convert a 4x4 uniform bicubic B-spline net (any coefficient type) to the Bezier net of the
    same segment: ``bez = M net M^T`` with M = :data:`BSPLINE_TO_BEZIER`.

    The standard B-spline to Bezier conversion of the middle segment (docs/readings.md R4).

    Parameters
    ----------
    net : sequence of sequences, shape (4, 4)
        ``net[i][j]``: a scalar or a 2-tuple (a point) of any ring type (Fraction, sympy, QcLam, arb).
    ops : callable, optional
        Turns a ``Fraction`` weight into the coefficient type; default: identity.

    Returns
    -------
    list of lists, shape (4, 4)
        The Bezier net, entries of the same kind as those of ``net``.

    Examples
    --------
    Equally spaced B-spline coefficients 0, 1, 2, 3 (along i) give the linear segment from 1 to 2,
    whose Bezier coefficients are 1, 4/3, 5/3, 2:

    >>> from fractions import Fraction
    >>> bez = bspline_to_bezier([[Fraction(i)] * 4 for i in range(4)])
    >>> [str(row[0]) for row in bez]
    ['1', '4/3', '5/3', '2']
    """
    conv = ops or (lambda f: f)
    M = [[conv(x) for x in row] for row in BSPLINE_TO_BEZIER]

    def lin(coeffs, pts):
        if isinstance(pts[0], tuple):
            return tuple(lin(coeffs, [p[c] for p in pts]) for c in range(len(pts[0])))
        acc = None
        for a, p in zip(coeffs, pts):
            if BSPLINE_TO_BEZIER and a == 0:
                continue
            acc = a * p if acc is None else acc + a * p
        return acc

    tmp = [[lin(M[i], [net[r][j] for r in range(4)]) for j in range(4)] for i in range(4)]
    return [[lin(M[j], tmp[i]) for j in range(4)] for i in range(4)]


@lru_cache(maxsize=1)
def symbolic_bezier_nets():
    """Bezier nets of P1, P2, P3 (same layout as :func:`symbolic_bspline_nets`), symbolic.

    :func:`bspline_to_bezier` of the nets of :func:`symbolic_bspline_nets` (bmz04 section 4.3;
    docs/readings.md R3, R4); these are the nets the certified tables store.

    Returns
    -------
    dict
        ``{"P1": net, "P2": net, "P3": net}``, ``net[i][j] = (x, y)``, i, j = 0..3, entries
        :class:`~ccproof.algebra.field.QcLam`.

    Examples
    --------
    For k = 4 (the identity map) the Bezier net of P2 on D2 = [1/2, 1]^2 is the uniform grid of D2:

    >>> from fractions import Fraction
    >>> from ccproof.algebra.field import eval_integer_form
    >>> at4 = lambda q: eval_integer_form(q.integer_form(), 0, Fraction(1, 2))
    >>> net = symbolic_bezier_nets()["P2"]
    >>> all((at4(net[i][j][0]), at4(net[i][j][1])) == (Fraction(3 + i, 6), Fraction(3 + j, 6))
    ...     for i in range(4) for j in range(4))
    True
    """
    from sympy import Rational

    conv = lambda f: QcLam(Rational(f.numerator, f.denominator))
    return {n: bspline_to_bezier(net, conv) for n, net in symbolic_bspline_nets().items()}


def symbolic_two_ring_eigenvector():
    """The level-0 subdominant eigenvector on the sector-0 part of the two-ring, scaled like the nets.

    :func:`mode1_eigenvector` scaled so that Phi(1,0) = (1,0) (bmz04 section 4.3 step 4;
    docs/readings.md R3).

    Returns
    -------
    dict
        ``{(a, b): (x, y)}`` for the 6 positions :data:`TWO_RING_POSITIONS`, entries
        :class:`~ccproof.algebra.field.QcLam`.

    Examples
    --------
    For k = 4 the scale is 1 and the values are the grid positions:

    >>> from fractions import Fraction
    >>> from ccproof.algebra.field import eval_integer_form
    >>> ev = symbolic_two_ring_eigenvector()
    >>> [eval_integer_form(ev[(2, 1)][i].integer_form(), 0, Fraction(1, 2)) for i in (0, 1)]
    [Fraction(2, 1), Fraction(1, 1)]
    """
    vals = mode1_eigenvector()
    nets = symbolic_bspline_nets()
    raw_e0 = _level1_value(vals, 2, 0)
    # scale factor = nets / raw: compare one coordinate of a non-zero control point
    scale = nets["P1"][2][1][0] / raw_e0[0]
    return {p: _scale(scale, vals[p]) for p in TWO_RING_POSITIONS}
