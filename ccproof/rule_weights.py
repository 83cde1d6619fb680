"""The weights of the Catmull-Clark rules and limit masks, written once for every number type.

Each function takes the number ``one`` and returns its weights in that arithmetic: an exact 1
(``flint.fmpq`` for the evaluator's exact local steps, ``fractions.Fraction`` for the proof branch's
ring matrices), 1.0 (floats, also with integer numpy arrays of face sizes and valences: the vectorized
reference step) or ``flint.arb(1)`` (balls). Everything that subdivides reads its weights from here:
the Sdc stencils of :mod:`ccproof.mesh.rules` (creases, corners, n-gons), the vectorized step of
:mod:`ccproof.mesh.subdivision`, the ring matrices of :mod:`ccproof.algebra.subdivision` (from which
the certified tables are built), the limit masks of :mod:`ccproof.mesh.masks`, the certified closest
points and the applications. The trusted verifier keeps its own copy on purpose
(docs/trusted_base.md).

Rules (bmz04 Fig. 1, docs/readings.md R1; OpenSubdiv's Sdc ``CATMARK`` rules, docs/evaluate.md):

* face point: the centroid;
* edge point: smooth ``(a + b + f0 + f1) / 4``, sharp the midpoint;
* vertex point: smooth ``((k - 2) V + sum e_j / k + sum f_j / k) / k``, crease
  ``(3/4) V + (1/8)(e0 + e1)``, corner ``V``;
* limit position: smooth ``(k^2 V + 4 sum e_j + sum d_j) / (k (k + 5))``, crease
  ``(e0 + 4 V + e1) / 6``.

This module imports nothing (it sits below both branches).
"""

from __future__ import annotations

__all__ = ["face_point_weight", "smooth_edge_weights", "sharp_edge_weight", "smooth_vertex_weights",
           "crease_vertex_weights", "smooth_limit_weights", "crease_limit_weights"]


def face_point_weight(n, one):
    """Face point: the centroid; the weight of each of the ``n`` vertices of the face.

    Parameters
    ----------
    n : int or ndarray of int
        Face size(s).
    one : number
        An exact 1 (``flint.fmpq``, ``Fraction``, sympy) or 1.0 (float).

    Returns
    -------
    number or ndarray
        ``one / n`` (bmz04 Fig. 1, docs/readings.md R1).

    Examples
    --------
    >>> from fractions import Fraction
    >>> face_point_weight(4, Fraction(1)), face_point_weight(3, 1.0) * 3
    (Fraction(1, 4), 1.0)
    """
    return one / n


def smooth_edge_weights(one):
    """Smooth edge point ``(a + b + f0 + f1) / 4``: (weight of each end, of each adjacent face point).

    Parameters
    ----------
    one : number
        An exact 1 (``flint.fmpq``, ``Fraction``, sympy) or 1.0 (float).

    Returns
    -------
    tuple of 2 numbers
        bmz04 Fig. 1 (docs/readings.md R1).

    Examples
    --------
    >>> from fractions import Fraction
    >>> smooth_edge_weights(Fraction(1))
    (Fraction(1, 4), Fraction(1, 4))
    """
    return one / 4, one / 4


def sharp_edge_weight(one):
    """Sharp (crease or boundary) edge point: the midpoint; the weight of each end.

    Parameters
    ----------
    one : number
        An exact 1 (``flint.fmpq``, ``Fraction``, sympy) or 1.0 (float).

    Returns
    -------
    number
        OpenSubdiv's Sdc crease rule (docs/evaluate.md "Tagged polygon meshes").

    Examples
    --------
    >>> from fractions import Fraction
    >>> sharp_edge_weight(Fraction(1)), sharp_edge_weight(1.0)
    (Fraction(1, 2), 0.5)
    """
    return one / 2


