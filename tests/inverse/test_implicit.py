"""Implicitization of the boundary cubics (bmz04 Definition 5): exactness, cross-checks, sign tests.

Expected values come from python-flint's and sympy's ``resultant`` (independent implementations),
from the parametric curves themselves (points on / on either side of an edge are built from the
Bezier nets in arb), or from exact rational arithmetic.
"""

from fractions import Fraction
from functools import lru_cache

import numpy as np
import pytest
import sympy as sp
from flint import arb, ctx, fmpq, fmpz_mpoly_ctx
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from ccproof.algebra.specialize import characteristic_map_patches, subdominant_eigenvalue
from ccproof.errors import CCProofError
from ccproof.inverse.data import bezier_to_power
from ccproof.inverse.edges import EDGES
from ccproof.inverse.implicit import FloatImplicit, exact_sign, implicit_polynomial, inside_sign, symbolic_implicit
from ccproof.inverse.sylvester import RATIONAL_PAIRS, determinant, rational_implicit, rational_nets, sylvester_matrix

EDGE_NAMES = sorted(EDGES)


def _lift(p, R5):
    return R5.from_dict({tuple(int(e) for e in k) + (0,): v for k, v in p.to_dict().items()})


@pytest.mark.parametrize("name", EDGE_NAMES)
def test_symbolic_determinant_equals_flint_resultant(name):
    """det S (Definition 5) = (-1)^(m n) Res = -Res for two cubics, as polynomials in lam, c, u, v."""
    g = symbolic_implicit(name)
    R5 = fmpz_mpoly_ctx.get(("lam", "c", "u", "v", "w"), "lex")
    w = R5.gens()[4]
    X = sum((_lift(a, R5) * w**i for i, a in enumerate(g.x)), R5.constant(0))
    Y = sum((_lift(a, R5) * w**i for i, a in enumerate(g.y)), R5.constant(0))
    assert _lift(g.resultant, R5) == -X.resultant(Y, "w")
    assert g.numerator.degrees()[0] <= 1  # reduced modulo the minimal polynomial of lam
    assert g.numerator.total_degree() > 0


def test_sylvester_matrix_layout_matches_definition_5():
    q = [sp.Symbol(f"q{i}") for i in range(4)]
    r = [sp.Symbol(f"r{i}") for i in range(3)]
    S = sylvester_matrix(q, r, 0)
    assert S[0] == [q[0], q[1], q[2], q[3], 0]
    assert S[1] == [0, q[0], q[1], q[2], q[3]]
    assert S[2] == [r[0], r[1], r[2], 0, 0]
    assert S[4] == [0, 0, r[0], r[1], r[2]]
    x = sp.Symbol("x")
    res = sp.resultant(sum(a * x**i for i, a in enumerate(q)), sum(a * x**i for i, a in enumerate(r)), x)
    assert sp.expand(determinant(S, 0, 1) - (-1) ** (3 * 2) * res) == 0
    assert sp.expand(sp.Matrix(S).det() - determinant(S, 0, 1)) == 0


@pytest.mark.parametrize("pair", RATIONAL_PAIRS, ids=lambda p: f"c={p[0]}")
def test_rational_specializations_against_sympy(pair):
    """Over Q: our Sylvester determinant (actual degrees) = (-1)^(mn) sympy.resultant, and for
    c != 0 the symbolic g specialized at (c, lam) is the same polynomial."""
    c, lam = pair
    nets = rational_nets(c, lam)
    u, v, w = sp.symbols("u v w")
    for name, e in EDGES.items():
        pts = e.control_points(nets[e.patch])
        X = sum(sp.Rational(a.numerator, a.denominator) * w**i
                for i, a in enumerate(bezier_to_power([p[0] for p in pts])))
        Y = sum(sp.Rational(a.numerator, a.denominator) * w**i
                for i, a in enumerate(bezier_to_power([p[1] for p in pts])))
        m, n = sp.degree(X, w), sp.degree(Y, w)
        want = sp.expand((-1) ** (m * n) * sp.resultant(X - u, Y - v, w))
        g = rational_implicit(name, c, lam)
        got = sum(sp.Rational(x.numerator, x.denominator) * u**a * v**b for (a, b), x in g.items())
        assert sp.expand(got - want) == 0, name
        if c != 0:
            sym = symbolic_implicit(name)
            lam_q = fmpq(lam.numerator, lam.denominator)
            c_q = fmpq(c.numerator, c.denominator)
            num = sym.numerator.subs({"lam": lam_q, "c": c_q})
            den = sym.denominator(c_q)
            spec = sum(sp.Rational(int(x.p), int(x.q)) * u ** int(k[2]) * v ** int(k[3])
                       for k, x in num.to_dict().items()) / sp.Rational(int(den.p), int(den.q))
            assert sp.expand(spec - got) == 0, name


