"""OpenSubdiv's Sdc crease rules (``sdc/crease.cpp``): what every scheme shares, and the rule table of the step.

Sharpness ``s`` is an IEEE float32 as in OpenSubdiv, ``s >= INFINITE`` (10) is infinite; the rule of a
vertex (:func:`rule_code`, :func:`vertex_rule` by name) follows from its sharpness and the number of sharp
edges at it; sharpness decays by one per level (:func:`decrement`), or by Chaikin's average around a vertex
(:func:`child_sharpness_at_vertex`).

The rule table, which rule applies where, is written once, on numbers and on numpy arrays alike, and read
by both the exact stencils (:func:`ccproof.mesh.rules.refine_complex`, one vertex at a time, rationals) and
the float operator (:func:`ccproof.mesh.step.catmark_operator`, every vertex at once): the vertex rule
(:func:`rule_code`), the mask it uses (:func:`mask_kind`), the blend of the parent's and the child's masks
(:func:`rule_blend`, generic over the number type), the edge rule (:func:`midpoint_weight`), the sharpness decay
(:func:`decrement`, :func:`chaikin_sharpness`) and which features count in Sdc's fractional weight
(:func:`becomes_smooth`). The weights
are the scheme's (:data:`ccproof.mesh.scheme.CATMARK`). What stays written twice is the assembly of the rows
(dicts of rationals per point there, integer-scaled numpy terms over the whole mesh here: a shared per-point
assembly is the former, about 12x slower: ``python scripts/bench_refine.py``) and the float32 sums of
Sdc's fractional weight and Chaikin's rule (in fan order, one vertex at a time or segmented);
tests/mesh/test_step.py checks those bit for bit, the OpenSubdiv comparisons check the shared table.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["INFINITE", "SMOOTH", "DART", "CREASE", "CORNER", "RULES", "decrement", "child_sharpness_at_vertex",
           "vertex_rule", "rule_code", "mask_kind", "rule_blend", "midpoint_weight", "chaikin_sharpness",
           "becomes_smooth"]

#: OpenSubdiv's Sdc::Crease::SHARPNESS_INFINITE: sharpness at or above it is infinite
INFINITE = 10.0

#: the vertex rules (Sdc ``Crease::Rule``)
SMOOTH, DART, CREASE, CORNER = "smooth", "dart", "crease", "corner"

#: the vertex rules by code (:func:`rule_code`): ``RULES[code]`` is its name
RULES = (SMOOTH, DART, CREASE, CORNER)

_F32 = np.float32
_ONE = _F32(1.0)


def _is_semi_sharp(s):
    return 0.0 < s < INFINITE


def decrement(s):
    """Sdc's uniform decay of float32 sharpness, on a number or a numpy array: ``s - 1`` in float32 above 1, 0 at
    or below, infinite (``>= INFINITE``) stays infinite.

    >>> decrement(2.5), decrement(0.5), decrement(10.0)
    (1.5, 0.0, inf)
    >>> decrement(np.array([2.5, 0.5, 12.0, -1.0, np.inf])).tolist()
    [1.5, 0.0, inf, 0.0, inf]
    """
    if not isinstance(s, np.ndarray):  # the same rule, without arrays (one vertex of the exact stencils)
        s = float(s)
        if s <= 0.0:
            return 0.0
        if s >= INFINITE:
            return math.inf
        return float(_F32(s) - _ONE) if s > 1.0 else 0.0
    s = np.asarray(s, dtype=np.float64)
    out = np.where(s > 1.0, (s.astype(_F32) - _ONE).astype(np.float64), 0.0)
    return np.where(s >= INFINITE, np.inf, out)


def child_sharpness_at_vertex(edge_sharpness, chaikin):
    """Sdc ``SubdivideEdgeSharpnessesAroundVertex``: child sharpness of every edge at one vertex.

    ``CREASE_UNIFORM`` (``chaikin`` False): each decays by one; ``CREASE_CHAIKIN``: with two or more
    semi-sharp edges, ``0.75 s + 0.25 mean(other semi-sharp) - 1`` in float32.

    >>> child_sharpness_at_vertex([2.0, 1.0, 0.0], False), child_sharpness_at_vertex([2.0, 1.0, 0.0], True)
    ([1.0, 0.0, 0.0], [0.75, 0.25, 0.0])
    """
    if not chaikin or len(edge_sharpness) < 2:
        return [decrement(s) for s in edge_sharpness]
    semi = [s for s in edge_sharpness if _is_semi_sharp(s)]
    if not semi:
        return list(edge_sharpness)
    total = _F32(0.0)
    for s in semi:
        total = _F32(total + _F32(s))
    out = []
    for s in edge_sharpness:
        if s <= 0.0:
            out.append(0.0)
        elif s >= INFINITE:
            out.append(math.inf)
        elif len(semi) == 1:
            out.append(decrement(s))
        else:
            out.append(chaikin_sharpness(s, total, len(semi)))
    return out


def chaikin_sharpness(s, total, n_semi):
    """Sdc's ``CREASE_CHAIKIN`` child sharpness of a semi-sharp edge ``s`` at a vertex with ``n_semi >= 2``
    semi-sharp edges whose float32 sharpness sums to ``total``: ``0.75 s + 0.25 mean(the others) - 1`` in float32,
    0 below; on numbers or numpy arrays (one vertex of the exact stencils, every incidence of the float step).

    >>> chaikin_sharpness(2.0, np.float32(3.0), 2), chaikin_sharpness(np.array([2.0, 1.0]), np.float32(3.0), 2).tolist()
    (0.75, [0.75, 0.25])
    """
    s32 = np.asarray(s).astype(_F32)
    avg = ((total - s32) / np.asarray(n_semi - 1).astype(_F32)).astype(_F32)
    c = (_F32(0.75) * s32 + _F32(0.25) * avg).astype(_F32) - _ONE
    out = np.where(c > 0, c.astype(np.float64), 0.0)
    return float(out) if out.ndim == 0 else out


def becomes_smooth(p, c, uniform):
    """Whether a feature of sharpness ``p`` (child sharpness ``c``) counts in Sdc's fractional weight
    (``ComputeFractionalWeightAtVertex``): ``0 < p <= 1`` under ``CREASE_UNIFORM`` edges, ``p > 0`` and ``c <= 0``
    otherwise (Chaikin edges, and the vertex's own sharpness under either); numbers or numpy arrays.

    >>> becomes_smooth(0.5, 0.0, True), becomes_smooth(1.5, 0.0, False), becomes_smooth(np.array([1.5]), 0.5, True)
    (True, True, array([False]))
    """
    return (p > 0.0) & ((p <= 1.0) if uniform else (c <= 0.0))


def rule_code(vertex_sharpness, n_sharp):
    """Sdc ``DetermineVertexVertexRule`` as a code (the index into :data:`RULES`), on numbers or numpy arrays.

    The rule table of the step, exact and float: a sharp vertex or three or more sharp edges: corner (3);
    two: crease (2); one: dart (1); none: smooth (0).

    Parameters
    ----------
    vertex_sharpness : float or ndarray
    n_sharp : int or ndarray of int
        The number of sharp edges at the vertex.

    Returns
    -------
    int or ndarray of int64
        The code (an int for a number and an int, the exact stencils' one vertex at a time), the codes.

    Examples
    --------
    >>> rule_code(np.array([0.0, 0.0, 0.0, 0.0, 2.0]), np.array([0, 1, 2, 5, 0])).tolist()
    [0, 1, 2, 3, 3]
    >>> rule_code(0.0, 2), rule_code(0.5, 2)
    (2, 3)
    """
    if not isinstance(n_sharp, np.ndarray) and not isinstance(vertex_sharpness, np.ndarray):  # the same rule
        return 3 if vertex_sharpness > 0.0 else min(int(n_sharp), 3)
    return np.where(np.asarray(vertex_sharpness) > 0.0, 3, np.minimum(n_sharp, 3)).astype(np.int64)


def mask_kind(code):
    """The mask a rule code uses: a dart uses the smooth mask (0 smooth, 2 crease, 3 corner).

    >>> mask_kind(np.arange(4)).tolist()
    [0, 0, 2, 3]
    """
    return code - (code == 1)


def rule_blend(parent, child, w, one):
    """Sdc's vertex point as ``cp * parent mask + cc * child mask``: the coefficients ``(cp, cc)``.

    Where the parent's mask is not smooth and the child's mask differs (:func:`mask_kind` of the rule codes
    ``parent``, ``child``), ``cp = w`` and ``cc = 1 - w`` with Sdc's fractional weight ``w``; elsewhere
    ``cp = 1``, ``cc = 0``. Generic over the number type of ``one`` and ``w``: exact rationals (one vertex of
    :func:`ccproof.mesh.rules.refine_complex`) or numpy float arrays (every vertex of
    :func:`ccproof.mesh.step.catmark_operator`; exact there too: ``w`` is a float32 in [0, 1]).

    Examples
    --------
    >>> from fractions import Fraction
    >>> rule_blend(3, 2, Fraction(1, 4), Fraction(1)), rule_blend(1, 0, Fraction(1, 4), Fraction(1))
    ((Fraction(1, 4), Fraction(3, 4)), (Fraction(1, 1), Fraction(0, 1)))
    >>> cp, cc = rule_blend(np.array([2, 2, 0]), np.array([0, 2, 0]), np.array([0.5, 0.5, 0.5]), 1.0)
    >>> cp.tolist(), cc.tolist()
    ([0.5, 1.0, 1.0], [0.5, 0.0, 0.0])
    """
    p, c = mask_kind(parent), mask_kind(child)
    b = ((p != 0) & (c != p)) * 1  # 0 or 1 (an int, or an int array)
    return one + b * (w - one), b * (one - w)


def midpoint_weight(s, halves_sharp):
    """Sdc's edge rule as the weight ``pw`` of the midpoint in ``pw * midpoint + (1 - pw) * smooth``, on numbers
    or numpy arrays (the rule table of the edge points, exact and float).

    Parameters
    ----------
    s : float or ndarray
        The edge's sharpness (a boundary edge: infinite).
    halves_sharp : bool or ndarray of bool
        Whether both child halves of the edge stay sharp (or it is a boundary edge).

    Returns
    -------
    float or ndarray of float64
        1 where ``s > 0`` and the halves stay sharp, ``s`` as a float32 where ``s > 0`` and they do not
        (semi-sharp), 0 where ``s <= 0`` (smooth).

    Examples
    --------
    >>> midpoint_weight(0.3, False), midpoint_weight(2.0, True), midpoint_weight(0.0, True)
    (0.30000001192092896, 1.0, 0.0)
    >>> midpoint_weight(np.array([0.3, 2.0, 0.0]), np.array([False, True, True])).tolist()
    [0.30000001192092896, 1.0, 0.0]
    """
    if not isinstance(s, np.ndarray):  # the same rule, without arrays (one edge of the exact stencils)
        s = float(s)
        return (1.0 if halves_sharp else float(_F32(s))) if s > 0.0 else 0.0
    s = np.asarray(s, dtype=np.float64)
    return np.where(s > 0, np.where(halves_sharp, 1.0, s.astype(_F32).astype(np.float64)), 0.0)


def vertex_rule(vertex_sharpness, edge_sharpness):
    """Sdc ``DetermineVertexVertexRule``: 'corner', 'crease', 'dart' or 'smooth' (:func:`rule_code`, by name).

    Parameters
    ----------
    vertex_sharpness : float
    edge_sharpness : sequence of float
        Sharpness of the edges at the vertex.

    Returns
    -------
    str
        A sharp vertex or three or more sharp edges: corner; two: crease; one: dart; none: smooth.

    Examples
    --------
    >>> import math
    >>> [vertex_rule(0.0, e) for e in ([0, 0, 0, 0], [math.inf, 0, 0, 0], [2, 0, 2, 0], [1, 1, 1, 0])]
    ['smooth', 'dart', 'crease', 'corner']
    >>> vertex_rule(1.0, [0, 0, 0, 0])
    'corner'
    """
    return RULES[rule_code(vertex_sharpness, sum(1 for s in edge_sharpness if s > 0.0))]
