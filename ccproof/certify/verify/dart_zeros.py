"""Exact facts behind the dropped Taylor coefficients of the dart family (trusted; Q(sqrt 5), exact).

L0 = lam(1) = (6 + sqrt 20)/16 is an eigenvalue of B(1) with a symmetric eigenvector rho, and
adj(L0 - B(1)) kappa is a non-zero multiple of rho (:func:`exact_zeros`): what makes the family's
coefficients of low order vanish at h = 0 (docs/tagged_c1.md, item 6, "The dropped coefficients").
"""

from __future__ import annotations

from flint import fmpq

from .dart_family import _B1, _NPOLY
from .tagged_modes import _POS


class QL0:
    """a + b L0 in Q(L0) = Q(sqrt 5), L0 = lam(1) = (6 + sqrt 20)/16 the root of 16 x^2 - 12 x + 1 = 0 (exact)."""

    __slots__ = ("a", "b")

    def __init__(self, a, b=0):
        self.a, self.b = fmpq(a), fmpq(b)

    @staticmethod
    def lift(z):
        return z if isinstance(z, QL0) else QL0(z)

    def __add__(self, o):
        o = QL0.lift(o)
        return QL0(self.a + o.a, self.b + o.b)

    __radd__ = __add__

    def __neg__(self):
        return QL0(-self.a, -self.b)

    def __sub__(self, o):
        return self + (-QL0.lift(o))

    def __mul__(self, o):
        o = QL0.lift(o)
        bb = self.b * o.b  # L0^2 = (12 L0 - 1)/16
        return QL0(self.a * o.a - bb / 16, self.a * o.b + self.b * o.a + bb * fmpq(12, 16))

    __rmul__ = __mul__

    def inv(self):
        # (a + b L0)(a + b L0') = a^2 + a b (L0 + L0') + b^2 L0 L0' = a^2 + 3 a b/4 + b^2/16, L0' = 3/4 - L0
        n = self.a * self.a + self.a * self.b * fmpq(3, 4) + self.b * self.b / 16
        return QL0((self.a + self.b * fmpq(3, 4)) / n, -self.b / n)

    def __truediv__(self, o):
        return self * QL0.lift(o).inv()

    def __eq__(self, o):
        o = QL0.lift(o)
        return self.a == o.a and self.b == o.b

    def is_zero(self):
        return self.a == 0 and self.b == 0


def exact_zeros():
    """Check exactly (in Q(L0)) the facts the dropped coefficients rest on: L0 is an eigenvalue of B(1) with
    eigenvector rho (rho(1,0) = 1) and rho(a, b) = rho(b, a); adj(L0 - B(1)) kappa = N(L0) is a multiple of rho
    (so U(L0) = U(1,0) rho and alpha(0) U(L0) = -cos(sigma) rho). Returns rho (6 QL0)."""
    L = QL0(0, 1)
    A = [[(L if i == k else QL0(0)) - _B1[i, k] for k in range(6)] for i in range(6)]
    # rho: solve A rho = 0 with rho(1,0) = 1: drop row 0 (rank 5 since L0 is simple: checked by the solve)
    M = [[A[i][k] for k in range(1, 6)] + [-A[i][0]] for i in range(1, 6)]
    for c in range(5):  # Gauss-Jordan over Q(L0)
        piv = next(r for r in range(c, 5) if not M[r][c].is_zero())
        M[c], M[piv] = M[piv], M[c]
        inv = M[c][c].inv()
        M[c] = [z * inv for z in M[c]]
        for r in range(5):
            if r != c and not M[r][c].is_zero():
                f = M[r][c]
                M[r] = [z - f * w for z, w in zip(M[r], M[c])]
    rho = [QL0(1)] + [M[r][5] for r in range(5)]
    if not all(sum((A[i][k] * rho[k] for k in range(6)), QL0(0)).is_zero() for i in range(6)):
        raise AssertionError("rho is no eigenvector of B(1) for L0")
    pos = {p: k for p, k in _POS.items()}
    if not all(rho[pos[(a, b)]] == rho[pos[(b, a)]] for (a, b) in pos if b > 0 and (b, a) in pos):
        raise AssertionError("rho is not symmetric in (a, b)")
    N = [sum((c * L0pow for c, L0pow in zip(p, _powers(L, len(p)))), QL0(0)) for p in _NPOLY]
    if not all((N[k] - N[0] * rho[k]).is_zero() for k in range(6)) or N[0].is_zero():
        raise AssertionError("adj(L0 - B(1)) kappa is not a non-zero multiple of rho")
    return rho


def _powers(x, n):
    out, acc = [], QL0(1)
    for _ in range(n):
        out.append(acc)
        acc = acc * x
    return out
