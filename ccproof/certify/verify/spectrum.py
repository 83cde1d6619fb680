"""The spectrum of the Catmull-Clark subdivision matrix re-derived from the rules (trusted): the Fourier blocks
B(w) (one stencil, shared by the smooth, tagged and dart routes) and B0(1/k), their characteristic polynomials
(exact) and the spectral ordering (arb). docs/appendix_a.md section 9.3; docs/readings.md R2."""

from functools import cache
from math import prod

from flint import arb, ctx, fmpq, fmpq_mat

from .rules import CENTRE, TWO_RING, Vec, apply, canonical, centre_rule_mode0, level1_rule
from .statement import lam_of

RING_INDEX = {p: i for i, p in enumerate(TWO_RING)}  # ring position -> its index in a mode vector v^ (and B(w))
SMALL_ROOTS = (fmpq(1, 8), fmpq(1, 16), fmpq(1, 32), fmpq(1, 64))


@cache
def ring_stencil():
    """For each ring point of sector 0 (:data:`.rules.TWO_RING`) its rule on the ring points {(delta, position):
    weight}, the centre dropped.

    >>> row = ring_stencil()[0]    # the ray's edge point: 3/8 on (1, 0), 1/16 on far corners; the centre's 3/8 dropped
    >>> row[(0, (1, 0))], row[(-1, (1, 0))], row[(-1, (1, 1))], sum(row.values())
    (3/8, 1/16, 1/16, 5/8)
    """
    out = []
    for pos in TWO_RING:
        row = {}
        for raw, w in level1_rule(*pos).items():
            d, a, b = canonical(*raw)
            if (a, b) != CENTRE:
                row[(d, (a, b))] = row.get((d, (a, b)), 0) + w
        out.append({k: w for k, w in row.items() if w != 0})
    return tuple(out)


def ring_block(w):
    """B(w): (B v^)(p) = sum of the stencil weights times w^delta (w a number: fmpq, arb or acb).

    >>> ring_block(fmpq(1))[0]    # mode 0: the ray's edge point, 3/8 + 2/16 on (1, 0), 2/16 on (1, 1)
    [1/2, 0, 1/8, 0, 0, 0]
    """
    rows = [[0 * w] * 6 for _ in range(6)]
    for i, row in enumerate(ring_stencil()):
        for (d, pos), x in row.items():
            rows[i][RING_INDEX[pos]] += x * w ** d
    return rows


def _block0(t):
    """B0(t) (7 x 7, centre first) as fmpq rows: every sector alike, the centre's rule for t = 1/k."""
    pos = (CENTRE,) + TWO_RING

    def lookup(delta, p):  # the row vector of the value at (delta, p) in the unknowns
        return Vec(fmpq(int(p == q)) for q in pos)
    return [list(apply(centre_rule_mode0(t) if p == CENTRE else level1_rule(*p), lookup, Vec([fmpq(0)] * 7)))
            for p in pos]


def _identity_holds(block, claimed, params, xs):
    """det(x - block(s)) == claimed(x, s) (x - 1/8)..(x - 1/64) at every exact grid point (s in params, x in xs)."""
    for s in map(fmpq, params):
        rows = block(s)
        n = len(rows)
        if not all(fmpq_mat(n, n, [(x if i == j else 0) - rows[i][j] for i in range(n) for j in range(n)]).det()
                   == claimed(x, s) * prod(x - r for r in SMALL_ROOTS) for x in map(fmpq, xs)):
            return False
    return True


def mode_polynomials_hold(block):
    """det(x - B(w)) = (x - 1/8)..(x - 1/64)(x^2 - (5 + c) x/8 + 1/16), c = (w + 1/w)/2, for the rows ``block(w)``,
    on the grid w = 1..19, x = 0..6 (w^6 det has degree <= 18 in w, 6 in x).

    >>> mode_polynomials_hold(ring_block), mode_polynomials_hold(lambda w: ring_block(w * w))
    (True, False)
    """
    return _identity_holds(block, lambda x, w: x * x - (5 + (w + 1 / w) / 2) * x / 8 + fmpq(1, 16), range(1, 20),
                           range(7))


def check_block_polynomials():
    """Both identities: :func:`mode_polynomials_hold` of B(w), and det(x - B0(t)) = (x - 1)(x - 1/8)..(x - 1/64)
    (x^2 - (12 - 28 t) x/16 + (1 - 3t)/16) on t = 1..8, x = 0..7 (degree <= 7 in each).

    >>> check_block_polynomials()
    True
    """
    return mode_polynomials_hold(ring_block) and _identity_holds(
        _block0, lambda x, t: (x - 1) * (x * x - (12 - 28 * t) * x / 16 + (1 - 3 * t) / 16), range(1, 9), range(8))


def spectral_ordering(k, prec):
    """(ok, message): 1 = lam_0 > lam_1 = lam_2 = lam(k) > |lam_3|, lam double and non-defective, for the valence k
    or every k >= k0 (``{"min": k0}``), given :func:`check_block_polynomials` (arb at ``prec`` bits).

    >>> spectral_ordering(5, 64)[0], spectral_ordering({"min": 20}, 64)[0]
    (True, True)
    """
    with ctx.workprec(prec):
        every, k0 = isinstance(k, dict), k["min"] if isinstance(k, dict) else k
        c1 = arb(fmpq(2, k0)).cos_pi()
        lam = lam_of(c1).union(lam_of(arb(1))) if every else lam_of(c1)  # every k >= k0: lam increases with c
        # p0(lam) > 0; for every k >= k0: 1 - c_1 <= 2 pi^2/k^2, so 28 lam - 3 > 4 pi^2 lam / k0 suffices
        mode0 = 28 * lam - 3 > 4 * arb.pi() ** 2 * lam / k0 if every else 28 * lam - 3 - 2 * k * (1 - c1) * lam > 0
        label = f"every k >= {k0}" if every else f"k = {k}"
        checks = [
            (lam < 1, "lam < 1 (1 is the dominant eigenvalue, simple in mode 0)"),
            (lam > fmpq(1, 4), "lam > 1/4 >= the smaller roots and > 1/8"),
            ((1 + c1) * (9 + c1) > 0, "lam simple in modes 1 and k-1 (discriminant > 0)"),
            (mode0 and lam > fmpq(3, 8), "lam above both mode-0 roots (p0(lam) > 0, lam > 3/8)"),
        ]
        if not every and k >= 4:
            checks.append((lam > lam_of(arb(fmpq(4, k)).cos_pi()), "lam > lam(c_2) (modes 2..k-2)"))
        bad = next((what for ok, what in checks if not ok), None)
        return (False, f"{label}: {bad} fails") if bad else (True, f"{label}: " + "; ".join(w for _, w in checks))