def smooth_vertex_weights(k, one):
    """Smooth (and dart) vertex point ``((k - 2) V + sum e_j / k + sum f_j / k) / k`` at valence ``k``.

    Parameters
    ----------
    k : int or ndarray of int
        Valence(s).
    one : number
        An exact 1 (``flint.fmpq``, ``Fraction``, sympy) or 1.0 (float).

    Returns
    -------
    tuple of 3 numbers
        (weight of V, of each edge neighbour e_j, of each adjacent face point f_j); for quads
        bmz04 Fig. 1 (docs/readings.md R1): ``1 - 7/(4k)`` on V, ``3/(2k^2)`` and ``1/(4k^2)`` on the
        edge and diagonal neighbours.

    Examples
    --------
    With the face points of quads expanded (each carries 1/4 of its vertices), k = 5 gives
    ``1 - 7/20``, ``3/50`` and ``1/100``:

    >>> from fractions import Fraction
    >>> wV, we, wf = smooth_vertex_weights(5, Fraction(1))
    >>> [str(w) for w in (wV + 5 * wf / 4, we + 2 * wf / 4, wf / 4)]
    ['13/20', '3/50', '1/100']
    """
    return one * (k - 2) / k, one / (k * k), one / (k * k)


def crease_vertex_weights(one):
    """Crease (and boundary) vertex point ``(3/4) V + (1/8)(e0 + e1)``.

    Parameters
    ----------
    one : number
        An exact 1 (``flint.fmpq``, ``Fraction``, sympy) or 1.0 (float).

    Returns
    -------
    tuple of 2 numbers
        (weight of V, of each of the two neighbours along the crease): the cubic B-spline curve
        rule, OpenSubdiv's Sdc crease rule (docs/evaluate.md "Conventions").

    Examples
    --------
    >>> from fractions import Fraction
    >>> crease_vertex_weights(Fraction(1)), crease_vertex_weights(1.0)
    ((Fraction(3, 4), Fraction(1, 8)), (0.75, 0.125))
    """
    return one * 3 / 4, one / 8


# ------------------------------------------------------------------------------ the limit masks
# The left eigenvectors of eigenvalue 1 of the rules above: where a vertex goes in the limit.
def smooth_limit_weights(k, one):
    """Limit position of a smooth interior vertex of valence ``k`` (quads around it).

    ``(k^2 V + 4 sum e_j + sum d_j) / (k (k + 5))`` on the vertex, its edge neighbours e_j and its
    diagonal neighbours d_j (Halstead, Kass, DeRose 1993; Stam 1998).

    Parameters
    ----------
    k : int or ndarray of int
        Valence(s).
    one : number
        An exact 1 (``flint.fmpq``, ``Fraction``, sympy), 1.0 (float) or ``flint.arb(1)`` (balls).

    Returns
    -------
    tuple of 3 numbers
        (weight of V, of each e_j, of each d_j).

    Examples
    --------
    For k = 4 the bicubic B-spline's ``(16 V + 4 sum e + sum d) / 36``; the weights sum to 1:

    >>> from fractions import Fraction
    >>> wV, we, wd = smooth_limit_weights(4, Fraction(1))
    >>> [str(w) for w in (wV, we, wd)], wV + 4 * we + 4 * wd == 1
    (['4/9', '1/9', '1/36'], True)
    """
    den = one * k * (k + 5)
    return one * k * k / den, 4 * one / den, one / den


def crease_limit_weights(one):
    """Limit position of a crease (or boundary) vertex: ``(e0 + 4 V + e1) / 6``, the cubic B-spline
    curve's, on the two neighbours along the crease.

    Parameters
    ----------
    one : number
        An exact 1 (``flint.fmpq``, ``Fraction``, sympy), 1.0 (float) or ``flint.arb(1)`` (balls).

    Returns
    -------
    tuple of 2 numbers
        (weight of V, of each of e0, e1).

    Examples
    --------
    >>> from fractions import Fraction
    >>> crease_limit_weights(Fraction(1)), crease_limit_weights(1.0)[1] == 1 / 6
    ((Fraction(2, 3), Fraction(1, 6)), True)
    """
    return one * 4 / 6, one / 6
