"""The statement, derived from the valence and the Catmull-Clark rules alone (trusted): the field
F = Q(c)[lam]/(16 lam^2 - 2(5 + c) lam + 1), the mode-1 eigenvector, the layer-0 nets and their hypotheses
(exact in F, every valence at once), c, lam and the nets of one valence (arb). docs/appendix_a.md
sections 0 and 9.1; docs/readings.md R2-R4.

>>> L, c = QL.lam(), QL.c()
>>> 16 * L * L - 2 * (5 + c) * L + 1 == 0, (4 * L - 1).inverse() * (4 * L - 1) == 1
(True, True)
"""

from dataclasses import dataclass
from functools import lru_cache
from math import lcm

from flint import arb, ctx, fmpq, fmpq_poly

from .rules import TWO_RING, Vec, level1_value

PATCHES = ("P1", "P2", "P3")
#: level-1 grid position of B-spline control point [0][0] of each piece (net[i][j] at offset + (i, j))
NET_OFFSETS = {"P1": (0, -1), "P2": (0, 0), "P3": (-1, 0)}
#: uniform cubic B-spline segment -> Bezier (per direction), times 6
B2Z = ((1, 4, 1, 0), (0, 4, 2, 0), (0, 2, 4, 0), (0, 1, 4, 1))
_S = fmpq_poly([fmpq(10, 16), fmpq(2, 16)])  # lam + lam' = (10 + 2c)/16; lam lam' = 1/16


class QL:
    """(a + b lam)/d in F, a, b, d in Q[c] in lowest terms, d monic (docs/appendix_a.md section 9.1).

    >>> x = (1 + QL.lam()) / (QL.c() + 2)     # k = 4: c = 0, lam = 1/2
    >>> x.evaluate(arb(0), arb(1) / 2), x.integer_form()
    (0.750000000000000, [[1], [1], [2, 1]])
    """

    __slots__ = ("a", "b", "d")

    def __init__(self, a=0, b=0, d=1):
        a, b, d = (x if isinstance(x, fmpq_poly) else fmpq_poly([x]) for x in (a, b, d))
        if d == 0:
            raise ZeroDivisionError("zero denominator")
        g = a.gcd(b).gcd(d)  # monic, non-zero
        if g.degree() > 0:
            a, b, d = a / g, b / g, d / g  # exact division
        lead = d.coeffs()[-1]
        self.a, self.b, self.d = a / lead, b / lead, d / lead

    @classmethod
    def lam(cls):
        return cls(0, 1)

    @classmethod
    def c(cls):
        return cls(fmpq_poly([0, 1]))

    @staticmethod
    def of(x):
        return x if isinstance(x, QL) else QL(x)

    def is_zero(self):
        return self.a == 0 and self.b == 0  # exact polynomials: == is equality

    def __eq__(self, other):
        return (self - other).is_zero()

    def __add__(self, other):
        o = QL.of(other)
        return QL(self.a * o.d + o.a * self.d, self.b * o.d + o.b * self.d, self.d * o.d)

    def __neg__(self):
        return QL(-self.a, -self.b, self.d)

    def __sub__(self, other):
        return self + -QL.of(other)

    def __mul__(self, other):
        o = QL.of(other)
        bb = self.b * o.b  # lam^2 = ((10 + 2c) lam - 1)/16
        return QL(self.a * o.a - bb / 16, self.a * o.b + self.b * o.a + bb * _S, self.d * o.d)

    __radd__, __rmul__ = __add__, __mul__

    def inverse(self):
        if self.is_zero():
            raise ZeroDivisionError("inverse of 0 in F")
        norm = self.a * self.a + self.a * self.b * _S + self.b * self.b / 16  # times the conjugate
        return QL(self.d * (self.a + self.b * _S), -self.d * self.b, norm)

    def __truediv__(self, other):
        return self * QL.of(other).inverse()

    def integer_form(self):
        """``[A, B, D]``: integer coefficient lists (constant first) with self = (A(c) + B(c) lam)/D(c)."""
        den = lcm(*(int(q.q) for p in (self.a, self.b, self.d) for q in (p.coeffs() or [fmpq(0)])))
        return [[int(q * den) for q in (p.coeffs() or [fmpq(0)])] for p in (self.a, self.b, self.d)]

    def evaluate(self, c, lam):
        """Ball holding self at every (c, lam) of the balls; ZeroDivisionError if the denominator may vanish."""
        den = horner(self.d, c)
        if den.contains(0):  # a ball containing 0 cannot be divided by: the value may not exist
            raise ZeroDivisionError("the denominator may vanish")
        return (horner(self.a, c) + horner(self.b, c) * lam) / den


def horner(p, x, acc=None):
    """p(x) (fmpq_poly or coefficients, constant first) accumulated onto ``acc`` (default arb(0)); on a ball x,
    a ball holding p(y) for every y in x.

    >>> horner(fmpq_poly([1, 2, 3]), arb(2)), horner([fmpq(1), 2, 3], fmpq(1, 2), fmpq(0))
    (17.0000000000000, 11/4)
    """
    acc = arb(0) if acc is None else acc
    for q in reversed(p.coeffs() if isinstance(p, fmpq_poly) else p):
        acc = acc * x + q
    return acc


