"""The statement of a certificate, derived from the valence and the Catmull-Clark rules alone (trusted).

Nothing here is read from a file. :func:`derivation` computes once, with c = cos(2 pi/k) an
indeterminate (so for every valence at once), in the field F below:

1. the mode-1 subdominant eigenvector on the two-ring of sector 0 in the normalized frame
   (docs/readings.md R3): the rotation to the next sector is R = [[0, -1], [1, 2c]]; the vector solves
   (M(c) - lam) v = 0 with v(1, 0) = (1, 0) by exact elimination, and the eigen-equation
   M(c) v = lam v is then checked as an identity in F (all 12 coordinates);
2. the layer-0 pieces P1, P2, P3: the B-spline nets after one Catmull-Clark step of v
   (:mod:`.rules`), their Bezier nets, scaled so that Phi(1, 0) = (1, 0);
3. the hypotheses the proofs use, each an exact identity in F: Phi(1, 0) = (1, 0); the axis edges
   mapped onto the axes; Phi continuous across P1|P2 and P2|P3; the layer boundary
   Phi(1/2, v) = lam Phi(1, 2v), Phi(u, 1/2) = lam Phi(2u, 1); the mirror symmetry
   P3 = S P1^T, P2 = S P2^T, S(x, y) = (y, x).

:func:`nets_for_valence` specializes to one valence in arb: c = cos(2 pi/k) (arb's rigorous cos) and
lam = (5 + c + sqrt((1 + c)(9 + c)))/16, the larger root of the quadratic, whose ball therefore holds
lam(k); each net entry is evaluated from its exact form, after checking that no denominator vanishes.
That the eigenvector is *the* subdominant one (lam simple in its Fourier block, the ordering of the
spectrum) is :mod:`.spectrum`.

The field F = Q(c)[lam] / (16 lam^2 - 2(5 + c) lam + 1) in which the characteristic map lives.

c = cos(2 pi/k) is kept as an indeterminate, so one computation in F covers every valence at once;
lam is the root of the subdominant quadratic (docs/readings.md R2). The quadratic is irreducible
over Q(c) (its discriminant 4(1 + c)(9 + c) is not a square in Q(c)), so {1, lam} is a basis of F over
Q(c): ``a + b lam == 0`` iff ``a == b == 0``, which makes equality exact and decidable.

An element is ``(a + b lam) / d`` with a, b, d in Q[c] (python-flint ``fmpq_poly``), d != 0, kept in
lowest terms with d monic. Inversion uses the conjugate lam' = (10 + 2c)/16 - lam:
(a + b lam)(a + b lam') = a^2 + a b (10 + 2c)/16 + b^2/16, a non-zero polynomial when a + b lam != 0.

>>> L, c = QL.lam(), QL.c()
>>> 16 * L * L - 2 * (5 + c) * L + 1 == QL(0)
True
>>> (1 / (4 * L - 1)) * (4 * L - 1) == QL(1)
True
"""

from __future__ import annotations

from functools import lru_cache

from flint import arb, ctx, fmpq, fmpq_poly

from .rules import TWO_RING, Vec, level1_value

PATCHES = ("P1", "P2", "P3")
#: level-1 grid position of B-spline control point [0][0] of each piece (net[i][j] at offset + (i, j))
NET_OFFSETS = {"P1": (0, -1), "P2": (0, 0), "P3": (-1, 0)}
#: uniform cubic B-spline segment -> Bezier (per direction), times 6
B2Z = ((1, 4, 1, 0), (0, 4, 2, 0), (0, 2, 4, 0), (0, 1, 4, 1))


# ------------------------------------------------------------------------ the field F
_C = fmpq_poly([0, 1])
_S = fmpq_poly([fmpq(10, 16), fmpq(2, 16)])  # lam + lam' = (10 + 2c)/16; lam lam' = 1/16


