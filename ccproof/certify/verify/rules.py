"""The Catmull-Clark rules on the k-regular complex, written out for the verifier (trusted).

The verifier re-derives everything from these three rules (bmz04 Fig. 1, docs/readings.md R1) and
nothing else: face point = mean of the face's corners; edge point = mean of the edge's two ends and
the two new face points beside it; vertex point V' = (F + 2R + (n - 3) V)/n with F the mean of the new
face points and R the mean of the edge midpoints around V, n its valence.

Positions. Sector j of the k-regular complex is the quadrant of grid positions (a, b), a, b >= 0,
spanned by the edges e_j (along a) and e_(j+1) (along b); the centre (0, 0) is the extraordinary
vertex; every other vertex has valence 4. A position given in sector j's coordinates that lies in a
neighbouring sector is canonicalized to (delta, a', b'): position (a', b') of sector j + delta::

        b
        ^   sector j+1 | sector j
        |   (a <= 0)   | (a >= 1, b >= 0)
        +--------------C---------> a      (a, 0), a < 0: on e_(j+2)
            sector j-1: b <= -1 (a >= 0)

The two-ring of sector 0 is :data:`TWO_RING` (6 positions); a symmetric (Fourier-mode) vector is
given by its sector-0 values and ``value(j, p) = rot^j value(0, p)``.
"""

from __future__ import annotations

from flint import fmpq

TWO_RING = ((1, 0), (2, 0), (1, 1), (2, 1), (1, 2), (2, 2))
CENTRE = (0, 0)


def canonical(a, b):
    """``(delta, a', b')``: the position (a, b) of some sector is (a', b') of the sector delta steps on.

    Parameters
    ----------
    a, b : int
        Grid position in a sector's coordinates (the figure of the module docstring).

    Returns
    -------
    (int, int, int)
        ``(0, 0, 0)`` for the centre; ``a' >= 1, b' >= 0`` otherwise.

    Examples
    --------
    >>> canonical(2, 1), canonical(0, 2), canonical(-1, 0), canonical(1, -1)
    ((0, 2, 1), (1, 2, 0), (2, 1, 0), (-1, 1, 1))
    """
    if a == 0 and b == 0:
        return (0, 0, 0)
    if a >= 1 and b >= 0:
        return (0, a, b)
    if a <= 0 and b >= 1:
        return (1, b, -a)
    if a >= 0 and b <= -1:
        return (-1, -b, a)
    if b == 0 and a < 0:
        return (2, -a, 0)
    raise ValueError(f"grid position ({a}, {b}) is more than one sector away")


def _add(acc, comb, w):
    for p, x in comb.items():
        acc[p] = acc.get(p, 0) + w * x
    return acc


def face_point(a, b):
    """New face point of the level-0 face with lower corner (a, b): {raw position: weight}.

    Returns
    -------
    dict[(int, int), fmpq]
        The mean of the four corners (bmz04 Fig. 1, docs/readings.md R1).

    Examples
    --------
    >>> face_point(0, 0)
    {(0, 0): 1/4, (0, 1): 1/4, (1, 0): 1/4, (1, 1): 1/4}
    """
    return {(a + i, b + j): fmpq(1, 4) for i in (0, 1) for j in (0, 1)}


