"""The field F = Q(c)[lam] / (16 lam^2 - 2(5 + c) lam + 1) in which the characteristic map lives (trusted).

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

from flint import arb, fmpq, fmpq_poly

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


def horner(p, x):
    """p(x) for an fmpq_poly p and an arb x (ball arithmetic, Horner's scheme).

    Returns
    -------
    arb
        A ball containing p(y) for every y in x.

    Examples
    --------
    >>> horner(fmpq_poly([1, 2, 3]), arb(2))   # 1 + 2 * 2 + 3 * 4
    17.0000000000000
    """
    acc = arb(0)
    for q in reversed(p.coeffs()):
        acc = acc * x + q
    return acc