def test_k4_boundaries_are_the_lines():
    lines = {"P1:s=0": "u", "P1:s=1": "u", "P1:t=1": "v", "P2:s=0": "u", "P2:s=1": "u",
             "P2:t=0": "v", "P2:t=1": "v", "P3:s=1": "u", "P3:t=0": "v", "P3:t=1": "v"}
    for name, var in lines.items():
        g = implicit_polynomial(4, name, "exact")
        assert set(g) <= {(0, 0), (1, 0) if var == "u" else (0, 1)}, (name, g)
        assert g[(0, 0)] != 0


def test_shared_edges_and_symmetry_exact():
    """The same curve seen from both sides has the same g (exactly) and opposite inside signs;
    Phi(v, u) = swap(Phi(u, v)) makes the P3 edges the mirror images of P1's."""
    R = symbolic_implicit("P1:t=1").numerator.context()
    lam, c, u, v = R.gens()
    for a, b in (("P1:t=1", "P2:t=0"), ("P2:s=0", "P3:s=1")):
        assert symbolic_implicit(a).numerator == symbolic_implicit(b).numerator
        assert symbolic_implicit(a).denominator == symbolic_implicit(b).denominator
        for k in (3, 5, 9):
            assert inside_sign(k, a) == -inside_sign(k, b)
    for a, b in (("P1:s=1", "P3:t=1"), ("P1:s=0", "P3:t=0"), ("P2:s=1", "P2:t=1"), ("P1:t=1", "P2:s=0")):
        ga, gb = symbolic_implicit(a).numerator, symbolic_implicit(b).numerator
        swapped = gb.compose(lam, c, v, u)
        assert swapped == ga or swapped == -ga, (a, b)


def test_outer_boundary_is_the_inner_one_scaled():
    """Phi(y/2) = lam Phi(y): the outer edges u = 1 (P1, P2) lie on Gamma / lam, Gamma the inner edge
    u = 1/2 of P1, so their implicit polynomials are proportional to g_Gamma(lam u, lam v).
    Checked exactly at a rational (c, lam) and in arb at real valences."""
    c, lam = RATIONAL_PAIRS[0]
    g0 = rational_implicit("P1:s=0", c, lam)
    for name in ("P1:s=1", "P2:s=1"):
        g1 = rational_implicit(name, c, lam)
        scaled = {ab: x * lam ** sum(ab) for ab, x in g0.items()}
        ratio = {g1[ab] / scaled[ab] for ab in scaled if scaled[ab] != 0}
        assert set(g1) == {ab for ab in scaled if scaled[ab] != 0}
        assert len(ratio) == 1
    for k in (3, 7, 40):
        lam_k = subdominant_eigenvalue(k, "arb", 200)
        g0 = implicit_polynomial(k, "P1:s=0", "arb", 200)
        g1 = implicit_polynomial(k, "P2:s=1", "arb", 200)
        ref = max(g1, key=lambda ab: abs(g1[ab]).mid())
        with ctx.workprec(200):
            r0 = g1[ref] / (g0[ref] * lam_k ** sum(ref))
            for ab in g1:
                assert abs(g1[ab] - r0 * g0[ab] * lam_k ** sum(ab)) < arb(10) ** -40


@pytest.mark.parametrize("k", [3, 5, 8, 50])
def test_g_vanishes_on_its_edge(k):
    nets = characteristic_map_patches(k, "bezier", "arb", 200)
    for name, e in EDGES.items():
        g = implicit_polynomial(k, name, "arb", 200)
        pts = e.control_points(nets[e.patch])
        with ctx.workprec(200):
            for w in (fmpq(1, 7), fmpq(1, 2), fmpq(5, 6)):
                W = arb(w)
                B = [(1 - W) ** 3, 3 * W * (1 - W) ** 2, 3 * W**2 * (1 - W), W**3]
                x = sum((b * p[0] for b, p in zip(B, pts)), arb(0))
                y = sum((b * p[1] for b, p in zip(B, pts)), arb(0))
                val = sum((cf * x**a * y**bb for (a, bb), cf in g.items()), arb(0))
                scale = sum((abs(cf) for cf in g.values()), arb(0))
                assert abs(val) < scale * arb(10) ** -40, (name, val)


@lru_cache(maxsize=16)
def _arb_nets(k):
    return characteristic_map_patches(k, "bezier", "arb", 300)


@lru_cache(maxsize=64)
def _classifier(k, name):
    return FloatImplicit(k, name)