def _poly(x):
    if isinstance(x, fmpq_poly):
        return x
    if isinstance(x, (int, fmpq)) and not isinstance(x, bool):
        return fmpq_poly([x])
    raise TypeError(f"not an exact scalar: {x!r}")


class QL:
    """An element (a + b lam) / d of F (see the module docstring; docs/readings.md R2).

    Parameters
    ----------
    a, b, d : int, fmpq or fmpq_poly in c
        Numerators and denominator (d != 0); stored in lowest terms with d monic.

    Examples
    --------
    At k = 4 (c = 0) the subdominant eigenvalue is lam = 1/2 (16 lam^2 - 10 lam + 1 = 0):

    >>> x = (1 + QL.lam()) / (QL.c() + 2)
    >>> x.evaluate(arb(0), arb(1) / 2), x.integer_form()
    (0.750000000000000, [[1], [1], [2, 1]])
    """

    __slots__ = ("a", "b", "d")

    def __init__(self, a=0, b=0, d=1):
        a, b, d = _poly(a), _poly(b), _poly(d)
        if d == 0:
            raise ZeroDivisionError("zero denominator")
        g = a.gcd(b).gcd(d) if (a != 0 or b != 0) else d
        if g != 0 and g.degree() > 0:
            a, b, d = a / g, b / g, d / g  # exact: g divides all three
            a, b, d = _poly(a), _poly(b), _poly(d)
        lead = d.coeffs()[-1]
        self.a, self.b, self.d = a / lead, b / lead, d / lead

    @classmethod
    def lam(cls):
        return cls(0, 1)

    @classmethod
    def c(cls):
        return cls(_C)

    @staticmethod
    def of(x):
        return x if isinstance(x, QL) else QL(x)

    def is_zero(self):
        return self.a == 0 and self.b == 0  # exact polynomials: == is equality

    def __eq__(self, other):
        return (self - QL.of(other)).is_zero()

    def __hash__(self):
        raise TypeError("QL is not hashable")

    def __add__(self, other):
        o = QL.of(other)
        return QL(self.a * o.d + o.a * self.d, self.b * o.d + o.b * self.d, self.d * o.d)

    __radd__ = __add__

    def __neg__(self):
        return QL(-self.a, -self.b, self.d)

    def __sub__(self, other):
        return self + (-QL.of(other))

    def __rsub__(self, other):
        return QL.of(other) - self

    def __mul__(self, other):
        o = QL.of(other)
        bb = self.b * o.b  # lam^2 = ((10 + 2c) lam - 1)/16
        return QL(self.a * o.a - bb / 16, self.a * o.b + self.b * o.a + bb * _S, self.d * o.d)

    __rmul__ = __mul__

    def inverse(self):
        if self.is_zero():
            raise ZeroDivisionError("inverse of 0 in F")
        norm = self.a * self.a + self.a * self.b * _S + self.b * self.b / 16
        return QL(self.d * (self.a + self.b * _S), -self.d * self.b, norm)

    def __truediv__(self, other):
        return self * QL.of(other).inverse()

    def __rtruediv__(self, other):
        return QL.of(other) * self.inverse()

    def __repr__(self):
        return f"(({self.a}) + ({self.b})*lam)/({self.d})"

    # -------------------------------------------------------------- specializations
    def integer_form(self):
        """``[A, B, D]``: integer coefficient lists (constant first) with self = (A(c) + B(c) lam)/D(c)."""
        from math import lcm

        den = lcm(*(int(q.q) for p in (self.a, self.b, self.d) for q in (p.coeffs() or [fmpq(0)])))
        return [[int(q * den) for q in (p.coeffs() or [fmpq(0)])] for p in (self.a, self.b, self.d)]

    def evaluate(self, c, lam):
        """Ball enclosing self at every (c, lam) in the balls ``c`` and ``lam``; raises ZeroDivisionError when
        the denominator's ball contains 0 (the caller sets the working precision)."""
        den = horner(self.d, c)
        if den.contains(0):  # a ball containing 0 cannot be divided by: the value may not exist
            raise ZeroDivisionError("the denominator may vanish")
        return (horner(self.a, c) + horner(self.b, c) * lam) / den


