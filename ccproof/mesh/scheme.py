"""The subdivision schemes as values (OpenSubdiv's ``Sdc::SchemeType`` and its rule tables).

A :class:`Scheme` owns the rules of one scheme: its name, how a face splits (``"quad"``: every face
into quads at its face point; ``"triangle"``: every triangle into four at its edge midpoints), the
regular face size and valences, and the weight functions. Every weight function takes the number
``one`` (as :mod:`ccproof.rule_weights` does): an exact 1 (``flint.fmpq``, ``fractions.Fraction``),
1.0 (floats, also numpy arrays of valences) or ``flint.arb(1)`` (balls; the precision of the
current ``flint.ctx``).

* :data:`CATMARK`: Catmull-Clark, the functions of :mod:`ccproof.rule_weights` unchanged.
* :data:`LOOP`: Loop's rules as OpenSubdiv's Sdc writes them: smooth edge point
  ``3/8 (a + b) + 1/8 (c + d)`` (a, b its ends, c, d the opposite vertices of its two triangles),
  smooth vertex point ``(1 - k beta) V + beta sum e_j`` with Loop's
  ``beta = (5/8 - (3/8 + cos(2 pi / k) / 4)^2) / k``, crease vertex ``3/4 V + 1/8 (e0 + e1)``, sharp edge
  midpoint, corners fixed; limit position ``(1 - k eps) V + eps sum e_j`` with
  ``eps = 1 / (k + 3 / (8 beta))``, crease limit ``(e0 + 4 V + e1) / 6``.

``beta`` lies in Q(cos(2 pi / k)): it is rational for k = 3, 4, 6 (3/16, 31/256, 1/16), and exact
arithmetic (``Fraction``, ``fmpq``) raises ValueError for any other valence; use balls (``flint.arb``)
there.

Semi-sharp creases decay as in Sdc's uniform creasing: an edge of sharpness ``s`` uses the sharp
rule while ``s >= 1``, the blend ``(1 - s) smooth + s sharp`` for ``0 < s < 1``
(:meth:`Scheme.blend`), and its children carry ``max(s - 1, 0)`` (:meth:`Scheme.child_sharpness`).

Examples
--------
>>> from fractions import Fraction
>>> LOOP.name, LOOP.split, LOOP.regular_face_size, LOOP.regular_valence, LOOP.regular_boundary_valence
('loop', 'triangle', 3, 6, 4)
>>> LOOP.vertex_point(6, Fraction(1)), LOOP.limit(6, Fraction(1))
((Fraction(5, 8), Fraction(1, 16)), (Fraction(1, 2), Fraction(1, 12)))
>>> CATMARK.name, CATMARK.regular_valence, CATMARK.limit(4, Fraction(1))
('catmark', 4, (Fraction(4, 9), Fraction(1, 9), Fraction(1, 36)))
>>> scheme_named("butterfly")
Traceback (most recent call last):
...
ValueError: unknown subdivision scheme 'butterfly' (one of: catmark, loop)
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from fractions import Fraction
from typing import Any

from ccproof import rule_weights as rw

__all__ = ["Scheme", "CATMARK", "LOOP", "SCHEMES", "scheme_named", "loop_beta", "loop_edge_weights",
           "loop_vertex_weights", "loop_limit_weights", "loop_tangent_masks", "catmark_tangent_masks",
           "cos_2pi"]

#: the fractions q of a turn whose cos(2 pi q) is rational (exact arithmetic works there)
_RATIONAL_COS = {Fraction(0): (1, 1), Fraction(1, 6): (1, 2), Fraction(1, 4): (0, 1), Fraction(1, 3): (-1, 2),
                 Fraction(1, 2): (-1, 1), Fraction(2, 3): (-1, 2), Fraction(3, 4): (0, 1), Fraction(5, 6): (1, 2)}


def cos_2pi(j, k, one):
    """``cos(2 pi j / k)`` in the arithmetic of ``one``.

    Examples
    --------
    >>> from fractions import Fraction
    >>> cos_2pi(1, 3, Fraction(1)), round(cos_2pi(1, 5, 1.0), 12)
    (Fraction(-1, 2), 0.309016994375)
    >>> cos_2pi(1, 5, Fraction(1))
    Traceback (most recent call last):
    ...
    ValueError: cos(2 pi * 1/5) is irrational: exact weights exist for valences 3, 4 and 6 only (use flint.arb)
    """
    if hasattr(one, "cos_pi"):  # flint.arb
        return (one * 2 * j / k).cos_pi()
    if type(one).__module__ == "numpy" or type(k).__module__ == "numpy" or type(j).__module__ == "numpy":
        import numpy as np

        return one * np.cos(2 * np.pi * j / k)
    if isinstance(one, float):
        return one * math.cos(2 * math.pi * j / k)
    q = Fraction(j % k, k) if isinstance(k, int) and isinstance(j, int) else None
    if q in _RATIONAL_COS:
        num, den = _RATIONAL_COS[q]
        return one * num / den
    raise ValueError(f"cos(2 pi * {j}/{k}) is irrational: exact weights exist for valences 3, 4 and 6 only "
                     "(use flint.arb)")


def loop_beta(k, one):
    """Loop's ``beta = (5/8 - (3/8 + cos(2 pi / k) / 4)^2) / k``, the weight of each neighbour.

    Examples
    --------
    >>> from fractions import Fraction
    >>> [str(loop_beta(k, Fraction(1))) for k in (3, 4, 6)]
    ['3/16', '31/256', '1/16']
    """
    c = one * 3 / 8 + cos_2pi(1, k, one) / 4
    return (one * 5 / 8 - c * c) / k


def loop_edge_weights(one):
    """Smooth Loop edge point: (weight of each end, of each opposite vertex) = (3/8, 1/8).

    >>> loop_edge_weights(1.0)
    (0.375, 0.125)
    """
    return one * 3 / 8, one / 8


def loop_vertex_weights(k, one):
    """Smooth Loop vertex point ``(1 - k beta) V + beta sum e_j``: (weight of V, of each neighbour).

    Examples
    --------
    The weights sum to 1 (k = 5 in balls):

    >>> import flint
    >>> wV, we = loop_vertex_weights(5, flint.arb(1))
    >>> (wV + 5 * we - 1).contains(0), [str(w) for w in loop_vertex_weights(3, Fraction(1))]
    (True, ['7/16', '3/16'])
    """
    b = loop_beta(k, one)
    return one - k * b, b


def loop_limit_weights(k, one):
    """Limit position of a smooth Loop vertex: ``(1 - k eps) V + eps sum e_j``, ``eps = 1/(k + 3/(8 beta))``.

    Examples
    --------
    The left eigenvector of eigenvalue 1 of the vertex and edge rules: at k = 5 the limit of the
    vertex point equals the limit of the vertex (the rules' one-ring of the star), checked in floats:

    >>> k, (wV, we), (lV, le) = 5, loop_vertex_weights(5, 1.0), loop_limit_weights(5, 1.0)
    >>> ev, ee = loop_edge_weights(1.0)
    >>> # the limit mask applied to the subdivided star: on V, then on each neighbour
    >>> abs(lV * wV + k * le * ev - lV) < 1e-15, abs(lV * we + le * (ev + 2 * ee) - le) < 1e-15
    (True, True)
    """
    b = loop_beta(k, one)
    eps = one / (k + 3 / (8 * b))
    return one - k * eps, eps


def loop_tangent_masks(k, one):
    """Two limit tangent masks of a smooth Loop vertex on its k neighbours (the vertex weighs 0):
    ``cos(2 pi j / k)`` and ``sin(2 pi j / k)`` (Sdc's; up to scale: directions of the tangent plane).

    Returns (list of k numbers, list of k numbers); the sine as ``cos(2 pi (j - k/4) / k)`` needs
    ``4 j - k`` over ``4 k``: balls and floats for any k, exact numbers where rational.

    >>> t1, t2 = loop_tangent_masks(6, 1.0)
    >>> [round(x, 12) for x in t1], [round(x, 12) for x in t2][:2]
    ([1.0, 0.5, -0.5, -1.0, -0.5, 0.5], [0.0, 0.866025403784])
    """
    c = [cos_2pi(j, k, one) for j in range(k)]
    s = [cos_2pi(4 * j - k, 4 * k, one) for j in range(k)]
    return c, s


def catmark_tangent_masks(k, one):
    """Halstead-Kass-DeRose tangent masks of a smooth Catmull-Clark vertex of valence k (vertex weight 0):
    on edge neighbour j ``A_k cos(2 pi j / k)``, on diagonal j ``cos(2 pi j / k) + cos(2 pi (j+1) / k)``
    (``A_k = 1 + cos(2 pi / k) + cos(pi / k) sqrt(2 (9 + cos(2 pi / k)))``), and the same rotated by a
    quarter turn; floats or balls.

    >>> e, d = catmark_tangent_masks(4, 1.0)[0]
    >>> [round(x, 12) for x in e], [round(x, 12) for x in d]
    ([4.0, 0.0, -4.0, -0.0], [1.0, -1.0, -1.0, 1.0])
    """
    c1, ch = cos_2pi(1, k, one), cos_2pi(1, 2 * k, one)
    A = one + c1 + ch * (2 * (9 + c1)) ** (one / 2) if hasattr(one, "cos_pi") else \
        one + c1 + ch * math.sqrt(2 * (9 + c1))
    out = []
    for shift in (0, k):  # the second: cos(2 pi (j - k/4) / k), written over 4k
        e = [A * cos_2pi(4 * j - shift, 4 * k, one) for j in range(k)]
        d = [cos_2pi(4 * j - shift, 4 * k, one) + cos_2pi(4 * (j + 1) - shift, 4 * k, one) for j in range(k)]
        out.append((e, d))
    return out


def _corner_weights(one):
    """Corner vertex (and limit): the vertex itself."""
    return (one,)


def _blend(smooth, sharp, s):
    """Sdc's fractional rule: ``(1 - s) smooth + s sharp`` for sharpness ``0 < s < 1``."""
    return [(1 - s) * a + s * b for a, b in zip(smooth, sharp)]


def _uniform_decay(s):
    """Sdc's uniform creasing: sharpness one level down."""
    return max(s - 1, 0)


@dataclass(frozen=True)
class Scheme:
    """One subdivision scheme's rules (OpenSubdiv's ``Sdc::Scheme<SCHEME_...>``).

    Attributes
    ----------
    name : str
    split : {"quad", "triangle"}
    regular_face_size, regular_valence, regular_boundary_valence : int
        Edges of a regular face; edges at a regular interior and boundary vertex.
    edge_point : callable(one)
        Smooth edge point: Catmull-Clark (each end, each adjacent face point); Loop (each end, each
        opposite vertex).
    sharp_edge : callable(one)
        Weight of each end of a sharp edge (the midpoint).
    vertex_point : callable(k, one)
        Smooth vertex point: Catmull-Clark (V, each edge neighbour, each face point); Loop (V, each
        neighbour).
    crease_vertex, corner_vertex : callable(one)
    face_point : callable(n, one) or None
        Catmull-Clark's centroid weight; None for Loop (no face points).
    limit, crease_limit : callable
        Limit position masks: ``limit(k, one)`` (Catmull-Clark: V, e_j, d_j; Loop: V, e_j),
        ``crease_limit(one)`` (V, each crease neighbour).
    tangent_masks : callable(k, one)
        Two limit tangent masks of a smooth vertex (directions, up to scale).
    """

    name: str
    split: str
    regular_face_size: int
    regular_valence: int
    regular_boundary_valence: int
    edge_point: Callable[..., Any]
    sharp_edge: Callable[..., Any]
    vertex_point: Callable[..., Any]
    crease_vertex: Callable[..., Any]
    corner_vertex: Callable[..., Any]
    face_point: Callable[..., Any] | None
    limit: Callable[..., Any]
    crease_limit: Callable[..., Any]
    tangent_masks: Callable[..., Any]

    def blend(self, smooth, sharp, s):
        """Weights of a semi-sharp rule of sharpness ``0 < s < 1`` (Sdc): ``(1 - s) smooth + s sharp``.

        >>> LOOP.blend([0.375, 0.125], [0.5, 0.0], 0.5)
        [0.4375, 0.0625]
        """
        return _blend(smooth, sharp, s)

    def child_sharpness(self, s):
        """Sharpness of the children of an edge or vertex of sharpness ``s`` (Sdc's uniform decay; infinite
        stays infinite).

        >>> LOOP.child_sharpness(2.5), LOOP.child_sharpness(0.5), LOOP.child_sharpness(float("inf"))
        (1.5, 0, inf)
        """
        return _uniform_decay(s)

    def is_regular(self, valence, boundary=False):
        """Whether a smooth vertex of this valence (edges at it) is regular.

        >>> LOOP.is_regular(6), LOOP.is_regular(4, boundary=True), CATMARK.is_regular(5)
        (True, True, False)
        """
        return valence == (self.regular_boundary_valence if boundary else self.regular_valence)


CATMARK = Scheme(
    name="catmark", split="quad", regular_face_size=4, regular_valence=4, regular_boundary_valence=3,
    edge_point=rw.smooth_edge_weights, sharp_edge=rw.sharp_edge_weight, vertex_point=rw.smooth_vertex_weights,
    crease_vertex=rw.crease_vertex_weights, corner_vertex=_corner_weights, face_point=rw.face_point_weight,
    limit=rw.smooth_limit_weights, crease_limit=rw.crease_limit_weights, tangent_masks=catmark_tangent_masks,
)

LOOP = Scheme(
    name="loop", split="triangle", regular_face_size=3, regular_valence=6, regular_boundary_valence=4,
    edge_point=loop_edge_weights, sharp_edge=rw.sharp_edge_weight, vertex_point=loop_vertex_weights,
    crease_vertex=rw.crease_vertex_weights, corner_vertex=_corner_weights, face_point=None,
    limit=loop_limit_weights, crease_limit=rw.crease_limit_weights, tangent_masks=loop_tangent_masks,
)

#: the schemes by name
SCHEMES = {s.name: s for s in (CATMARK, LOOP)}


def scheme_named(name):
    """The :class:`Scheme` called ``name`` (``"catmark"`` or ``"loop"``), or ValueError naming the choices."""
    try:
        return SCHEMES[name]
    except KeyError:
        raise ValueError(f"unknown subdivision scheme {name!r} (one of: {', '.join(SCHEMES)})") from None