class StatementError(ValueError):
    """The derivation of the statement failed (cannot happen for the true rules; a tripwire)."""


def rot(delta, p):
    """R^delta p in the normalized frame, R = [[0, -1], [1, 2c]] (delta in -1..2; docs/readings.md R3).

    >>> [q == w for q, w in zip(rot(1, (QL(1), QL(0))) + rot(-1, rot(1, (QL(1), QL(2)))), (0, 1, 1, 2))]
    [True, True, True, True]
    """
    c2, (x, y) = 2 * QL.c(), p
    for _ in range(delta % 4 if delta >= 0 else 0):
        x, y = -y, x + c2 * y
    return (c2 * x + y, -x) if delta == -1 else (x, y)


_ZERO = Vec((QL(0), QL(0)))


def level1(values, A, B):
    """Level-1 mode-1 value at sector-local (A, B) from the sector-0 two-ring ``values`` {position: (x, y)}.

    >>> v = derivation().eigenvector     # an eigenvector: one step scales it by lam
    >>> [q == QL.lam() * w for q, w in zip(level1(v, 1, 0), v[(1, 0)])]
    [True, True]
    """
    def look(delta, p):
        return _ZERO if p == (0, 0) else Vec(rot(delta, values[p]))  # the centre is 0 in mode 1
    if (A, B) == (0, 0):
        return _ZERO
    delta, v = level1_value(A, B, look, _ZERO)
    return Vec(rot(delta, v))


def _equations(assign):
    """(v, M(c) v - lam v on the 12 coordinates) for v(1, 0) = (1, 0) and the other coordinates from ``assign``."""
    vals = {p: tuple(assign.get((p, d), QL(int(p == TWO_RING[0] and d == 0))) for d in range(2)) for p in TWO_RING}
    return vals, [level1(vals, *p)[d] - QL.lam() * vals[p][d] for p in TWO_RING for d in range(2)]


def _eigenvector():
    """v with v(1, 0) = (1, 0) and M(c) v = lam v: the 10 other coordinates by exact Gauss-Jordan over F; the
    residuals (checked, part S)."""
    unknowns = [(p, d) for p in TWO_RING[1:] for d in range(2)]
    base = _equations({})[1]  # the affine part; then one column per unknown, augmented by -base
    cols = [[e - b for e, b in zip(_equations({u: QL(1)})[1], base)] for u in unknowns] + [[-b for b in base]]
    M = [list(row) for row in zip(*cols)]
    for col in range(len(unknowns)):
        piv = next((i for i in range(col, len(M)) if not M[i][col].is_zero()), None)
        if piv is None:
            raise StatementError("the eigenvector is not determined (rank deficient)")
        piv = M.pop(piv)
        M.insert(col, [x * piv[col].inverse() for x in piv])
        M = [r if i == col or r[col].is_zero() else [x - r[col] * y for x, y in zip(r, M[col])]
             for i, r in enumerate(M)]
    return _equations({u: M[i][-1] for i, u in enumerate(unknowns)})


def bspline_to_bezier(net, zero=None):
    """Bezier net of the bicubic B-spline segment of a 4x4 net of points (``B2Z`` / 6 both ways); points of F, or
    with ``zero`` the origin of their kind (``(arb(0), arb(0))``: a tagged sector's nets).

    >>> Z = bspline_to_bezier([[(QL(i), QL(j)) for j in range(4)] for i in range(4)])   # linear: (1 + i/3, 1 + j/3)
    >>> [q == w for q, w in zip(Z[0][0] + Z[1][2], (1, 1, fmpq(4, 3), fmpq(5, 3)))]
    [True, True, True, True]
    """
    def lin(coeffs, pts):
        return sum((Vec(p) * fmpq(a, 6) for a, p in zip(coeffs, pts) if a), _ZERO if zero is None else Vec(zero))
    tmp = [[lin(B2Z[i], [net[r][j] for r in range(4)]) for j in range(4)] for i in range(4)]
    return [[tuple(lin(B2Z[j], tmp[i])) for j in range(4)] for i in range(4)]


