"""Specialize the symbolic characteristic map to a valence: exact, arb ball, arb interval, float.

The nets of :mod:`ccproof.algebra.characteristic_map` are derived once with c = cos(2 pi/k)
symbolic; here c (and lam, R2) get values:

* ``"exact"``: sympy numbers, c = cos(2 pi/k) and lam = (5 + c + sqrt((1+c)(9+c)))/16 exactly;
* ``"arb"``: python-flint balls at ``prec`` bits (outward rounded: each ball contains the exact value);
* ``"float"``: Python floats (from the arb ball's midpoint; for numerics only, never for proofs);
* an *interval* of valences k >= k0 (:func:`valence_interval`): c in [cos(2 pi/k0), 1] and lam in
  [lam(k0), lam(infinity)] as arb balls. The nets evaluated there are enclosures valid for every
  k >= k0 (the union over k of the exact nets lies inside them).
"""

from __future__ import annotations

from ccproof.algebra.field import eval_integer_form, subdominant_lam_sympy
from ccproof.errors import CCProofError, check_valence
from ccproof.valence import Valence, lam_from_c

ARITHMETICS = ("exact", "arb", "float")


def _check_arithmetic(arithmetic):
    if arithmetic not in ARITHMETICS:
        raise CCProofError(f"unknown arithmetic {arithmetic!r}; choose one of {', '.join(ARITHMETICS)}")


def _check_prec(prec):
    if not isinstance(prec, int) or prec < 16:
        raise CCProofError(f"precision must be an integer number of bits >= 16, got {prec!r}")


def cos_2pi_over_k(k, arithmetic="arb", prec=128):
    """c = cos(2 pi / k) (R2, R3).

    The parameter of the field Q(c, lam) of the characteristic map (docs/readings.md R2, R3).

    Parameters
    ----------
    k : int
        Valence, k >= 3.
    arithmetic : {"arb", "exact", "float"}, optional
        A ``flint.arb`` ball (default), a sympy expression or a Python float.
    prec : int, optional
        Bits of precision of the arb ball (default 128).

    Returns
    -------
    flint.arb or sympy.Expr or float

    Examples
    --------
    >>> cos_2pi_over_k(6, "exact")
    1/2
    >>> cos_2pi_over_k(4, "arb", 64)
    0
    >>> import math
    >>> abs(cos_2pi_over_k(5, "float") - (math.sqrt(5) - 1) / 4) < 1e-15
    True
    """
    k = check_valence(k)
    _check_arithmetic(arithmetic)
    if arithmetic == "exact":
        from sympy import cos, pi

        return cos(2 * pi / k)
    _check_prec(prec)
    from flint import arb, ctx, fmpq

    with ctx.workprec(prec):
        c = arb(fmpq(2, k)).cos_pi()
    return c if arithmetic == "arb" else float(c.mid())


def _lam_from_c_arb(c):
    from flint import arb

    return lam_from_c(c, arb.sqrt)


def subdominant_eigenvalue(k, arithmetic="arb", prec=128):
    """Subdominant eigenvalue lam(k) = (5 + c + sqrt((1+c)(9+c)))/16, c = cos(2 pi/k) (R2).

    The larger root of 16 L^2 - 2(5 + c) L + 1 = 0; the double eigenvalue lam_1 = lam_2 of the
    Catmull-Clark subdivision matrix of valence k (bmz04 section 3, Definition 4).

    Parameters
    ----------
    k : int
        Valence, k >= 3.
    arithmetic : {"arb", "exact", "float"}, optional
        A ``flint.arb`` ball (default), a sympy expression or a Python float.
    prec : int, optional
        Bits of precision of the arb ball (default 128).

    Returns
    -------
    flint.arb or sympy.Expr or float

    Examples
    --------
    >>> subdominant_eigenvalue(4, "exact")
    1/2
    >>> subdominant_eigenvalue(3, "exact")
    sqrt(17)/32 + 9/32
    """
    k = check_valence(k)
    _check_arithmetic(arithmetic)
    if arithmetic == "exact":
        from sympy import expand, radsimp

        return expand(radsimp(subdominant_lam_sympy(cos_2pi_over_k(k, "exact"))))
    _check_prec(prec)
    from flint import ctx

    with ctx.workprec(prec + 10):
        lam = _lam_from_c_arb(cos_2pi_over_k(k, "arb", prec + 10))
    with ctx.workprec(prec):
        lam = +lam
    return lam if arithmetic == "arb" else float(lam.mid())


