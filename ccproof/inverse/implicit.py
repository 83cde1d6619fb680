"""Implicit equations of the layer and patch boundaries of the characteristic map (bmz04 section 4.3).

Every boundary between two layers or between two of the pieces P1, P2, P3 is the image of a
segment u = 1/2, v = 1/2, u = 1 or v = 1 of a layer-0 domain, i.e. an edge of a bicubic Bezier
net: a parametric cubic ``(x(w), y(w))``, w in [0, 1]. Its implicit equation is the Sylvester
resultant of Definition 5 (bmz04):

    g(u, v) = det S(x(w) - u, y(w) - v),

the 6 x 6 determinant with rows ``q0 q1 q2 q3 0 0`` (shifted three times) and ``r0 .. r3``
(shifted three times), q = x - u, r = y - v, coefficients in the power basis of w. g has total
degree 3 in (u, v) and vanishes exactly on the (whole algebraic) curve.

Exactness and the choice of field
---------------------------------
The edge control points lie in Q(c, lam) with c = cos(2 pi/k) *symbolic* (docs/readings.md R3, the field
of the certified tables). We therefore compute g ONCE, symbolically, for every valence at the same
time: each coefficient ``(A(c) + B(c) lam)/D(c)`` is cleared of its denominator, the Sylvester
determinant is expanded exactly in Z[lam, c, u, v] (python-flint ``fmpz_mpoly``, a Laplace
expansion with memoized minors), and the result is reduced modulo 16 lam^2 - 2(5+c) lam + 1
(exact ``fmpq_mpoly`` division), giving

    g(u, v) = (G0(c, u, v) + G1(c, u, v) lam) / Den(c),      Den = (D_x D_y)^3.

This beats working per valence with sympy algebraic numbers (slow, and c = cos(2 pi/7) has no
radical form) and beats arb-only computation (it would not be exact). The symbolic determinant is
cross-checked against python-flint's ``resultant`` (same polynomials, identical up to the sign
(-1) that reversing the column order of Definition 5 introduces) and, at rational specializations,
against ``sympy.resultant`` (tests). Specializations: ``"exact"`` (sympy numbers), ``"arb"``
(balls enclosing the exact coefficients) and ``"float"`` (the arb midpoints, scaled by a positive
number so that the largest coefficient is 1: the sign of g is unchanged).

The formal-degree resultant vanishes identically when both leading coefficients vanish: this
happens for k = 4 only (Phi is the identity, every boundary is a straight line, lam = 1/2 is
rational). There, and for any rational (c, lam) pair, :func:`rational_implicit` computes the
Sylvester determinant over Q with the *actual* degrees of x(w) and y(w).

Sign convention
---------------
``inside_sign(k, edge)`` is the sign of g on the side of the edge where the edge's own piece lies
(e.g. for ``"P1:s=1"``, the outer boundary u = 1 of layer 0, the side towards the origin). It is
determined rigorously in ``arb`` from the sign of the directional derivative
d/dn g(P(edge + n)) at points of the edge (n the inward normal in the parameter domain), and
checked to be the same at 9 points along the edge. The float classifier :class:`FloatImplicit`
returns +1 (piece side), -1 (other side) or 0 (within the bound on the rounding error of its own
evaluation: undecided).

>>> g = implicit_polynomial(4, "P1:s=1", "exact")   # k = 4: the line u = 1, as 1 - u
>>> sorted(g.items())
[((0, 0), 1), ((1, 0), -1)]
>>> inside_sign(4, "P1:s=1"), inside_sign(4, "P1:s=0")
(1, -1)
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from functools import cache, lru_cache

from ccproof.errors import CCProofError, check_valence
from ccproof.inverse.data import bezier_to_power
from ccproof.inverse.edges import Edge, get_edge
from ccproof.inverse.sylvester import determinant, rational_implicit, rational_nets, sylvester_matrix

# ---------------------------------------------------------------------------------------------
# symbolic implicitization over Q(c, lam)
# ---------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class SymbolicImplicit:
    """g(u, v) = numerator(lam, c, u, v) / denominator(c) for every valence at once (bmz04 Definition 5).

    Made by :func:`symbolic_implicit` (docs/inverse.md).

    Parameters
    ----------
    edge : Edge
    resultant : flint.fmpz_mpoly
        The Sylvester determinant in Z[lam, c, u, v] of the denominator-cleared cubics (before
        reduction; equals (-1) times flint's ``resultant`` of the same two polynomials).
    numerator : flint.fmpq_mpoly
        In (lam, c, u, v), of degree <= 1 in lam (reduced modulo 16 lam^2 - 2(5+c) lam + 1).
    denominator : flint.fmpz_poly
        In c, = (D_x D_y)^3 where D_x, D_y clear the denominators of the coefficients of x(w), y(w).
    x, y : tuple of flint.fmpz_mpoly
        The cleared cubics in (lam, c, u, v) (power basis in w).
    dx, dy : flint.fmpz_poly
        Their denominators.

    Examples
    --------
    >>> g = symbolic_implicit("P1:s=1")
    >>> g.edge.name, g.numerator.degrees()[0], len(g.x)
    ('P1:s=1', 1, 4)
    """

    edge: Edge
    resultant: object
    numerator: object
    denominator: object
    x: tuple
    y: tuple
    dx: object
    dy: object


def _zring():
    from flint import fmpz_mpoly_ctx

    return fmpz_mpoly_ctx.get(("lam", "c", "u", "v"), "lex")


def _qring():
    from flint import fmpq_mpoly_ctx

    return fmpq_mpoly_ctx.get(("lam", "c", "u", "v"), "lex")


def _cpoly(R, coeffs):
    c = R.gens()[1]
    acc = R.constant(0)
    for a in reversed(coeffs):
        acc = acc * c + int(a)
    return acc


def _cleared_cubic(R, values):
    """Power-basis cubic with QcLam coefficients -> (list of fmpz_mpoly, fmpz_poly denominator)."""
    from flint import fmpz_poly

    lam = R.gens()[0]
    fracs = []
    for q in bezier_to_power(values):
        A, B, D = q.integer_form()
        fracs.append((_cpoly(R, A) + _cpoly(R, B) * lam, fmpz_poly([int(d) for d in D])))
    den = fmpz_poly(1)
    for _, d in fracs:
        den = den * d // den.gcd(d)
    if den.coeffs()[-1] < 0:
        den = -den
    out = [num * _cpoly(R, (den // d).coeffs()) for num, d in fracs]
    return out, den


def _reduce_lam(poly):
    """Reduce an ``fmpq_mpoly``/``fmpz_mpoly`` in (lam, c, u, v) modulo 16 lam^2 - 2(5+c) lam + 1
    (R2): the result has degree <= 1 in lam and the same value at lam = lam(c)."""
    Q = _qring()
    p = Q.from_dict(dict(poly.to_dict())) if poly.context() is not Q else poly
    lam, c, _, _ = Q.gens()
    _, rem = divmod(p, 16 * lam**2 - 2 * (5 + c) * lam + 1)
    return rem


@cache
def symbolic_implicit(edge):
    """The implicit polynomial of a boundary edge, symbolic in c and lam (see module docstring).

    Parameters
    ----------
    edge : str or Edge
        A boundary edge (:data:`EDGES`).

    Returns
    -------
    SymbolicImplicit

    Examples
    --------
    >>> g = symbolic_implicit("P1:s=1")
    >>> g.numerator.degrees()[0] <= 1, g.numerator.total_degree() > 0
    (True, True)
    """
    from ccproof.algebra.characteristic_map import symbolic_bezier_nets

    e = get_edge(edge)
    R = _zring()
    _, _, u, v = R.gens()
    pts = e.control_points(symbolic_bezier_nets()[e.patch])
    x, dx = _cleared_cubic(R, [p[0] for p in pts])
    y, dy = _cleared_cubic(R, [p[1] for p in pts])
    q = [x[0] - _cpoly(R, dx.coeffs()) * u] + x[1:]
    r = [y[0] - _cpoly(R, dy.coeffs()) * v] + y[1:]
    res = determinant(sylvester_matrix(q, r, R.constant(0)), R.constant(0), R.constant(1))
    den = (dx * dy) ** 3
    return SymbolicImplicit(e, res, _reduce_lam(res), den, tuple(q), tuple(r), dx, dy)


# ---------------------------------------------------------------------------------------------
# specialization to a valence
# ---------------------------------------------------------------------------------------------


def _uv_split(numerator):
    """{(a, b): (coeff list of c for lam^0, coeff list of c for lam^1)} from the numerator."""
    out = {}
    for key, coef in numerator.to_dict().items():
        i, j, a, b = (int(x) for x in key)
        g = out.setdefault((a, b), ({}, {}))
        g[i][j] = coef
    return out


def _horner(coeffs_by_power, x, zero):
    if not coeffs_by_power:
        return zero
    acc = zero
    for p in range(max(coeffs_by_power), -1, -1):
        acc = acc * x + coeffs_by_power.get(p, 0)
    return acc


def implicit_polynomial(k, edge, arithmetic="arb", prec=128):
    """Coefficients ``{(a, b): g_ab}`` of g(u, v) = sum g_ab u^a v^b for valence k.

    ``arithmetic``: ``"exact"`` (sympy numbers; for k = 4 Python ``int``/``Fraction``), ``"arb"``
    (balls containing the exact coefficients) or ``"float"`` (midpoints, scaled by a positive
    factor so that the largest |coefficient| is 1; same sign as g everywhere).

    bmz04 Definition 5 specialized to valence k (docs/inverse.md).

    Parameters
    ----------
    k : int
        Valence, k >= 3.
    edge : str or Edge
        A boundary edge (:data:`EDGES`).
    arithmetic : {"arb", "exact", "float"}, optional
    prec : int, optional
        Bits of precision of arb coefficients (default 128).

    Returns
    -------
    dict of tuple -> scalar
        ``{(a, b): g_ab}``, total degree <= 3.

    Examples
    --------
    >>> g = implicit_polynomial(3, "P1:s=0", "float")
    >>> max(abs(x) for x in g.values())
    1.0
    >>> sorted(g)[-1]            # total degree 3
    (3, 0)
    """
    k = check_valence(k)
    e = get_edge(edge)
    if k == 4:
        g = rational_implicit(e, Fraction(0), Fraction(1, 2))
        if arithmetic == "exact":
            return {ab: (int(x) if x.denominator == 1 else x) for ab, x in g.items()}
        if arithmetic == "arb":
            from flint import arb, fmpq

            return {ab: arb(fmpq(x.numerator, x.denominator)) for ab, x in g.items()}
        return _normalize({ab: float(x) for ab, x in g.items()})
    sym = symbolic_implicit(e)
    split = _uv_split(sym.numerator)
    if arithmetic == "exact":
        from sympy import Integer, Rational

        from ccproof.algebra.specialize import cos_2pi_over_k, subdominant_eigenvalue

        c = cos_2pi_over_k(k, "exact")
        lam = subdominant_eigenvalue(k, "exact")
        den = _horner({i: Integer(int(a)) for i, a in enumerate(sym.denominator.coeffs())}, c, Integer(0))

        def conv(d):
            return {p: Rational(int(q.p), int(q.q)) for p, q in d.items()}

        return {ab: (_horner(conv(g0), c, Integer(0)) + _horner(conv(g1), c, Integer(0)) * lam) / den
                for ab, (g0, g1) in split.items()}
    if arithmetic not in ("arb", "float"):
        raise CCProofError(f"unknown arithmetic {arithmetic!r}; choose 'exact', 'arb' or 'float'")
    coeffs = _arb_coefficients(k, e.name, prec if arithmetic == "arb" else 128)
    if arithmetic == "arb":
        return dict(coeffs)
    return _normalize({ab: float(x.mid()) for ab, x in coeffs})


def _normalize(g):
    m = max(abs(x) for x in g.values())
    if m == 0:
        raise CCProofError("implicit polynomial vanishes identically")
    return {ab: x / m for ab, x in g.items()}


@lru_cache(maxsize=512)
def _arb_coefficients(k, edge_name, prec):
    from flint import arb, ctx, fmpq

    from ccproof.algebra.specialize import cos_2pi_over_k, subdominant_eigenvalue

    sym = symbolic_implicit(edge_name)
    split = _uv_split(sym.numerator)
    work = prec + 64 + 8 * sym.denominator.degree()
    c = cos_2pi_over_k(k, "arb", work + 20)
    lam = subdominant_eigenvalue(k, "arb", work + 20)
    out = []
    with ctx.workprec(work):
        zero = arb(0)
        den = _horner({i: arb(int(a)) for i, a in enumerate(sym.denominator.coeffs())}, c, zero)
        for ab, (g0, g1) in sorted(split.items()):
            f0 = {p: arb(fmpq(int(q.p), int(q.q))) for p, q in g0.items()}
            f1 = {p: arb(fmpq(int(q.p), int(q.q))) for p, q in g1.items()}
            val = (_horner(f0, c, zero) + _horner(f1, c, zero) * lam) / den
            out.append((ab, val))
    with ctx.workprec(prec):
        out = [(ab, +x) for ab, x in out]
    return tuple(out)


def _exact_value_rational_c(edge, c, u, v):
    """g(u, v) exactly for rational c (valences 3, 4, 6, or a rational pseudo-valence) and
    rational u, v, as ``(alpha, beta, d)`` meaning alpha + beta sqrt(d) with d = (1+c)(9+c)
    (lam = (5 + c + sqrt d)/16). Uses the symbolic numerator (formal degrees).

    >>> a, b, d = _exact_value_rational_c("P1:s=1", Fraction(-1, 2), Fraction(1), Fraction(0))
    >>> d
    Fraction(17, 4)
    """
    from flint import fmpq

    c, u, v = Fraction(c), Fraction(u), Fraction(v)
    sym = symbolic_implicit(get_edge(edge))
    f = lambda x: fmpq(x.numerator, x.denominator)
    # numerator = N0 + N1 lam at (c, u, v) (exact substitution in flint); lam = (5 + c + sqrt d)/16
    rest = sym.numerator.subs({"c": f(c), "u": f(u), "v": f(v)})
    n0 = n1 = Fraction(0)
    for exps, coef in rest.to_dict().items():
        val = Fraction(int(coef.p), int(coef.q))
        if int(exps[0]) == 0:
            n0 += val
        else:
            n1 += val
    den = Fraction(int(sym.denominator(f(c)).p), int(sym.denominator(f(c)).q))
    d = (1 + c) * (9 + c)
    alpha = (n0 + n1 * (5 + c) / 16) / den
    beta = n1 / 16 / den
    return alpha, beta, d


def _sign_quadratic_surd(alpha, beta, d):
    """Exact sign of alpha + beta sqrt(d) for rationals alpha, beta and d >= 0.

    >>> _sign_quadratic_surd(Fraction(-3), Fraction(1), Fraction(10)), _sign_quadratic_surd(1, -1, 1)
    (1, 0)
    """
    sa = (alpha > 0) - (alpha < 0)
    sb = (beta > 0) - (beta < 0)
    if sb == 0 or d == 0:
        return sa
    if sa == 0 or sa == sb:
        return sb
    # opposite signs: compare alpha^2 with beta^2 d
    diff = alpha * alpha - beta * beta * d
    s = (diff > 0) - (diff < 0)
    return sa * s


def exact_sign(k, edge, u, v, prec=256):
    """Sign (-1, 0, 1) of g at a rational point (u, v) (``Fraction``/int), exactly.

    k = 3, 4, 6 (c rational): exact arithmetic in Q(sqrt d). Other k: an ``arb`` evaluation of the
    exact coefficients at ``prec`` bits, doubled until the ball excludes 0 (a point exactly on the
    curve with irrational coefficients is then never decided: after 4096 bits a
    :class:`CCProofError` is raised).

    Parameters
    ----------
    k : int
        Valence, k >= 3.
    edge : str or Edge
        A boundary edge (:data:`EDGES`).
    u, v : Fraction or int
        The point.
    prec : int, optional
        Starting bits of precision of the arb evaluation (k other than 3, 4, 6).

    Returns
    -------
    int
        -1, 0 or 1.

    Examples
    --------
    >>> exact_sign(3, "P1:s=1", 1, 0), exact_sign(3, "P1:s=1", Fraction(1, 2), 0) != 0
    (0, True)
    """
    k = check_valence(k)
    u, v = Fraction(u), Fraction(v)
    c = {3: Fraction(-1, 2), 4: Fraction(0), 6: Fraction(1, 2)}.get(k)
    if k == 4:
        g = rational_implicit(edge, 0, Fraction(1, 2))
        val = sum(x * u**a * v**b for (a, b), x in g.items())
        return (val > 0) - (val < 0)
    if c is not None:
        return _sign_quadratic_surd(*_exact_value_rational_c(edge, c, u, v))
    from flint import arb, ctx, fmpq

    while prec <= 4096:
        coeffs = _arb_coefficients(k, get_edge(edge).name, prec)
        with ctx.workprec(prec):
            U, V = arb(fmpq(u.numerator, u.denominator)), arb(fmpq(v.numerator, v.denominator))
            val = sum((x * U**a * V**b for (a, b), x in coeffs), arb(0))
        if val > 0:
            return 1
        if val < 0:
            return -1
        prec *= 2
    raise CCProofError(f"could not decide the sign of g_{edge} at ({u}, {v}) for k = {k}")


# ---------------------------------------------------------------------------------------------
# sign convention (which side is inside)
# ---------------------------------------------------------------------------------------------


def _arb_net(k, patch, prec):
    from ccproof.algebra.specialize import characteristic_map_patches

    return characteristic_map_patches(k, "bezier", "arb", prec)[patch]


def _bernstein(n, i, t):
    from math import comb

    return comb(n, i) * t**i * (1 - t) ** (n - i)


def _bernstein_d(n, i, t):
    from math import comb

    d = 0
    if i > 0:
        d += i * t ** (i - 1) * (1 - t) ** (n - i)
    if i < n:
        d -= (n - i) * t**i * (1 - t) ** (n - i - 1)
    return comb(n, i) * d


@lru_cache(maxsize=512)
def inside_sign(k, edge, prec=128):
    """Sign of g on the side of ``edge`` where its own piece lies (+1 or -1), decided in arb.

    At w = 0.1, 0.2, ..., 0.9 along the edge, the derivative of g(P(s, t)) in the direction
    pointing into the piece's domain is enclosed in a ball; all nine balls must exclude 0 and
    agree (else :class:`CCProofError`). docs/inverse.md.

    Parameters
    ----------
    k : int
        Valence, k >= 3.
    edge : str or Edge
        A boundary edge (:data:`EDGES`).
    prec : int, optional
        Bits of precision (default 128).

    Returns
    -------
    int
        +1 or -1.

    Examples
    --------
    For k = 4 the edge P1:s=1 is the line u = 1 and P1 lies at u < 1:

    >>> g = rational_implicit("P1:s=1", 0, Fraction(1, 2))
    >>> u, v = Fraction(3, 4), Fraction(1, 4)
    >>> inside_sign(4, "P1:s=1") * sum(x * u**a * v**b for (a, b), x in g.items()) > 0
    True
    """
    k = check_valence(k)
    e = get_edge(edge)
    if k == 4:
        net = rational_nets(0, Fraction(1, 2))[e.patch]
        g = rational_implicit(e, 0, Fraction(1, 2))
        signs = set()
        for w in [Fraction(i, 10) for i in range(1, 10)]:
            d = _directional(net, e, w, g, Fraction)
            signs.add((d > 0) - (d < 0))
    else:
        from flint import arb, ctx, fmpq

        net = _arb_net(k, e.patch, prec + 40)
        g = dict(_arb_coefficients(k, e.name, prec + 40))
        signs = set()
        with ctx.workprec(prec + 40):
            for i in range(1, 10):
                d = _directional(net, e, arb(fmpq(i, 10)), g, arb)
                signs.add(1 if d > 0 else (-1 if d < 0 else 0))
    if len(signs) != 1 or 0 in signs:
        raise CCProofError(f"the sign of g on the inside of {e.name} is not constant/decided for k = {k}")
    return signs.pop()


def _directional(net, e, w, g, kind):
    """d/dn g(P(edge point moved by n into the piece)) at n = 0, edge parameter w."""
    s, t = e.parameter(w, 0)
    x = y = dxn = dyn = kind(0)
    sign = -1 if e.value == 1 else 1  # moving inward changes the fixed coordinate by sign * n
    for i in range(4):
        for j in range(4):
            px, py = net[i][j]
            bi, bj = _bernstein(3, i, s), _bernstein(3, j, t)
            x = x + px * bi * bj
            y = y + py * bi * bj
            if e.axis == 0:
                dd = _bernstein_d(3, i, s) * bj * sign
            else:
                dd = bi * _bernstein_d(3, j, t) * sign
            dxn = dxn + px * dd
            dyn = dyn + py * dd
    gu = gv = kind(0)
    for (a, b), cval in g.items():
        if a:
            gu = gu + cval * a * x ** (a - 1) * y**b
        if b:
            gv = gv + cval * b * x**a * y ** (b - 1)
    return gu * dxn + gv * dyn


# ---------------------------------------------------------------------------------------------
# float classifier
# ---------------------------------------------------------------------------------------------


class FloatImplicit:
    """Float copy of g for one valence and edge: vectorized evaluation and side test.

    ``coeffs[a, b]`` multiplies u^a v^b (normalized: max |coeff| = 1). ``sign`` is
    :func:`inside_sign`. ``side(u, v)`` is +1 on the piece's side, -1 on the other side and 0
    where |g| is below a rigorous bound on the rounding error of the Horner evaluation
    (gamma_12 sum |g_ab| |u|^a |v|^b: nested Horner of degree 3 + 3, the standard a-priori bound).

    Parameters
    ----------
    k : int
        Valence, k >= 3.
    edge : str or Edge
        A boundary edge (:data:`EDGES`).

    Examples
    --------
    >>> f = FloatImplicit(4, "P1:s=1")
    >>> f.side([0.5, 1.5, 1.0], [0.2, 0.2, 0.3]).tolist()
    [1, -1, 0]
    """

    def __init__(self, k, edge):
        import numpy as np

        k = check_valence(k)
        e = get_edge(edge)
        g = implicit_polynomial(k, e, "float")
        c = np.zeros((4, 4))
        for (a, b), x in g.items():
            c[a, b] = x
        self.k, self.edge, self.coeffs = k, e, c
        self.abs_coeffs = np.abs(c)
        self.sign = inside_sign(k, e.name)

    def __call__(self, u, v):
        import numpy as np

        return _horner2(self.coeffs, np.asarray(u, dtype=float), np.asarray(v, dtype=float))

    def error_bound(self, u, v):
        import numpy as np

        u, v = np.abs(np.asarray(u, dtype=float)), np.abs(np.asarray(v, dtype=float))
        gamma = 12 * 2.0**-53 / (1 - 12 * 2.0**-53)
        return gamma * _horner2(self.abs_coeffs, u, v) * (1 + 1e-12) + 1e-300

    def side(self, u, v):
        import numpy as np

        val = self(u, v)
        err = self.error_bound(u, v)
        out = np.where(val > err, 1, np.where(val < -err, -1, 0))
        return out * self.sign


def _horner2(c, u, v):
    """sum c[a, b] u^a v^b for a 4x4 coefficient array, Horner in u over Horner in v."""
    acc = None
    for a in range(3, -1, -1):
        row = c[a]
        q = ((row[3] * v + row[2]) * v + row[1]) * v + row[0]
        acc = q if acc is None else acc * u + q
    return acc
