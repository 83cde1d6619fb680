"""The Catmull-Clark rules on the k-regular complex (bmz04 Fig. 1, docs/readings.md R1), the verifier's only
source of the scheme (trusted): face, edge and vertex points; sector j is the quadrant of grid positions
(a, b), a, b >= 0, the centre (0, 0) of valence k (docs/appendix_a.md section 9.2).

>>> level1_rule(2, 0)[(1, 0)], centre_rule_mode0(fmpq(1, 5))[(0, 0)]   # 1 - 7/(4n) at n = 4 and n = k = 5
(9/16, 13/20)
"""

from flint import fmpq

TWO_RING = ((1, 0), (2, 0), (1, 1), (2, 1), (1, 2), (2, 2))
CENTRE = (0, 0)


def canonical(a, b):
    """``(delta, a', b')``: the position (a, b) of a sector is (a', b') of the sector delta steps on (a' >= 1,
    b' >= 0, or the centre (0, 0, 0)).

    >>> canonical(2, 1), canonical(0, 2), canonical(-1, 0), canonical(1, -1)
    ((0, 2, 1), (1, 2, 0), (2, 1, 0), (-1, 1, 1))
    """
    if (a, b) == CENTRE:
        return (0, 0, 0)
    for delta, a2, b2 in ((0, a, b), (1, b, -a), (-1, -b, a), (2, -a, -b)):  # (a, b) in the frame of sector delta
        if a2 >= 1 and b2 >= 0 and (delta < 2 or b2 == 0):  # two sectors on (delta 2): the ray only
            return delta, a2, b2
    raise ValueError(f"grid position ({a}, {b}) is more than one sector away")


def _mix(*terms):
    """The combination sum of weight * comb over (comb, weight) terms."""
    acc = {}
    for comb, w in terms:
        for p, x in comb.items():
            acc[p] = acc.get(p, 0) + w * x
    return acc


def face_point(a, b):
    """New face point of the face with lower corner (a, b): {raw position: weight}, the corners' mean.

    >>> face_point(0, 0)
    {(0, 0): 1/4, (0, 1): 1/4, (1, 0): 1/4, (1, 1): 1/4}
    """
    return {(a + i, b + j): fmpq(1, 4) for i in (0, 1) for j in (0, 1)}


def level1_rule(A, B):
    """The level-1 vertex at sector-local (A, B) != (0, 0) (both odd: a face point, one odd: an edge point,
    else a vertex point of valence 4) on raw level-0 positions.

    >>> r = level1_rule(2, 0)    # 1 - 7/(4n), 3/(2n^2), 1/(4n^2) at n = 4
    >>> r[(1, 0)], r[(2, 0)], r[(2, 1)], sum(r.values())
    (9/16, 3/32, 1/64, 1)
    """
    if (A, B) == CENTRE:
        raise ValueError("the centre has valence k: use centre_rule")
    q, half = fmpq(1, 4), fmpq(1, 2)
    if A % 2 and B % 2:
        return face_point((A - 1) // 2, (B - 1) // 2)
    if A % 2 or B % 2:  # edge (a, b)-(a + da, b + db); faces (a, b) and (a - db, b - da)
        a, b, da, db = ((A - 1) // 2, B // 2, 1, 0) if A % 2 else (A // 2, (B - 1) // 2, 0, 1)
        return _mix(({(a, b): 1}, q), ({(a + da, b + db): 1}, q), (face_point(a, b), q),
                    (face_point(a - db, b - da), q))
    a, b = A // 2, B // 2  # vertex point, n = 4: V' = (F + 2R + V)/4
    return _mix(({(a, b): 1}, q), *((face_point(fa, fb), q / 4) for fa, fb in ((a, b), (a - 1, b), (a, b - 1),
                                                                               (a - 1, b - 1))),
                *(({(a, b): half, e: half}, q / 2) for e in ((a + 1, b), (a - 1, b), (a, b + 1), (a, b - 1))))


def centre_rule_mode0(t):
    """The new centre in Fourier mode 0 (every sector alike), t = 1/k: V' = t (F + 2R) + (1 - 3t) V on sector 0's
    positions ((0, 1) is the next sector's (1, 0)).

    >>> centre_rule_mode0(fmpq(1, 5))     # 1 - 7/(4k), 3/(2k) = 1/4 + 1/20, 1/(4k) at k = 5
    {(0, 0): 13/20, (0, 1): 1/20, (1, 0): 1/4, (1, 1): 1/20}
    """
    return _mix(({CENTRE: 1}, 1 - 3 * t), (face_point(0, 0), t), ({CENTRE: fmpq(1, 2), (1, 0): fmpq(1, 2)}, 2 * t))


class Vec(tuple):
    """A vector with ``+`` and ``* weight`` entrywise (points of F^2, rows of a Fourier block).

    >>> Vec((1, 2)) + Vec((3, 4)) * 2
    (7, 10)
    """

    def __add__(self, other):
        return Vec(a + b for a, b in zip(self, other))

    def __mul__(self, w):
        return Vec(a * w for a in self)


def apply(comb, lookup, zero):
    """Sum of weight * lookup(delta, (a', b')) over a combination of raw positions (the centre: ``(0, (0, 0))``).

    >>> x = lambda d, p: [p[0], -p[1], -p[0], p[1]][d % 4]    # k = 4: x after d quarter turns
    >>> apply(face_point(0, 0), x, 0), apply(face_point(-1, 0), x, 0)
    (1/2, -1/2)
    """
    acc = zero
    for (a, b), w in comb.items():
        delta, a2, b2 = canonical(a, b)
        acc = acc + lookup(delta, (a2, b2)) * w
    return acc


def level1_value(A, B, lookup, zero):
    """``(delta, value)``: the level-1 value at sector-local (A, B) != centre, in the frame of its sector delta.

    >>> x = lambda d, p: [p[0], -p[1], -p[0], p[1]][d % 4]    # k = 4: x = A/2 in its own sector
    >>> level1_value(2, 3, x, 0), level1_value(-1, 2, x, 0)
    ((0, 1), (1, 1))
    """
    delta, A2, B2 = canonical(A, B)
    return delta, apply(level1_rule(A2, B2), lookup, zero)
