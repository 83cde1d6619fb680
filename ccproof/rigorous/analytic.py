"""Functions analytic in one complex parameter h on a disc: Taylor coefficients and a Cauchy remainder (the bound:
docs/rigorous.md, "Analytic models"); nothing here is specific to one quantity."""

from functools import reduce

from flint import acb, acb_mat, arb, fmpq


def ball(lo, hi):
    """The arb ball [lo, hi] of two exact endpoints.

    >>> ball(0, 1).contains(0), ball(0, 1).contains(1), ball(0, 1).contains(fmpq(11, 10))
    (True, True, False)
    """
    lo, hi = fmpq(lo), fmpq(hi)
    return arb((lo + hi) / 2, (hi - lo) / 2)


def _near(a, grid):
    """grid/2 times the distance from 0 of the a-th of ``grid`` equal intervals of [-1, 1] (an integer)."""
    lo, hi = 2 * a - grid, 2 * a + 2 - grid
    return 0 if lo <= 0 <= hi else min(abs(lo), abs(hi))


def disc_boxes(r, grid):
    """The acb boxes of the grid x grid grid on [-r, r]^2 that meet the closed disc |h| <= r (exact test).

    >>> len(list(disc_boxes(fmpq(1, 2), 3))), len(list(disc_boxes(fmpq(1, 2), 4))), len(list(disc_boxes(1, 12)))
    (9, 16, 132)
    """
    r = fmpq(r)
    edges = [-r + 2 * r * fmpq(a, grid) for a in range(grid + 1)]
    for a in range(grid):
        for b in range(grid):
            if _near(a, grid) ** 2 + _near(b, grid) ** 2 <= grid ** 2:
                yield acb(ball(edges[a], edges[a + 1]), ball(edges[b], edges[b + 1]))


def disc_bound(values, r, grid):
    """{key: M}, |z| <= M for every entry z of ``values(h)[key]`` (acb) and every h of the disc |h| <= r, over the
    boxes of :func:`disc_boxes`; ZeroDivisionError where a box gives no finite bound (or ``values`` raises it).

    >>> M = disc_bound(lambda h: {"exp": [h.exp()]}, fmpq(1, 2), 4)
    >>> bool(M["exp"] > arb(fmpq(1, 2)).exp()), bool(M["exp"] < 2)
    (True, True)
    """
    M = {}
    for i, h in enumerate(disc_boxes(r, grid)):
        for key, zs in values(h).items():
            bound = max((abs(acb(z)).upper() for z in zs), key=lambda x: x)
            if not bound.is_finite():
                raise ZeroDivisionError(f"disc box {i} ({h}), {key}: no bound")
            M[key] = bound if key not in M or bound > M[key] else M[key]
    return M


def cauchy_factor(r, n, h_hi):
    """1 / (r^(n+1) (1 - h_hi/r)): the remainder of order n is at most M h^(n+1) times this for 0 <= h <= h_hi < r.

    >>> cauchy_factor(fmpq(1, 2), 0, fmpq(1, 4)).contains(4)
    True
    """
    r, h_hi = fmpq(r), fmpq(h_hi)
    if not (0 <= h_hi < r):
        raise ZeroDivisionError(f"h up to {h_hi} is not inside the Cauchy disc of radius {r}")
    return 1 / (arb(r) ** (n + 1) * (1 - arb(h_hi / r)))


class AnalyticModel:
    """f(h) = sum_(m <= n) C_m h^m + the Cauchy remainder: C_m acb matrices of one shape, |column k| <= M[k] on the
    disc |h| <= r.

    e^h to order 8 on [0, 1/8], |e^h| <= e^(1/2) on |h| <= 1/2 (the coefficient of h^0 dropped):

    >>> coeffs = [acb_mat([[arb(1) / arb.fac_ui(m)]]) for m in range(9)]
    >>> model = AnalyticModel(coeffs, [arb(fmpq(1, 2)).exp()], fmpq(1, 2))
    >>> V, rho = model.enclose(fmpq(1, 8), fmpq(1, 8), low=1)
    >>> bool((V[0, 0].real + arb(0, rho[0].upper())).contains((arb(fmpq(1, 8)).exp() - 1) * 8))
    True
    """

    def __init__(self, coeffs, M, r):
        self.coeffs, self.M, self.r = coeffs, M, fmpq(r)
        self.order = len(coeffs) - 1

    @classmethod
    def from_columns(cls, columns, M, r):
        """The model whose column k has the Taylor coefficients ``columns[k][m]`` (the rows, per order m).

        >>> AnalyticModel.from_columns([[[1, 2], [3, 4]]], [arb(5)], fmpq(1, 2)).coeffs[1][1, 0]
        4.00000000000000
        """
        return cls([acb_mat([[acb(col[m][row]) for col in columns] for row in range(len(columns[0][m]))])
                    for m in range(len(columns[0]))], M, r)

    def enclose(self, h_lo, h_hi, low=0):
        """(V, rho): f(h)/h^low lies in V[c, k] plus a complex ball of radius rho[k] for every h in [h_lo, h_hi]
        (the coefficients below h^low dropped: the caller knows them to be 0)."""
        h = acb(ball(h_lo, h_hi))
        acc = self.coeffs[-1]
        for C in reversed(self.coeffs[low:-1]):
            acc = acc * h + C
        tail = arb(fmpq(h_hi)) ** (self.order + 1 - low) * cauchy_factor(self.r, self.order, h_hi)
        return acc, [m * tail for m in self.M]

    def real_part(self, weights, h_lo, h_hi, low=0):
        """Re sum_k weights[k] f_k(h)/h^low per row (arb), every h in [h_lo, h_hi]: |Re w e| <= (|Re w| + |Im w|) rho
        for |e| <= rho."""
        V, rho = self.enclose(h_lo, h_hi, low)
        ws = [acb(w) for w in weights]
        vals = V * acb_mat([[w] for w in ws])
        rad = sum(((abs(w.real) + abs(w.imag)) * t for w, t in zip(ws, rho)), arb(0)).upper()
        return [vals[c, 0].real + arb(0, rad) for c in range(vals.nrows())]


def hull(balls):
    """The arb ball holding every ball of a non-empty iterable.

    >>> hull([arb(1), arb(3), arb(2)]).contains(ball(1, 3))
    True
    """
    return reduce(arb.union, balls)


__all__ = ["AnalyticModel", "ball", "cauchy_factor", "disc_bound", "disc_boxes", "hull"]