def valence_interval(k0, prec=128):
    """Balls ``(c, lam)`` enclosing c = cos(2 pi/k) and lam(k) for every integer k >= k0 (R10).

    c ranges over [cos(2 pi/k0), 1] and lam, increasing in c, over [lam(k0), (3 + sqrt 5)/8]
    (docs/readings.md R10: one certificate for every k >= k0).

    Parameters
    ----------
    k0 : int
        Smallest valence of the interval, k0 >= 3.
    prec : int, optional
        Bits of precision (default 128).

    Returns
    -------
    c, lam : flint.arb
        The two enclosures.

    Examples
    --------
    >>> from flint import arb, fmpq
    >>> c, lam = valence_interval(40)
    >>> c.contains(1), c.contains(arb(fmpq(2, 40)).cos_pi()), lam.contains((3 + arb(5).sqrt()) / 8)
    (True, True, True)
    >>> lam.contains(subdominant_eigenvalue(1000)), lam.contains(subdominant_eigenvalue(39))
    (True, False)
    """
    k0 = check_valence(k0)
    _check_prec(prec)
    from flint import arb, ctx

    with ctx.workprec(prec):
        c_lo = cos_2pi_over_k(k0, "arb", prec)
        c = c_lo.union(arb(1))
        lam = _lam_from_c_arb(c_lo).union((3 + arb(5).sqrt()) / 8)
    return c, lam


def specialize(element_form, k, arithmetic="arb", prec=128):
    """Value of an integer form ``(A, B, D)`` (see :meth:`QcLam.integer_form`) at valence k.

    ``k`` may be an int or an interval of valences k >= K0 in any spelling of
    :meth:`ccproof.valence.Valence.parse` (``">=K0"``, ``{"min": K0}``; then the value is the union over
    :func:`_interval_pieces`, arb only). The specialization of the symbolic characteristic map to one
    valence (bmz04 section 4.3; docs/readings.md R3, R10).

    Parameters
    ----------
    element_form : tuple of three lists of int
        ``(A, B, D)``, coefficients constant term first: the element (A(c) + B(c) lam)/D(c).
    k : int or str or dict or Valence
        Valence k >= 3, or an interval of valences.
    arithmetic : {"arb", "exact", "float"}, optional
        Arithmetic of the result (default arb).
    prec : int, optional
        Bits of precision of an arb result (default 128).

    Returns
    -------
    flint.arb or sympy.Expr or float

    Examples
    --------
    The form ``lam`` itself, at k = 4 (lam = 1/2), at k = 5 and on k >= 40:

    >>> lam = ([0], [1], [1])
    >>> specialize(lam, 4, "exact"), round(specialize(lam, 5, "float"), 12)
    (1/2, 0.549988354518)
    >>> specialize(lam, ">=40").contains(subdominant_eigenvalue(40))
    True
    """
    v = Valence.parse(k)
    if v.interval:
        return _eval_interval(element_form, _interval_pieces(v.k, 256, prec + 20), prec)
    values = _field_values(v, arithmetic, prec)
    return _eval(element_form, values, arithmetic, prec)


def _eval_interval(form, boxes, prec):
    from flint import ctx

    acc = None
    with ctx.workprec(prec + 20):
        for c, lam in boxes:
            v = eval_integer_form(form, c, lam)
            acc = v if acc is None else acc.union(v)
    with ctx.workprec(prec):
        return +acc


def _field_values(v, arithmetic, prec):
    """(c, lam) of the :class:`~ccproof.valence.Valence` ``v`` in ``arithmetic``."""
    _check_arithmetic(arithmetic)
    if v.interval:
        if arithmetic != "arb":
            raise CCProofError("an interval of valences can only be specialized in 'arb' arithmetic")
        return valence_interval(v.k, prec)
    k = v.k
    if arithmetic == "exact":
        c = cos_2pi_over_k(k, "exact")
        return c, subdominant_lam_sympy(c)
    return cos_2pi_over_k(k, "arb", prec + 20), subdominant_eigenvalue(k, "arb", prec + 20)