def level1_rule(A, B):
    """The level-1 vertex at sector-local level-1 position (A, B) != (0, 0) as a combination of level-0
    positions (raw, sector-local), derived from the three rules (the vertex is not the centre, so
    a vertex point has n = 4).

    Parameters
    ----------
    A, B : int
        Level-1 position: both odd a face point, one odd an edge point, both even a vertex point.

    Returns
    -------
    dict[(int, int), fmpq]
        Weights summing to 1.

    Examples
    --------
    The vertex point of (1, 0) (valence 4): 9/16 on it, 3/32 on edge and 1/64 on diagonal neighbours
    (bmz04 Fig. 1 at n = 4: ``1 - 7/(4n)``, ``3/(2n^2)``, ``1/(4n^2)``):

    >>> r = level1_rule(2, 0)
    >>> r[(1, 0)], r[(2, 0)], r[(2, 1)], sum(r.values())
    (9/16, 3/32, 1/64, 1)
    """
    if (A, B) == CENTRE:
        raise ValueError("the centre has valence k: use centre_rule")
    half = fmpq(1, 2)
    if A % 2 and B % 2:
        return face_point((A - 1) // 2, (B - 1) // 2)
    if A % 2 or B % 2:
        if A % 2:  # edge (a, b)-(a+1, b); faces (a, b) and (a, b-1)
            a, b = (A - 1) // 2, B // 2
            ends, faces = ((a, b), (a + 1, b)), ((a, b), (a, b - 1))
        else:  # edge (a, b)-(a, b+1); faces (a, b) and (a-1, b)
            a, b = A // 2, (B - 1) // 2
            ends, faces = ((a, b), (a, b + 1)), ((a, b), (a - 1, b))
        acc = {}
        for e in ends:
            _add(acc, {e: 1}, fmpq(1, 4))
        for f in faces:
            _add(acc, face_point(*f), fmpq(1, 4))
        return acc
    a, b = A // 2, B // 2  # vertex point, n = 4: V' = (F + 2R + V)/4
    acc = {(a, b): fmpq(1, 4)}
    for fa, fb in ((a, b), (a - 1, b), (a, b - 1), (a - 1, b - 1)):
        _add(acc, face_point(fa, fb), fmpq(1, 16))  # F/4 = (mean of 4 face points)/4
    for e in ((a + 1, b), (a - 1, b), (a, b + 1), (a, b - 1)):
        _add(acc, {(a, b): half, e: half}, fmpq(2, 16))  # 2R/4 = 2 (mean of 4 midpoints)/4
    return acc


def centre_rule_mode0(t):
    """The new centre in Fourier mode 0 (every sector equal) for t = 1/k: V' = t (F + 2R) + (1 - 3t) V,
    with F = the face point of the sector-0 face (0, 0) and R = (V + value(1, 0))/2 (all sectors alike).

    Parameters
    ----------
    t : fmpq
        1/k.

    Returns
    -------
    dict[(int, int), fmpq]
        Sector-0 weights; (0, 1) is the (1, 0) of the next sector.

    Examples
    --------
    k = 5: ``1 - 7/(4k) = 13/20`` on the centre, ``3/(2k) = 1/4 + 1/20`` on the edge and ``1/(4k)`` on the
    diagonal neighbours of all sectors together:

    >>> centre_rule_mode0(fmpq(1, 5))
    {(0, 0): 13/20, (0, 1): 1/20, (1, 0): 1/4, (1, 1): 1/20}
    """
    acc = {CENTRE: 1 - 3 * t}
    _add(acc, face_point(0, 0), t)
    _add(acc, {CENTRE: fmpq(1, 2), (1, 0): fmpq(1, 2)}, 2 * t)
    return acc


class Vec(tuple):
    """A vector with ``+`` and ``* weight`` entrywise, what :func:`apply` needs of its values (points of F^2,
    rows of a Fourier block).

    >>> Vec((1, 2)) + Vec((3, 4)) * 2
    (7, 10)
    """

    def __add__(self, other):
        return Vec(a + b for a, b in zip(self, other))

    def __mul__(self, w):
        return Vec(a * w for a in self)


def apply(comb, lookup, zero):
    """Sum of weight * lookup(delta, (a', b')) over a combination of raw positions; the centre is
    ``lookup(0, (0, 0))``.

    Parameters
    ----------
    lookup : callable (delta, (a', b')) -> value
        The value at position (a', b') of the sector delta steps on.

    Examples
    --------
    On the regular grid (k = 4), with x(delta, (a, b)) the x coordinate after ``delta`` quarter turns:

    >>> x = lambda d, p: [p[0], -p[1], -p[0], p[1]][d % 4]
    >>> apply(face_point(0, 0), x, 0), apply(face_point(-1, 0), x, 0)
    (1/2, -1/2)
    """
    acc = zero
    for (a, b), w in comb.items():
        delta, a2, b2 = canonical(a, b)
        acc = acc + lookup(delta, (a2, b2)) * w
    return acc


def level1_value(A, B, lookup, zero):
    """The level-1 value at any sector-local level-1 position (A, B) != centre, rotated into place:
    canonicalize to (delta, A', B'), apply the rule in sector delta.

    Returns
    -------
    (int, value)
        ``delta`` and the value in sector delta's frame.

    Examples
    --------
    Subdivision of the regular grid halves it: level-1 position (A, B) has x = A/2 in its own sector:

    >>> x = lambda d, p: [p[0], -p[1], -p[0], p[1]][d % 4]
    >>> level1_value(2, 3, x, 0), level1_value(-1, 2, x, 0)
    ((0, 1), (1, 1))
    """
    delta, A2, B2 = canonical(A, B)
    return delta, apply(level1_rule(A2, B2), lookup, zero)