def horner(p, x, acc=None):
    """p(x) by Horner's scheme, for an fmpq_poly p or a list of coefficients (constant term first), accumulated
    onto ``acc`` (the zero of x's ring; default arb(0)). On a ball x, a ball containing p(y) for every y in x.

    Examples
    --------
    >>> horner(fmpq_poly([1, 2, 3]), arb(2))   # 1 + 2 * 2 + 3 * 4
    17.0000000000000
    >>> horner([fmpq(1), 2, 3], fmpq(1, 2), fmpq(0))
    11/4
    """
    acc = arb(0) if acc is None else acc
    for q in reversed(p.coeffs() if isinstance(p, fmpq_poly) else p):
        acc = acc * x + q
    return acc


class StatementError(ValueError):
    """The derivation of the statement failed (cannot happen for the true rules; a tripwire).

    Parameters
    ----------
    message : str
        Which identity or denominator failed.

    Examples
    --------
    >>> issubclass(StatementError, ValueError), all(ok for _, ok in derivation().hypotheses)
    (True, True)
    """


# ------------------------------------------------------------------------ points in F^2
def rot(delta, p):
    """R^delta p in the normalized frame, R = [[0, -1], [1, 2c]] (delta in -1..2; docs/readings.md R3).

    Examples
    --------
    >>> x, y = rot(1, (QL(1), QL(0)))
    >>> x == 0, y == 1, [q == w for q, w in zip(rot(-1, rot(1, (QL(1), QL(2)))), (1, 2))]
    (True, True, [True, True])
    """
    c2 = 2 * QL.c()
    x, y = p
    for _ in range(delta % 4 if delta >= 0 else 0):
        x, y = -y, x + c2 * y
    if delta == -1:
        x, y = c2 * x + y, -x
    return (x, y)


_ZERO = Vec((QL(0), QL(0)))


def _lookup(values):
    def look(delta, p):
        if p == (0, 0):
            return _ZERO  # the centre is 0 in Fourier mode 1
        return Vec(rot(delta, values[p]))
    return look


def level1(values, A, B):
    """Level-1 mode-1 value at sector-local position (A, B) from the level-0 sector-0 ``values``.

    Parameters
    ----------
    values : dict[(int, int), (QL, QL)]
        The sector-0 two-ring (:data:`TWO_RING`) in the normalized frame.

    Returns
    -------
    (QL, QL)
        By :mod:`.rules` (bmz04 Fig. 1), rotated by :func:`rot` (docs/readings.md R3).

    Examples
    --------
    The eigenvector is an eigenvector: one step scales it by lam (here at the two-ring point (1, 0)):

    >>> v = derivation().eigenvector
    >>> [q == QL.lam() * w for q, w in zip(level1(v, 1, 0), v[(1, 0)])]
    [True, True]
    """
    if (A, B) == (0, 0):
        return _ZERO
    delta, v = level1_value(A, B, _lookup(values), _ZERO)
    return Vec(rot(delta, v))


# ------------------------------------------------------------------------ the derivation
def _solve(rows, rhs):
    """Exact Gauss-Jordan over F; rows: n x m (n >= m). Returns the solution; raises if inconsistent
    or not of full column rank."""
    n, m = len(rows), len(rows[0])
    M = [list(r) + [b] for r, b in zip(rows, rhs)]
    r = 0
    for col in range(m):
        piv = next((i for i in range(r, n) if not M[i][col].is_zero()), None)
        if piv is None:
            raise StatementError("the eigenvector is not determined (rank deficient)")
        M[r], M[piv] = M[piv], M[r]
        inv = M[r][col].inverse()
        M[r] = [x * inv for x in M[r]]
        for i in range(n):
            if i != r and not M[i][col].is_zero():
                f = M[i][col]
                M[i] = [x - f * y for x, y in zip(M[i], M[r])]
        r += 1
    if any(not M[i][m].is_zero() for i in range(r, n)):
        raise StatementError("the eigen-equation has no solution with v(1, 0) = (1, 0)")
    return [M[i][m] for i in range(m)]


