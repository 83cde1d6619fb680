"""Exact Catmull-Clark subdivision of the k-regular complex (bmz04 section 3, Definition 2; R1).

Vertices of the k-regular complex R_k are addressed by *sector coordinates*: ``CENTER`` for the
extraordinary vertex, and ``(j, a, b)`` with ``j`` in Z/k, ``a >= 1``, ``b >= 0`` for the vertex at
grid position (a, b) of sector j. Sector j is the quarter-plane grid spanned by the edge directions
e_j (the a-axis) and e_{j+1} (the b-axis), so the point (0, b) of sector j is (b, 0) of sector j+1
and the point (a, -b) of sector j is (b, a) of sector j-1 (:func:`canonical`).

After one subdivision step the level-1 vertex at position (A, B) of a sector sits at the level-0
parameter (A/2, B/2); its parity tells the rule (R1): both even -> vertex point, one odd -> edge
point, both odd -> face point. Away from the centre every vertex has valence 4 and the rules are the
regular tensor-product stencils; the centre rule is V' = (F + 2R + (k-3)V)/k. Every weight is read
from the one rule implementation, :mod:`ccproof.rule_weights`, in exact ``Fraction`` arithmetic
(the face points expanded into the vertices of the ring).

The (6k+1) x (6k+1) matrix of Definition 2 acts on the two-ring ``{CENTER} + {(j, a, b): 1 <= a <= 2,
0 <= b <= 2}``; the (2k+8)-vertex ring of Stam 1998 (one face and its one-ring) is offered as well.
"""

from __future__ import annotations

from fractions import Fraction

from ccproof.errors import check_valence
from ccproof.rule_weights import face_point_weight, smooth_edge_weights, smooth_vertex_weights

_ONE = Fraction(1)

CENTER = "center"

#: level-0 positions of one sector in the two-ring of Definition 2 (6 per sector)
TWO_RING_POSITIONS = ((1, 0), (2, 0), (1, 1), (2, 1), (1, 2), (2, 2))


