"""Sylvester resultants (bmz04 Definition 5): the matrix and its determinant over any commutative ring, and
the implicit equation of a boundary edge over Q when c and lam are rational (:func:`rational_implicit`, with the
*actual* degrees of x(w) and y(w): the formal-degree resultant vanishes identically for k = 4).
"""

from __future__ import annotations

from fractions import Fraction
from functools import lru_cache

from ccproof.errors import CCProofError
from ccproof.inverse.data import bezier_to_power
from ccproof.inverse.edges import get_edge

__all__ = ["sylvester_matrix", "determinant", "rational_nets", "rational_implicit", "RATIONAL_PAIRS"]


def sylvester_matrix(q, r, zero):
    """The (m+n) x (m+n) Sylvester matrix of Definition 5 (bmz04) of q = q0 + ... + qm x^m and
    r = r0 + ... + rn x^n given as coefficient lists (constant term first): n rows of q's
    coefficients ``q0 .. qm`` shifted right one column per row, then m rows of r's.

    Parameters
    ----------
    q, r : sequence
        Coefficient lists, constant term first, of degrees m and n (any commutative ring).
    zero : scalar
        The zero of that ring.

    Returns
    -------
    list of lists, shape (m + n, m + n)

    Examples
    --------
    >>> sylvester_matrix([1, 2], [3, 4, 5], 0)
    [[1, 2, 0], [0, 1, 2], [3, 4, 5]]
    """
    m, n = len(q) - 1, len(r) - 1
    size = m + n
    S = [[zero for _ in range(size)] for _ in range(size)]
    for i in range(n):
        for j, a in enumerate(q):
            S[i][i + j] = a
    for i in range(m):
        for j, a in enumerate(r):
            S[n + i][i + j] = a
    return S


def determinant(M, zero, one):
    """Exact determinant of a square matrix over a commutative ring (no division): Laplace
    expansion along the rows with the minors memoized by their set of columns (2^n of them).

    Parameters
    ----------
    M : sequence of sequences, shape (n, n)
        Entries in a commutative ring (ints, Fractions, flint polynomials, ...).
    zero, one : scalar
        The ring's 0 and 1.

    Returns
    -------
    scalar

    Examples
    --------
    >>> determinant([[1, 2], [3, 4]], 0, 1)
    -2
    """
    n = len(M)
    memo = {}

    def minor(row, cols):
        if row == n:
            return one
        key = cols
        if key in memo:
            return memo[key]
        acc = zero
        for idx, col in enumerate(cols):
            a = M[row][col]
            if a == 0:
                continue
            term = a * minor(row + 1, cols[:idx] + cols[idx + 1:])
            acc = acc + term if idx % 2 == 0 else acc - term
        memo[key] = acc
        return acc

    return minor(0, tuple(range(n)))


def rational_nets(c, lam):
    """Bezier nets of P1, P2, P3 with c and lam rational (``Fraction``): exact, ``Fraction``s.

    Valid for any rational pair with 16 lam^2 - 2 (5 + c) lam + 1 = 0: k = 4 (c = 0, lam = 1/2)
    and the *rational pseudo-valences* of :data:`RATIONAL_PAIRS` used to test the algebra exactly
    (bmz04 section 4.3; docs/readings.md R3).

    Parameters
    ----------
    c, lam : Fraction or int

    Returns
    -------
    dict
        ``{"P1": net, "P2": net, "P3": net}``, ``net[i][j] = (x, y)`` Fractions, i, j = 0..3.

    Raises
    ------
    CCProofError
        If lam is not a root for c.

    Examples
    --------
    >>> rational_nets(0, Fraction(1, 2))["P2"][3][3]            # k = 4: the identity map
    (Fraction(1, 1), Fraction(1, 1))
    """
    c, lam = Fraction(c), Fraction(lam)
    if 16 * lam * lam - 2 * (5 + c) * lam + 1 != 0:
        raise CCProofError(f"lam = {lam} is not a root of 16 L^2 - 2 (5 + c) L + 1 for c = {c}")
    return _rational_nets(c, lam)


@lru_cache(maxsize=32)
def _rational_nets(c, lam):
    from ccproof.algebra.characteristic_map import symbolic_bezier_nets
    from ccproof.algebra.field import eval_integer_form

    return {name: [[tuple(eval_integer_form(x.integer_form(), c, lam) for x in p) for p in row]
                   for row in net]
            for name, net in symbolic_bezier_nets().items()}


def _rational_pair(m):
    a = Fraction(8) / (m * m - 1)
    c = a - 1
    return c, (5 + c + a * m) / 16


#: rational (c, lam) pairs with 16 lam^2 - 2(5+c) lam + 1 = 0 and c in (-1, 1): (1+c)(9+c) is a
#: square for 1 + c = 8/(m^2 - 1). m = 3 is k = 4; the others are "pseudo-valences" near k = 3
#: (c = -7/15), 6 (c = 11/21) and 8 (c = 81/119) on which every identity can be tested over Q.
RATIONAL_PAIRS = tuple(_rational_pair(Fraction(m)) for m in (4, 3, Fraction(5, 2), Fraction(12, 5)))


def _trim(coeffs):
    coeffs = list(coeffs)
    while len(coeffs) > 1 and coeffs[-1] == 0:
        coeffs.pop()
    return coeffs


def rational_implicit(edge, c, lam):
    """g(u, v) for rational (c, lam) as ``{(a, b): Fraction}``: the Sylvester determinant of
    Definition 5 over Q with the actual degrees of x(w) - u and y(w) - v (no formal leading
    zeros; for k = 4, whose boundaries are straight lines, this is what gives a non-zero g).

    Parameters
    ----------
    edge : str or Edge
        A boundary edge (:data:`EDGES`).
    c, lam : Fraction or int
        A rational pair with 16 lam^2 - 2 (5 + c) lam + 1 = 0 (:func:`rational_nets`).

    Returns
    -------
    dict of tuple -> Fraction
        ``{(a, b): g_ab}``.

    Examples
    --------
    >>> rational_implicit("P1:t=1", 0, Fraction(1, 2))   # k = 4: the line v = 1/2, as 1/2 - v
    {(0, 0): Fraction(1, 2), (0, 1): Fraction(-1, 1)}
    """
    from flint import fmpq, fmpq_mpoly_ctx

    e = get_edge(edge)
    pts = e.control_points(rational_nets(c, lam)[e.patch])
    Q = fmpq_mpoly_ctx.get(("u", "v"), "lex")
    u, v = Q.gens()

    def conv(x):
        return Q.constant(fmpq(x.numerator, x.denominator))

    q = [conv(a) for a in _trim(bezier_to_power([p[0] for p in pts]))]
    r = [conv(a) for a in _trim(bezier_to_power([p[1] for p in pts]))]
    q[0] = q[0] - u
    r[0] = r[0] - v
    g = determinant(sylvester_matrix(q, r, Q.constant(0)), Q.constant(0), Q.constant(1))
    return {tuple(int(x) for x in ab): Fraction(int(x.p), int(x.q)) for ab, x in sorted(g.to_dict().items())}

