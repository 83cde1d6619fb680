"""The spectrum of the Catmull-Clark subdivision matrix, re-derived from the rules (trusted).

The (6k + 1) x (6k + 1) matrix S on the two-ring of the k-regular complex commutes with the rotation
of the sectors, so the discrete Fourier transform splits it into blocks: for a k-th root of unity
w = exp(2 pi i m/k), m != 0, the 6 x 6 block B(w) acting on the sector-0 values of vectors with
value(j, p) = w^j value(0, p) (the centre is then 0), and for m = 0 a 7 x 7 block B0(t), t = 1/k, that
includes the centre. The spectrum of S is the union of the blocks' spectra. The blocks are built
here from :mod:`.rules`, and their characteristic polynomials are checked exactly:

  det(x - B(w))  = (x - 1/8)(x - 1/16)(x - 1/32)(x - 1/64) (x^2 - (5 + c) x/8 + 1/16),  c = (w + 1/w)/2,
  det(x - B0(t)) = (x - 1)(x - 1/8)(x - 1/16)(x - 1/32)(x - 1/64) (x^2 - (12 - 28 t) x/16 + (1 - 3t)/16).

Each is an identity of polynomials (after multiplying by w^6, entries of w B(w) have degree <= 3 in w;
B0 is affine in t), so it holds as soon as both sides agree on a grid of (deg_x + 1) x (deg_w + 1)
rational points, which :func:`check_block_polynomials` evaluates with exact determinants. B(w) is
:func:`ring_block`, built from one stencil (:func:`ring_stencil`: the rule of each two-ring point on the
two-ring of its own and the neighbouring sectors); the tagged sectors' modes (:mod:`.tagged_modes`) and
the dart family use the same block.

Consequences (every k >= 3; :func:`spectral_ordering` checks the numbers in arb): mode m != 0 has the
eigenvalues 1/8..1/64 and the roots of 16 x^2 - 2(5 + c_m) x + 1, c_m = cos(2 pi m/k); the larger root
lam(c) = (5 + c + sqrt((1 + c)(9 + c)))/16 increases with c and c_1 = c_(k-1) > c_m for 2 <= m <= k - 2,
so lam = lam(c_1) is the largest of the modes m != 0, a simple root in each of the modes 1 and k - 1
(discriminant 4(1 + c_1)(9 + c_1) > 0), hence a double, non-defective eigenvalue of S; the smaller roots
are 1/(16 lam(c_m)) <= 1/4. Mode 0 has 1 (simple), 1/8..1/64 and the roots of
p0(x) = 16k x^2 - (12k - 28) x + k - 3, both real and >= 0; with 16 lam^2 = 2(5 + c) lam - 1,
p0(lam) = 28 lam - 3 - 2k(1 - c) lam, so lam exceeds both roots iff p0(lam) > 0 and lam > 3/8 (> the
vertex (12k - 28)/(32k)).
"""

from __future__ import annotations

from functools import cache

from flint import arb, ctx, fmpq, fmpq_mat

from .rules import CENTRE, TWO_RING, Vec, apply, canonical, centre_rule_mode0, level1_rule
from .statement import lam_of

RING_INDEX = {p: i for i, p in enumerate(TWO_RING)}  # ring position -> its index in a mode vector v^ (and B(w))


@cache
def ring_stencil():
    """The rule of each ring point (sector 0) on the ring points, the centre dropped.

    Returns
    -------
    tuple of dict[(int, (int, int)), fmpq]
        For each position of :data:`.rules.TWO_RING`: ``{(delta, position): weight}``.

    Examples
    --------
    The edge point of a ray (level-1 (1, 0)): 3/8 on its end (1, 0), 1/16 on the far corners of the two
    faces beside it; the centre's 3/8 is dropped:

    >>> row = ring_stencil()[0]
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
    """B(w) (module docstring): (B v^)(p) = sum of the stencil weights times w^delta (w a number, fmpq or acb).

    Examples
    --------
    Mode 0 (every sector alike): the ray's edge point is 3/8 + 2/16 on (1, 0), 2/16 on (1, 1):

    >>> ring_block(fmpq(1))[0]
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


def _charpoly_at(rows, x):
    n = len(rows)
    return fmpq_mat(n, n, [(x if i == j else 0) - rows[i][j] for i in range(n) for j in range(n)]).det()


SMALL_ROOTS = (fmpq(1, 8), fmpq(1, 16), fmpq(1, 32), fmpq(1, 64))