def _eigen_equations(values):
    """M(c) v - lam v on the 6 two-ring positions (12 coordinates in F)."""
    L = QL.lam()
    return [level1(values, *p)[d] - L * values[p][d] for p in TWO_RING for d in range(2)]


def _eigenvector():
    """Solve for v with v(1, 0) = (1, 0): the 10 other coordinates are linear unknowns."""
    unknowns = [(p, d) for p in TWO_RING[1:] for d in range(2)]

    def values_with(assign):
        vals = {TWO_RING[0]: (QL(1), QL(0))}
        for p in TWO_RING[1:]:
            vals[p] = (assign.get((p, 0), QL(0)), assign.get((p, 1), QL(0)))
        return vals

    base = _eigen_equations(values_with({}))  # affine part
    cols = []
    for u in unknowns:
        eq = _eigen_equations(values_with({u: QL(1)}))
        cols.append([e - b for e, b in zip(eq, base)])
    rows = [[cols[j][i] for j in range(len(unknowns))] for i in range(len(base))]
    sol = _solve(rows, [-b for b in base])
    return values_with(dict(zip(unknowns, sol)))


def bspline_to_bezier(net, zero=None):
    """Bezier net of the uniform bicubic B-spline segment of a 4x4 net of points: ``B2Z`` (the B-spline to
    Bezier matrix, / 6) applied in both directions; points of F (exact; the default) or with ``zero`` the
    origin of their kind (``(arb(0), arb(0))``: a tagged sector's nets).

    Examples
    --------
    A linear net ``(i, j)`` gives the Bezier points ``(1 + i/3, 1 + j/3)`` of the middle segment:

    >>> Z = bspline_to_bezier([[(QL(i), QL(j)) for j in range(4)] for i in range(4)])
    >>> [q == w for q, w in zip(Z[0][0] + Z[1][2], (1, 1, fmpq(4, 3), fmpq(5, 3)))]
    [True, True, True, True]
    """
    def lin(coeffs, pts):
        acc = _ZERO if zero is None else Vec(zero)
        for a, p in zip(coeffs, pts):
            if a:
                acc = acc + Vec(p) * fmpq(a, 6)
        return acc
    tmp = [[lin(B2Z[i], [net[r][j] for r in range(4)]) for j in range(4)] for i in range(4)]
    return [[tuple(lin(B2Z[j], tmp[i])) for j in range(4)] for i in range(4)]


def _swap(p):
    return (p[1], p[0])


def _eq(p, q):
    return p[0] == q[0] and p[1] == q[1]


def split_half(curve):
    """De Casteljau halves (left, right) of a cubic Bezier curve of points of F (exact) or of arb balls.

    Examples
    --------
    >>> split_half([(0, 0), (1, 0), (2, 0), (3, 3)])[1]
    [(3/2, 3/8), (2, 3/4), (5/2, 3/2), (3, 3)]
    """
    half = fmpq(1, 2)
    left, right, pts = [curve[0]], [curve[3]], list(curve)
    for _ in range(3):
        pts = [((p[0] + q[0]) * half, (p[1] + q[1]) * half) for p, q in zip(pts, pts[1:])]
        left.append(pts[0])
        right.append(pts[-1])
    return left, right[::-1]