def split_half(curve):
    """De Casteljau halves (left, right) of a cubic Bezier curve of points of F or of arb balls.

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


def entrywise(nets, f):
    """{piece: net} with ``f`` applied to every coordinate of every point."""
    return {n: [[tuple(f(q) for q in p) for p in row] for row in net] for n, net in nets.items()}


@dataclass(frozen=True)
class Derivation:
    """What :func:`derivation` computes (entries in F); ``hypotheses`` [(name, holds)]: docs/appendix_a.md section 0.

    >>> d = derivation()
    >>> sorted(d.bezier), d.symmetric, len(d.hypotheses), [len(f) for f in d.integer_forms()["P1"][0][0][1]]
    (['P1', 'P2', 'P3'], True, 8, [1, 2, 3])
    """

    eigenvector: dict
    bspline: dict
    bezier: dict
    symmetric: bool
    hypotheses: list

    def integer_forms(self):
        """{piece: 4x4 of ([A,B,D], [A,B,D])}: the exact forms (A(c) + B(c) lam)/D(c) of the B-spline nets."""
        return entrywise(self.bspline, QL.integer_form)


@lru_cache(maxsize=1)
def derivation():
    """The statement's maps for every valence at once, scaled so that Phi(1, 0) = (1, 0); cached per process.

    >>> x, y = derivation().bezier["P1"][3][0]
    >>> x == 1, y == 0
    (True, True)
    """
    vals, residuals = _eigenvector()
    raw = {n: [[level1(vals, a + i, b + j) for j in range(4)] for i in range(4)] for n, (a, b) in NET_OFFSETS.items()}
    phi10 = bspline_to_bezier(raw["P1"])[3][0]
    if phi10[0].is_zero():
        raise StatementError("Phi(1, 0) = 0: the normalization is impossible")
    scale = phi10[0].inverse()
    bs = entrywise(raw, lambda q: q * scale)
    bz = {n: bspline_to_bezier(net) for n, net in bs.items()}
    vec = {p: tuple(q * scale for q in v) for p, v in vals.items()}
    return Derivation(vec, bs, bz, *_hypotheses(bz, all(e.is_zero() for e in residuals)))


def _hypotheses(bz, eig_ok):
    """(symmetric, [(hypothesis, holds)]): docs/appendix_a.md section 0, exact in F."""
    P1, P2, P3 = bz["P1"], bz["P2"], bz["P3"]
    L = QL.lam()

    def same(c1, c2, scale=1):
        return all(p[0] == scale * q[0] and p[1] == scale * q[1] for p, q in zip(c1, c2))

    col = lambda net, i: [net[i][j] for j in range(4)]  # side s = i/3 (a curve in t)
    row = lambda net, j: [net[i][j] for i in range(4)]  # side t = j/3 (a curve in s)
    inner1, inner3 = split_half(col(P1, 0)), split_half(row(P3, 0))
    symmetric = all(same([P3[i][j], P2[i][j]], [P1[j][i][::-1], P2[j][i][::-1]]) for i in range(4) for j in range(4))
    return symmetric, [
        ("eigen-equation M(c) v = lam v on the two-ring (identity in F)", eig_ok),
        ("Phi(1, 0) = (1, 0)", same([P1[3][0]], [(1, 0)])),
        ("the edge v = 0 is mapped onto the x-axis (P1, t = 0)", all(p[1].is_zero() for p in row(P1, 0))),
        ("the edge u = 0 is mapped onto the y-axis (P3, s = 0)", all(p[0].is_zero() for p in col(P3, 0))),
        ("Phi continuous across P1 | P2 (v = 1/2)", same(row(P1, 3), row(P2, 0))),
        ("Phi continuous across P2 | P3 (u = 1/2)", same(col(P3, 3), col(P2, 0))),
        ("layer boundary: Phi(1/2, v) = lam Phi(1, 2v)",
         same(inner1[0], col(P1, 3), L) and same(inner1[1], col(P2, 3), L)),
        ("layer boundary: Phi(u, 1/2) = lam Phi(2u, 1)",
         same(inner3[0], row(P3, 3), L) and same(inner3[1], row(P2, 3), L)),
    ]


def lam_of(c):
    """lam(c) = (5 + c + sqrt((1 + c)(9 + c)))/16, at c = cos(2 pi/k) the subdominant eigenvalue (R2): the one
    definition of lam in the trusted base (arb or acb c, the principal square root).

    >>> lam_of(arb(0)), lam_of(arb(-1) / 2).overlaps((9 + arb(17).sqrt()) / 32)   # k = 4, k = 3
    (0.500000000000000, True)
    """
    return (5 + c + ((1 + c) * (9 + c)).sqrt()) / 16


def c_lam(k, prec):
    """Balls (c, lam) holding cos(2 pi/k) and lam(k) at ``prec`` bits."""
    with ctx.workprec(prec):
        c = arb(fmpq(2, k)).cos_pi()
        return c, lam_of(c)


def nets_for_valence(k, prec):
    """arb Bezier nets {piece: 4x4 of (x, y)} of valence k from the exact forms; :class:`StatementError` if a
    denominator (eigenvector, nets) may vanish at c = cos(2 pi/k).

    >>> x, y = nets_for_valence(4, 53)["P1"][1][1]     # k = 4: the identity, P1 = [1/2, 1] x [0, 1/2]
    >>> x.overlaps(arb(2) / 3), y.overlaps(arb(1) / 6)
    (True, True)
    """
    d = derivation()
    c, lam = c_lam(k, prec)
    with ctx.workprec(prec):
        try:
            for p in [*d.eigenvector.values(), *(p for net in d.bspline.values() for row in net for p in row)]:
                [q.evaluate(c, lam) for q in p]  # every denominator checked
            return entrywise(d.bezier, lambda q: q.evaluate(c, lam))
        except ZeroDivisionError:
            raise StatementError(f"a denominator of the exact forms may vanish at c = cos(2 pi/{k})") from None