def canonical(a, b):
    """Canonical form of the grid position (a, b) given in the coordinates of some sector.

    The indexing of the k-regular complex of bmz04 Definition 2 (docs/readings.md R1).

    Parameters
    ----------
    a, b : int
        Grid position in the coordinates of a sector (sector 0 is the quadrant a >= 1, b >= 0).

    Returns
    -------
    tuple of int
        ``(delta, a', b')`` with ``a' >= 1, b' >= 0``: the same vertex as position (a', b') of
        the sector ``delta`` steps further (delta in {-1, 0, 1}, or 2 for the points (a, 0), a < 0, on
        the edge e_{j+2}), or ``(0, 0, 0)`` for the centre.

    Examples
    --------
    >>> canonical(0, 2)
    (1, 2, 0)
    >>> canonical(1, -1)
    (-1, 1, 1)
    >>> canonical(0, 0)
    (0, 0, 0)
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


def regular_stencil(A, B):
    """Level-0 stencil of the level-1 vertex at position (A, B) of a sector, (A, B) != (0, 0).

    Returns a list of ``(weight, (a, b))`` with Fraction weights and raw (not canonical) level-0
    positions in the same sector's coordinates. Valid wherever the level-0 vertices involved all
    have valence 4, which holds for every (A, B) != (0, 0) with A >= 0, B >= 0 except that the centre
    itself may appear as a *neighbour* (its valence does not enter the edge and face rules).
    """
    if A == 0 and B == 0:
        raise ValueError("the centre has its own rule (centre_stencil)")
    if A % 2 == 0 and B % 2 == 0:  # vertex point of a valence-4 vertex: 9/16, 3/32, 1/64
        a, b = A // 2, B // 2
        if a == 0 and b == 0:
            raise ValueError("centre")
        al, be, ga = _quad_vertex_weights(4)
        st = [(al, (a, b))]
        st += [(be, (a + da, b + db)) for da, db in ((1, 0), (-1, 0), (0, 1), (0, -1))]
        st += [(ga, (a + da, b + db)) for da, db in ((1, 1), (-1, 1), (1, -1), (-1, -1))]
        return st
    if A % 2 == 1 and B % 2 == 1:  # face point: mean of the 4 corners
        a, b = (A - 1) // 2, (B - 1) // 2
        wf = face_point_weight(4, _ONE)
        return [(wf, (a + da, b + db)) for da in (0, 1) for db in (0, 1)]
    end, wing = _quad_edge_weights()
    if A % 2 == 1:  # edge point of the edge (a, b)-(a+1, b): 3/8 ends, 1/16 wings
        a, b = (A - 1) // 2, B // 2
        st = [(end, (a, b)), (end, (a + 1, b))]
        st += [(wing, (a + da, b + db)) for da in (0, 1) for db in (1, -1)]
        return st
    a, b = A // 2, (B - 1) // 2  # edge point of the edge (a, b)-(a, b+1)
    st = [(end, (a, b)), (end, (a, b + 1))]
    st += [(wing, (a + da, b + db)) for db in (0, 1) for da in (1, -1)]
    return st


def _quad_vertex_weights(k):
    """The smooth vertex rule of :func:`ccproof.rule_weights.smooth_vertex_weights` at valence ``k``
    with its quad face points expanded (each is 1/4 of V, e_j, d_j, e_(j+1)): the weights on V, on
    each edge neighbour and on each diagonal neighbour."""
    wv, we, wf = smooth_vertex_weights(k, _ONE)
    q = face_point_weight(4, _ONE)
    return wv + k * wf * q, we + 2 * wf * q, wf * q


def _quad_edge_weights():
    """The smooth edge rule of :func:`ccproof.rule_weights.smooth_edge_weights` with its two quad face
    points expanded: the weight of each end and of each of the four wing vertices."""
    w_end, w_face = smooth_edge_weights(_ONE)
    q = face_point_weight(4, _ONE)
    return w_end + 2 * w_face * q, w_face * q


def centre_stencil(k):
    """Weights of the centre rule V' = (F + 2R + (k-3)V)/k (R1) as ``(alpha, beta, gamma)``.

    alpha on V, beta on each edge neighbour (1, 0) of every sector, gamma on each face neighbour
    (1, 1): alpha = 1 - 7/(4k), beta = 3/(2k^2), gamma = 1/(4k^2) (bmz04 Fig. 1; docs/readings.md R1).

    Parameters
    ----------
    k : int
        Valence, k >= 3.

    Returns
    -------
    tuple of Fraction
        ``(alpha, beta, gamma)``; alpha + k beta + k gamma = 1.

    Examples
    --------
    >>> centre_stencil(4)
    (Fraction(9, 16), Fraction(3, 32), Fraction(1, 64))
    >>> a, b, g = centre_stencil(7)
    >>> a + 7 * b + 7 * g
    Fraction(1, 1)
    """
    k = check_valence(k)
    return _quad_vertex_weights(k)


def level1_stencil(k, vertex):
    """Level-0 stencil of the level-1 vertex ``vertex`` (``CENTER`` or canonical ``(j, A, B)``).

    One row of the subdivision matrix: the Catmull-Clark rules of bmz04 Fig. 1 (docs/readings.md R1).

    Parameters
    ----------
    k : int
        Valence, k >= 3.
    vertex : str or tuple of int
        :data:`CENTER` or a canonical position ``(sector j, A, B)`` (:func:`canonical`).

    Returns
    -------
    list of tuple
        ``(weight, level-0 vertex)`` pairs, weights ``Fraction``, level-0 vertices in canonical form.

    Examples
    --------
    The edge point (0, 1, 0) of a regular vertex follows the edge rule 3/8, 3/8, 1/16 x 4:

    >>> sorted(str(w) for w, _ in level1_stencil(4, (0, 1, 0)))
    ['1/16', '1/16', '1/16', '1/16', '3/8', '3/8']
    """
    k = check_valence(k)
    if vertex == CENTER:
        al, be, ga = centre_stencil(k)
        st = [(al, CENTER)]
        for j in range(k):
            st += [(be, (j, 1, 0)), (ga, (j, 1, 1))]
        return st
    j, A, B = vertex
    out = {}
    for w, (a, b) in regular_stencil(A, B):
        d, a2, b2 = canonical(a, b)
        key = CENTER if (a2, b2) == (0, 0) else ((j + d) % k, a2, b2)
        out[key] = out.get(key, 0) + w
    return [(w, v) for v, w in out.items()]


def two_ring_vertices(k):
    """The 6k+1 vertices of the two-ring N_2 of Definition 2.

    In the order used by :func:`ring_subdivision_matrix`: the centre, then sector by sector the
    positions :data:`TWO_RING_POSITIONS` (bmz04 Definition 2; docs/readings.md R1).

    Parameters
    ----------
    k : int
        Valence, k >= 3.

    Returns
    -------
    list
        ``[CENTER, (0, 1, 0), (0, 2, 0), ...]``, length 6k + 1.

    Examples
    --------
    >>> v = two_ring_vertices(3)
    >>> len(v), v[:3], v[-1]
    (19, ['center', (0, 1, 0), (0, 2, 0)], (2, 2, 2))
    """
    k = check_valence(k)
    return [CENTER] + [(j, a, b) for j in range(k) for (a, b) in TWO_RING_POSITIONS]


def stam_vertices(k):
    """The 2k+8 vertices of Stam's ring of the face of sector 0.

    The centre, (j, 1, 0) and (j, 1, 1) for every sector j, then the 7 outer vertices of the face's 4x4
    net, in the order (2,-1), (2,0), (2,1), (2,2), (1,2), (0,2), (-1,2) of sector-0 grid positions
    (canonicalized); docs/readings.md R12 (Stam's natural parameterization).

    Parameters
    ----------
    k : int
        Valence, k >= 3.

    Returns
    -------
    list
        Length 2k + 8.

    Examples
    --------
    >>> v = stam_vertices(3)
    >>> len(v), v[-1]
    (14, (1, 2, 1))
    """
    k = check_valence(k)
    verts = [CENTER]
    for j in range(k):
        verts += [(j, 1, 0), (j, 1, 1)]
    for a, b in ((2, -1), (2, 0), (2, 1), (2, 2), (1, 2), (0, 2), (-1, 2)):
        d, a2, b2 = canonical(a, b)
        verts.append((d % k, a2, b2))
    return verts


def ring_subdivision_matrix(k, ring="two_ring"):
    """Exact Catmull-Clark subdivision matrix S of the k-regular complex (bmz04 Definition 2).

    Parameters
    ----------
    k : int
        Valence of the extraordinary vertex, k >= 3.
    ring : {"two_ring", "stam"}
        ``"two_ring"``: the (6k+1) x (6k+1) matrix on :func:`two_ring_vertices`;
        ``"stam"``: the (2k+8) x (2k+8) matrix on :func:`stam_vertices`.

    Returns
    -------
    S : list of list of Fraction, shape (n, n)
        ``p1 = S @ p0`` maps level-0 values on the ring to level-1 values on the ring.

    >>> S = ring_subdivision_matrix(4)
    >>> len(S), sum(S[0])
    (25, Fraction(1, 1))
    """
    k = check_valence(k)
    if ring == "two_ring":
        verts = two_ring_vertices(k)
    elif ring == "stam":
        verts = stam_vertices(k)
    else:
        raise ValueError(f"unknown ring {ring!r}; use 'two_ring' or 'stam'")
    index = {v: i for i, v in enumerate(verts)}
    n = len(verts)
    S = [[Fraction(0)] * n for _ in range(n)]
    for i, v in enumerate(verts):
        for w, src in level1_stencil(k, v):
            if src not in index:
                raise AssertionError(f"stencil of {v} leaves the ring at {src}")
            S[i][index[src]] += w
    return S


def subdivision_matrix_fmpq(k, ring="two_ring"):
    """:func:`ring_subdivision_matrix` as a ``flint.fmpq_mat`` (exact).

    Parameters
    ----------
    k : int
        Valence, k >= 3.
    ring : {"two_ring", "stam"}, optional
        The ring of :func:`ring_subdivision_matrix`.

    Returns
    -------
    flint.fmpq_mat, shape (6k+1, 6k+1) or (2k+8, 2k+8)

    Examples
    --------
    >>> S = subdivision_matrix_fmpq(4)
    >>> S.nrows(), S[0, 0]
    (25, 9/16)
    """
    from flint import fmpq, fmpq_mat

    S = ring_subdivision_matrix(k, ring)
    return fmpq_mat([[fmpq(x.numerator, x.denominator) for x in row] for row in S])


#: former name, kept importable for ccproof/apps/dynamics/elements.py; the package-wide
#: ``subdivision_matrix`` is :func:`ccproof.mesh.subdivision_matrix` (of a mesh, sparse float)
subdivision_matrix = ring_subdivision_matrix