class Derivation:
    """What :func:`derivation` computes: ``eigenvector`` {position: (x, y)}, ``bspline`` and ``bezier``
    nets {piece: 4x4 of (x, y)} with entries in F, ``symmetric`` and ``hypotheses`` [(name, ok)].

    Attributes
    ----------
    eigenvector : dict[(int, int), (QL, QL)]
    bspline, bezier : dict[str, 4 x 4 of (QL, QL)]
        Pieces ``P1, P2, P3`` of layer 0 (docs/readings.md R4).
    symmetric : bool
    hypotheses : list of (str, bool)
        docs/appendix_a.md section 0.

    Examples
    --------
    >>> d = derivation()
    >>> isinstance(d, Derivation), sorted(d.bezier), d.symmetric, len(d.hypotheses)
    (True, ['P1', 'P2', 'P3'], True, 8)
    """

    def __init__(self, eigenvector, bspline, bezier, symmetric, hypotheses):
        self.eigenvector, self.bspline, self.bezier = eigenvector, bspline, bezier
        self.symmetric, self.hypotheses = symmetric, hypotheses

    def integer_forms(self, which="bspline"):
        """{piece: 4x4 of ([A,B,D], [A,B,D])}: the exact forms (A(c) + B(c) lam)/D(c) of the nets."""
        nets = self.bspline if which == "bspline" else self.bezier
        return {n: [[tuple(q.integer_form() for q in p) for p in row] for row in net] for n, net in nets.items()}

    def denominators(self):
        """Every denominator in Q[c] that the specialization divides by (eigenvector and nets)."""
        out = [q.d for p in self.eigenvector.values() for q in p]
        out += [q.d for nets in (self.bspline, self.bezier) for net in nets.values() for row in net
                for p in row for q in p]
        return out


@lru_cache(maxsize=1)
def derivation():
    """The statement's maps for every valence at once (module docstring); cached per process.

    Returns
    -------
    Derivation
        The subdominant eigenvector, the layer-0 nets of the characteristic map in F (bmz04 section 3,
        docs/readings.md R2-R4) and the hypotheses of docs/appendix_a.md section 0.

    Examples
    --------
    The normalization Phi(1, 0) = (1, 0), exact in F:

    >>> x, y = derivation().bezier["P1"][3][0]
    >>> x == 1, y == 0
    (True, True)
    """
    vals = _eigenvector()
    eig_ok = all(e.is_zero() for e in _eigen_equations(vals))
    vec, bs, bz = _normalized_nets(vals)
    symmetric, hyp = _hypotheses(bz, eig_ok)
    return Derivation(vec, bs, bz, symmetric, hyp)


def _normalized_nets(vals):
    """(eigenvector, B-spline nets, Bezier nets), scaled so that Phi(1, 0) = (1, 0)."""
    raw = {n: [[level1(vals, oa + i, ob + j) for j in range(4)] for i in range(4)]
           for n, (oa, ob) in NET_OFFSETS.items()}
    phi10 = bspline_to_bezier(raw["P1"])[3][0]
    if phi10[0].is_zero():
        raise StatementError("Phi(1, 0) = 0: the normalization is impossible")
    scale = phi10[0].inverse()
    bs = {n: [[tuple(q * scale for q in p) for p in row] for row in net] for n, net in raw.items()}
    vec = {p: tuple(q * scale for q in v) for p, v in vals.items()}
    return vec, bs, {n: bspline_to_bezier(net) for n, net in bs.items()}