def _claimed_mode(x, c):
    out = x * x - (5 + c) * x / 8 + fmpq(1, 16)
    for r in SMALL_ROOTS:
        out *= x - r
    return out


def _claimed_mode0(x, t):
    out = (x - 1) * (x * x - (12 - 28 * t) * x / 16 + (1 - 3 * t) / 16)
    for r in SMALL_ROOTS:
        out *= x - r
    return out


def mode_polynomials_hold(block):
    """True iff det(x - B(w)) = (x - 1/8)(x - 1/16)(x - 1/32)(x - 1/64)(x^2 - (5 + c) x/8 + 1/16) for the
    6 x 6 rows ``block(w)`` (module docstring): w^6 det(x - B(w)) has degree <= 18 in w and 6 in x, so
    the grid w = 1..19, x = 0..6 of exact determinants decides the identity.

    Examples
    --------
    >>> mode_polynomials_hold(ring_block), mode_polynomials_hold(lambda w: ring_block(w * w))
    (True, False)
    """
    for w in range(1, 20):
        rows = block(fmpq(w))
        c = (fmpq(w) + 1 / fmpq(w)) / 2
        for x in range(7):
            if _charpoly_at(rows, fmpq(x)) != _claimed_mode(fmpq(x), c):
                return False
    return True


def check_block_polynomials():
    """True iff both characteristic-polynomial identities of the module docstring hold (exact grid).

    Returns
    -------
    bool
        Checked at enough exact points to identify the polynomials (docs/readings.md R2).

    Examples
    --------
    >>> check_block_polynomials()
    True
    """
    if not mode_polynomials_hold(ring_block):
        return False
    for t in range(1, 9):  # degree <= 7 in t and in x
        rows = _block0(fmpq(t))
        for x in range(8):
            if _charpoly_at(rows, fmpq(x)) != _claimed_mode0(fmpq(x), fmpq(t)):
                return False
    return True


def spectral_ordering(k, prec):
    """(ok, message): 1 = lam_0 > lam_1 = lam_2 = lam(k) > |lam_3|, lam double and non-defective, for the
    valence k (an int) or every k >= k0 (``{"min": k0}``); assumes :func:`check_block_polynomials`.

    Parameters
    ----------
    prec : int
        Bits of the arb comparisons.

    Returns
    -------
    (bool, str)
        Reif's spectral hypotheses (docs/readings.md R2; bmz04 section 2).

    Examples
    --------
    >>> spectral_ordering(5, 64)[0], spectral_ordering({"min": 20}, 64)[0]
    (True, True)
    """
    with ctx.workprec(prec):
        if isinstance(k, dict):
            k0 = k["min"]
            c_lo = arb(fmpq(2, k0)).cos_pi()
            lam_lo, lam_hi = lam_of(c_lo), lam_of(arb(1))
            lam = lam_lo.union(lam_hi)  # lam(k) for every k >= k0 (lam increases with c)
            # p0(lam) > 0 for every k >= k0: 1 - c_1 <= 2 pi^2/k^2, so 28 lam - 3 > 4 pi^2 lam / k0 suffices
            mode0 = 28 * lam - 3 > 4 * arb.pi() ** 2 * lam / k0
            label = f"every k >= {k0}"
            c1 = c_lo
        else:
            c1 = arb(fmpq(2, k)).cos_pi()
            lam = lam_of(c1)
            mode0 = 28 * lam - 3 - 2 * k * (1 - c1) * lam > 0
            label = f"k = {k}"
        checks = [
            (lam < 1, "lam < 1 (1 is the dominant eigenvalue, simple in mode 0)"),
            (lam > fmpq(1, 4), "lam > 1/4 >= the smaller roots and > 1/8"),
            ((1 + c1) * (9 + c1) > 0, "lam simple in modes 1 and k-1 (discriminant > 0)"),
            (mode0 and lam > fmpq(3, 8), "lam above both mode-0 roots (p0(lam) > 0, lam > 3/8)"),
        ]
        if not isinstance(k, dict) and k >= 4:
            checks.append((lam > lam_of(arb(fmpq(4, k)).cos_pi()), "lam > lam(c_2) (modes 2..k-2)"))
        for ok, what in checks:
            if not ok:
                return False, f"{label}: {what} fails"
        return True, f"{label}: " + "; ".join(w for _, w in checks)
