"""The field Q(c, lam) in which every characteristic-map control point lives (docs/readings.md R2, R3).

``c`` stands for cos(2 pi / k) and ``lam`` for the subdominant eigenvalue of the Catmull-Clark
subdivision matrix of valence k, the larger root of

    16 lam**2 - 2 (5 + c) lam + 1 = 0                                  (bmz04 section 4.3, R2)

An element is kept in the canonical form ``a(c) + b(c) lam`` with ``a, b`` in Q(c) (sympy's
rational function field, exact). Since ``c = 8 lam + 1/(2 lam) - 5``, Q(c, lam) = Q(lam): an element
is also a rational function of ``lam`` alone (:meth:`QcLam.as_lam_function`).

Specialization: :func:`specialize` turns an element into an exact sympy number, an ``arb`` ball, or a
float once ``c`` is fixed.
"""

from __future__ import annotations

from fractions import Fraction

from sympy import QQ, Rational, sqrt, sympify
from sympy.polys.fields import field

from ccproof.valence import lam_from_c

#: Q(c) as a sympy rational-function field and its generator.
QC, C = field("c", QQ)


def _qc(x):
    """Coerce an int, Fraction, sympy Rational or Q(c) element into Q(c)."""
    if isinstance(x, Fraction):
        return QC(QQ(x.numerator, x.denominator))
    return QC(x)