def _hypotheses(bz, eig_ok):
    """(symmetric, [(hypothesis, holds)]): docs/appendix_a.md section 0, exact in F."""
    P1, P2, P3 = bz["P1"], bz["P2"], bz["P3"]
    L = QL.lam()
    zero, one = QL(0), QL(1)

    def scaled(curve):
        return [(L * p[0], L * p[1]) for p in curve]

    def same(c1, c2):
        return all(_eq(p, q) for p, q in zip(c1, c2))

    col = lambda net, i: [net[i][j] for j in range(4)]  # side s = i/3 (a curve in t)
    row = lambda net, j: [net[i][j] for i in range(4)]  # side t = j/3 (a curve in s)
    inner1, inner3 = split_half(col(P1, 0)), split_half(row(P3, 0))
    symmetric = all(_eq(P3[i][j], _swap(P1[j][i])) and _eq(P2[i][j], _swap(P2[j][i]))
                    for i in range(4) for j in range(4))
    hyp = [
        ("eigen-equation M(c) v = lam v on the two-ring (identity in F)", eig_ok),
        ("Phi(1, 0) = (1, 0)", _eq(P1[3][0], (one, zero))),
        ("the edge v = 0 is mapped onto the x-axis (P1, t = 0)", all(p[1].is_zero() for p in row(P1, 0))),
        ("the edge u = 0 is mapped onto the y-axis (P3, s = 0)", all(p[0].is_zero() for p in col(P3, 0))),
        ("Phi continuous across P1 | P2 (v = 1/2)", same(row(P1, 3), row(P2, 0))),
        ("Phi continuous across P2 | P3 (u = 1/2)", same(col(P3, 3), col(P2, 0))),
        ("layer boundary: Phi(1/2, v) = lam Phi(1, 2v)",
         same(inner1[0], scaled(col(P1, 3))) and same(inner1[1], scaled(col(P2, 3)))),
        ("layer boundary: Phi(u, 1/2) = lam Phi(2u, 1)",
         same(inner3[0], scaled(row(P3, 3))) and same(inner3[1], scaled(row(P2, 3)))),
    ]
    return symmetric, hyp


# ------------------------------------------------------------------------ one valence in arb
def lam_of(c):
    """lam(c) = (5 + c + sqrt((1 + c)(9 + c)))/16: the subdominant eigenvalue, at c = cos(2 pi/k) for the
    valence k (docs/readings.md R2); the one definition of lam in the trusted base (arb or acb c, the
    principal square root).

    Examples
    --------
    >>> lam_of(arb(0)), lam_of(arb(-1) / 2).overlaps((9 + arb(17).sqrt()) / 32)   # k = 4, k = 3
    (0.500000000000000, True)
    """
    return (5 + c + ((1 + c) * (9 + c)).sqrt()) / 16


def c_lam(k, prec):
    """Balls (c, lam) holding cos(2 pi/k) and lam(k) = (5 + c + sqrt((1 + c)(9 + c)))/16.

    Parameters
    ----------
    prec : int
        Bits.

    Returns
    -------
    (arb, arb)
        docs/readings.md R2.

    Examples
    --------
    k = 4: the regular grid, lam = 1/2; k = 3: lam = (9 + sqrt 17)/32:

    >>> c_lam(4, 53)[1], c_lam(3, 53)[1].overlaps((9 + arb(17).sqrt()) / 32)
    (0.500000000000000, True)
    """
    with ctx.workprec(prec):
        c = arb(fmpq(2, k)).cos_pi()
        return c, lam_of(c)


def nets_for_valence(k, prec, which="bezier"):
    """arb nets {piece: 4x4 of (x, y)} of valence k, evaluated from the derived exact forms; raises
    :class:`StatementError` if a denominator may vanish at c = cos(2 pi/k).

    Examples
    --------
    At k = 4 the characteristic map is the identity: piece P1 = [1/2, 1] x [0, 1/2] has the Bezier
    points (1/2 + i/6, j/6):

    >>> x, y = nets_for_valence(4, 53)["P1"][1][1]
    >>> x.overlaps(arb(2) / 3), y.overlaps(arb(1) / 6)
    (True, True)
    """
    d = derivation()
    c, lam = c_lam(k, prec)
    nets = d.bezier if which == "bezier" else d.bspline
    with ctx.workprec(prec):
        try:
            for q in d.denominators():
                QL(1, 0, q).evaluate(c, lam)
            return {n: [[tuple(q.evaluate(c, lam) for q in p) for p in row] for row in net]
                    for n, net in nets.items()}
        except ZeroDivisionError:
            raise StatementError(f"a denominator of the exact forms may vanish at c = cos(2 pi/{k})") from None