def _point_near_edge(k, name, w, delta, inward):
    """The arb point P(edge moved by +-delta) at edge parameter w, rounded to an exact rational."""
    e = EDGES[name]
    net = _arb_nets(k)[e.patch] if k != 4 else None
    s, t = e.parameter(w, delta if inward else -delta)
    if k == 4:
        nets = rational_nets(0, Fraction(1, 2))[e.patch]
        B = lambda z: [(1 - z) ** 3, 3 * z * (1 - z) ** 2, 3 * z**2 * (1 - z), z**3]
        bs, bt = B(Fraction(s)), B(Fraction(t))
        x = sum(bs[i] * bt[j] * nets[i][j][0] for i in range(4) for j in range(4))
        y = sum(bs[i] * bt[j] * nets[i][j][1] for i in range(4) for j in range(4))
        return x, y
    with ctx.workprec(300):
        S, T = arb(fmpq(s.numerator, s.denominator)), arb(fmpq(t.numerator, t.denominator))
        B = lambda z: [(1 - z) ** 3, 3 * z * (1 - z) ** 2, 3 * z**2 * (1 - z), z**3]
        bs, bt = B(S), B(T)
        x = sum((bs[i] * bt[j] * net[i][j][0] for i in range(4) for j in range(4)), arb(0))
        y = sum((bs[i] * bt[j] * net[i][j][1] for i in range(4) for j in range(4)), arb(0))

    def frac(a):
        man, ex = a.mid().man_exp()
        return Fraction(int(man)) * Fraction(2) ** int(ex)

    return frac(x), frac(y)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    k=st.sampled_from([3, 4, 5, 6, 8, 13, 100]),
    name=st.sampled_from(EDGE_NAMES),
    w=st.fractions(min_value=Fraction(1, 50), max_value=Fraction(49, 50), max_denominator=10**6),
    e=st.integers(min_value=4, max_value=28),
)
def test_sign_test_agrees_with_exact_evaluation(k, name, w, e):
    """Rational points on both sides of each boundary (built from the parametric patch, so which
    side they are on is known independently of g): the exact sign of g (exact in Q(sqrt d) for
    k = 3, 4, 6; arb with the ball excluding 0 otherwise) is the documented inside sign on the
    piece's side and its opposite across; the float classifier agrees."""
    delta = Fraction(1, 2**e)
    f = _classifier(k, name)
    sigma = inside_sign(k, name)
    for inward, want in ((True, sigma), (False, -sigma)):
        x, y = _point_near_edge(k, name, w, delta, inward)
        got = exact_sign(k, name, x, y)
        assert got == want, (k, name, w, e, inward)
        side = int(f.side(float(x), float(y)))
        assert side in (0, 1 if inward else -1)
        if e <= 24:
            assert side == (1 if inward else -1)


def test_inside_signs_do_not_depend_on_the_valence():
    """The documented sign table (docs/inverse.md) holds for every k != 4 sampled."""
    want = {"P1:s=0": -1, "P2:s=0": -1, "P1:t=1": -1, "P2:t=1": -1, "P3:t=1": -1,
            "P1:s=1": 1, "P2:s=1": 1, "P2:t=0": 1, "P3:s=1": 1, "P3:t=0": 1}
    for k in (3, 5, 6, 9, 17, 33, 64, 100):
        assert {n: inside_sign(k, n) for n in EDGES} == want


def test_exact_sign_on_the_curve_and_k4():
    assert exact_sign(4, "P1:s=1", 1, Fraction(1, 3)) == 0
    assert exact_sign(4, "P1:s=1", Fraction(99, 100), 0) == inside_sign(4, "P1:s=1")
    assert exact_sign(3, "P1:s=1", 1, 0) == 0  # Phi(1, 0) = (1, 0) is on the edge u = 1


def test_float_classifier_on_dense_layer_samples():
    """Points Phi(y) for y inside layer 0 / layer 1, away from the boundaries, are on the right
    side of Gamma (the inner boundary of layer 0) and of Gamma / lam (its outer boundary)."""
    from ccproof.inverse import characteristic_map

    rng = np.random.default_rng(11)
    for k in (3, 5, 6, 8, 20, 100):
        f = FloatImplicit(k, "P1:s=0")
        lam = subdominant_eigenvalue(k, "float")
        u = rng.uniform(0.5 + 1e-6, 1 - 1e-6, 4000)
        v = rng.uniform(0, 1, 4000) * u
        for layer in (0, 1, 2):
            x, y = characteristic_map(k, u * 0.5**layer, v * 0.5**layer)
            inside_gamma = f.side(x, y)
            assert np.all(inside_gamma == (1 if layer == 0 else -1))
            outer = f.side(lam * x, lam * y)
            assert np.all(outer == -1)


def test_bad_edge_and_arithmetic():
    with pytest.raises(CCProofError):
        implicit_polynomial(5, "P4:s=0")
    with pytest.raises(CCProofError):
        implicit_polynomial(5, "P1:s=0", "double")
    with pytest.raises(CCProofError):
        rational_nets(Fraction(1, 3), Fraction(1, 2))
    with pytest.raises(CCProofError):
        implicit_polynomial(2, "P1:s=0")