class QcLam:
    """An element ``a + b*lam`` of Q(c, lam), lam**2 = (5 + c)/8 lam - 1/16.

    The field in which the characteristic map is exact for every valence at once, c = cos(2 pi/k)
    symbolic and lam the subdominant eigenvalue (bmz04 section 3; docs/readings.md R2, R3).

    Parameters
    ----------
    a : int or Fraction or sympy.Rational or element of Q(c) or QcLam, optional
        The rational part (a :class:`QcLam` is copied, ``b`` then ignored). Default 0.
    b : int or Fraction or sympy.Rational or element of Q(c), optional
        The coefficient of lam. Default 0.

    Examples
    --------
    >>> lam = QcLam.lam()
    >>> lam * lam == QcLam((C + 5) / 8) * lam - QcLam(Rational(1, 16))
    True
    >>> x = QcLam(C + 1, 2)
    >>> (x * x.inverse()) == QcLam.one()
    True
    """

    __slots__ = ("a", "b")

    def __init__(self, a=0, b=0):
        self.a = _qc(a) if not isinstance(a, QcLam) else a.a
        self.b = _qc(b) if not isinstance(a, QcLam) else a.b

    @classmethod
    def lam(cls):
        return cls(0, 1)

    @classmethod
    def one(cls):
        return cls(1, 0)

    @staticmethod
    def _lift(x):
        return x if isinstance(x, QcLam) else QcLam(x)

    def __add__(self, other):
        o = self._lift(other)
        return QcLam(self.a + o.a, self.b + o.b)

    __radd__ = __add__

    def __neg__(self):
        return QcLam(-self.a, -self.b)

    def __sub__(self, other):
        return self + (-self._lift(other))

    def __rsub__(self, other):
        return self._lift(other) - self

    def __mul__(self, other):
        o = self._lift(other)
        bb = self.b * o.b
        # lam^2 = (5 + c)/8 lam - 1/16
        return QcLam(self.a * o.a - bb / 16, self.a * o.b + self.b * o.a + bb * (C + 5) / 8)

    __rmul__ = __mul__

    def norm(self):
        """N(a + b lam) = (a + b lam)(a + b lam') in Q(c), lam' = (5+c)/8 - lam the conjugate root."""
        return self.a * self.a + self.a * self.b * (C + 5) / 8 + self.b * self.b / 16

    def conjugate(self):
        return QcLam(self.a + self.b * (C + 5) / 8, -self.b)

    def inverse(self):
        n = self.norm()
        if n == 0:
            raise ZeroDivisionError("inverse of zero in Q(c, lam)")
        cj = self.conjugate()
        return QcLam(cj.a / n, cj.b / n)

    def __truediv__(self, other):
        return self * self._lift(other).inverse()

    def __rtruediv__(self, other):
        return self._lift(other) * self.inverse()

    def __eq__(self, other):
        try:
            o = self._lift(other)
        except Exception:
            return NotImplemented
        return self.a == o.a and self.b == o.b

    def __hash__(self):
        return hash((self.a, self.b))

    def is_zero(self):
        return self.a == 0 and self.b == 0

    def __repr__(self):
        return f"QcLam({self.a}, {self.b})"

    # ---- canonical integer form -------------------------------------------------------------
    def integer_form(self):
        """Return ``(A, B, D)``, integer coefficient lists (constant term first) with
        ``self = (A(c) + B(c) lam) / D(c)``, ``D`` with positive leading coefficient and the
        integer content of (A, B, D) removed. This is the form written into the certified tables.

        >>> QcLam(C / 2 + 1, Rational(1, 3)).integer_form()
        ([6, 3], [2], [6])
        """
        from math import gcd, lcm

        den = self.a.denom.lcm(self.b.denom)
        polys = [self.a.numer * den.exquo(self.a.denom), self.b.numer * den.exquo(self.b.denom), den]
        dense = [[QQ.to_sympy(x) for x in reversed(p.to_dense())] or [0] for p in polys]
        m = 1
        for lst in dense:
            for x in lst:
                m = lcm(m, int(Rational(x).q))
        ints = [[int(Rational(x) * m) for x in lst] for lst in dense]
        g = 0
        for lst in ints:
            for x in lst:
                g = gcd(g, x)
        if ints[2][-1] < 0:
            g = -g
        ints = [[x // g for x in lst] for lst in ints]
        return tuple(ints)

    def as_expr(self):
        """A sympy expression in the symbols ``c`` and ``lam``."""
        from sympy.abc import c as csym

        lam = sympify("lam")
        return self.a.as_expr().subs(sympify("c"), csym) + self.b.as_expr() * lam

    def as_lam_function(self):
        """This element as a rational function of ``lam`` alone (sympy expression in ``lam``),
        substituting c = 8 lam + 1/(2 lam) - 5."""
        from sympy import cancel

        lam = sympify("lam")
        cval = 8 * lam + Rational(1, 2) / lam - 5
        csym = sympify("c")
        return cancel(self.a.as_expr().subs(csym, cval) + self.b.as_expr().subs(csym, cval) * lam)


def integer_form_string(form):
    """Human-readable string ``(A(c) + B(c)*lam)/D(c)`` of an integer form.

    Parameters
    ----------
    form : tuple of three lists of int
        ``(A, B, D)``, coefficients constant term first, as returned by :meth:`QcLam.integer_form`
        (the form the certified tables store, docs/tables.md).

    Returns
    -------
    str

    Examples
    --------
    >>> integer_form_string(QcLam(C / 2 + 1, Rational(1, 3)).integer_form())
    '((6 + 3*c) + (2)*lam)/(6)'
    >>> integer_form_string(([0], [-1], [1, 0, 2]))
    '((0) + (-1)*lam)/(1 + 2*c^2)'
    """

    def poly_str(coeffs):
        terms = []
        for i, a in enumerate(coeffs):
            if a == 0:
                continue
            mono = "" if i == 0 else ("c" if i == 1 else f"c^{i}")
            if mono and abs(a) == 1:
                t = ("-" if a < 0 else "") + mono
            else:
                t = f"{a}*{mono}" if mono else f"{a}"
            terms.append(t)
        return " + ".join(terms).replace("+ -", "- ") if terms else "0"

    A, B, D = form
    return f"(({poly_str(A)}) + ({poly_str(B)})*lam)/({poly_str(D)})"


def subdominant_lam_sympy(c):
    """Exact lam(c) = (5 + c + sqrt((1 + c)(9 + c)))/16 as a sympy expression (R2;
    :func:`ccproof.valence.lam_from_c` in sympy arithmetic)."""
    return lam_from_c(sympify(c), sqrt)


def eval_integer_form(form, cval, lamval):
    """Evaluate ``(A(c) + B(c) lam)/D(c)`` at given values with Horner's rule.

    Works for any ring-like values: ints/Fractions, sympy numbers, ``flint.arb`` balls (the
    result then encloses the exact value for every c, lam in the input balls) or floats.

    Parameters
    ----------
    form : tuple of three lists of int
        ``(A, B, D)``, coefficients constant term first (:meth:`QcLam.integer_form`).
    cval : scalar
        The value of c = cos(2 pi/k) (docs/readings.md R2).
    lamval : scalar
        The value of lam (same arithmetic as ``cval``).

    Returns
    -------
    scalar
        In the arithmetic of ``cval`` and ``lamval``.

    Examples
    --------
    c/2 + 1 + lam/3 at k = 4 (c = 0, lam = 1/2) is 7/6:

    >>> from fractions import Fraction
    >>> eval_integer_form(QcLam(C / 2 + 1, Rational(1, 3)).integer_form(), Fraction(0), Fraction(1, 2))
    Fraction(7, 6)
    """
    A, B, D = form

    def horner(coeffs):
        acc = 0
        for a in reversed(coeffs):
            acc = acc * cval + a
        return acc

    return (horner(A) + horner(B) * lamval) / horner(D)