def _eval(form, values, arithmetic, prec):
    c, lam = values
    if arithmetic == "exact":
        from sympy import Integer

        return eval_integer_form([[Integer(x) for x in p] for p in form], c, lam)
    from flint import ctx

    with ctx.workprec(prec + 20):
        val = eval_integer_form(form, c, lam)
    with ctx.workprec(prec):
        val = +val
    return val if arithmetic == "arb" else float(val.mid())


def _interval_pieces(k0, pieces, prec=128):
    """Cover the valences k >= k0 by ``pieces`` boxes ``(c, lam)`` (uniform in t = 1/k in [0, 1/k0]).

    Each box pairs a c-interval [cos(2 pi t_{i+1}), cos(2 pi t_i)] with the lam-interval it maps to
    (lam is increasing in c), so evaluating an element on every box and taking the union encloses
    its values for all k >= k0 much more tightly than one evaluation on the whole interval.
    """
    k0 = check_valence(k0)
    from flint import arb, ctx, fmpq

    out = []
    with ctx.workprec(prec):
        for i in range(pieces):
            # t in [i/(k0 pieces), (i+1)/(k0 pieces)]; c = cos(2 pi t) decreasing in t
            c_hi = arb(fmpq(2 * i, k0 * pieces)).cos_pi() if i else arb(1)
            c_lo = arb(fmpq(2 * (i + 1), k0 * pieces)).cos_pi()
            c = c_lo.union(c_hi)
            lam = _lam_from_c_arb(c_lo).union(_lam_from_c_arb(c_hi))
            out.append((c, lam))
    return out


def characteristic_map_patches(k, form="bezier", arithmetic="arb", prec=128, pieces=256):
    """Control nets of the three bicubic layer-0 pieces P1, P2, P3 of the characteristic map of
    valence k in the normalized frame (bmz04 section 4.3, Fig. 3; docs/readings.md R3, R4).

    Parameters
    ----------
    k : int or str or dict or Valence
        Valence k >= 3, or an interval ``">=K0"`` (any spelling of :meth:`ccproof.valence.Valence.parse`)
        for enclosures valid for every valence k >= K0 (arb only; the union of the values on ``pieces``
        sub-intervals, see :func:`_interval_pieces`).
    form : {"bezier", "bspline"}
        Bezier net of each piece on its domain, or its uniform cubic B-spline net.
    arithmetic : {"exact", "arb", "float"}
    prec : int
        Bits of precision of the arb result.

    Returns
    -------
    dict
        ``{"P1": net, "P2": net, "P3": net}`` where ``net[i][j] = (x, y)``, i, j = 0..3, index i
        along the local parameter s (the face's u), j along t (v). Domains: P1 on [1/2,1]x[0,1/2],
        P2 on [1/2,1]^2, P3 on [0,1/2]x[1/2,1], with s = 2u - 1 or 2u, t = 2v or 2v - 1.

    >>> nets = characteristic_map_patches(4, "bezier", "exact")
    >>> nets["P2"][3][3]        # k = 4 is the identity map: P2(1, 1) = (1, 1)
    (1, 1)
    """
    from ccproof.algebra.characteristic_map import symbolic_bezier_nets, symbolic_bspline_nets

    v = Valence.parse(k)
    if form not in ("bezier", "bspline"):
        raise CCProofError(f"unknown net form {form!r}; use 'bezier' or 'bspline'")
    sym = symbolic_bezier_nets() if form == "bezier" else symbolic_bspline_nets()
    if v.interval:
        if arithmetic != "arb":
            raise CCProofError("an interval of valences can only be specialized in 'arb' arithmetic")
        boxes = _interval_pieces(v.k, pieces, prec + 20)
        ev = lambda f: _eval_interval(f, boxes, prec)
    else:
        values = _field_values(v, arithmetic, prec)
        ev = lambda f: _simplify(_eval(f, values, arithmetic, prec), arithmetic)
    return {name: [[tuple(ev(x.integer_form()) for x in p) for p in row] for row in net]
            for name, net in sym.items()}


def _simplify(val, arithmetic):
    if arithmetic == "exact":
        from sympy import expand, radsimp

        return expand(radsimp(val))
    return val
