"""Bernstein forms: sympy expansion of the basis, de Casteljau, enclosures, det J."""

import importlib.util
import pathlib
from math import comb

import flint
import pytest
import sympy as sp
from flint import arb, fmpq
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from ccproof.certify.poly import Poly, ball_contains, bernstein_coefficients, certainly_positive, to_poly
from ccproof.certify.prover import lower_bound
from ccproof.rigorous import (
    BernsteinForm,
    exact_fmpq,
    jacobian_determinant,
    range_enclosure,
)

_spec = importlib.util.spec_from_file_location(
    "rig_helpers", pathlib.Path(__file__).with_name("_helpers.py")
)
H = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(H)

X = H.SYMS
HALF = fmpq(1, 2)


def _sympy_equal(form, poly):
    """The sympy expansion of the Bernstein sum is exactly the polynomial."""
    return sp.expand(H.bernstein_to_sympy(form) - H.to_sympy(poly)) == 0


# ---------------------------------------------------------------------------- conversion


@pytest.mark.parametrize(
    "degrees, box, elevate",
    [
        ((5,), [(0, 1)], None),
        ((3, 4), [(0, 1), (0, 1)], None),
        ((3, 4), [(fmpq(1, 4), fmpq(3, 4)), (-1, fmpq(1, 3))], None),
        ((3, 2), [(0, 1), (fmpq(1, 2), 1)], (5, 4)),
        ((2, 1, 2), [(0, 1), (-2, 2), (fmpq(1, 8), fmpq(1, 4))], None),
        ((2, 2, 1, 1), [(0, fmpq(1, 2)), (0, 1), (fmpq(1, 3), 1), (0, 1)], (2, 3, 1, 2)),
    ],
)
def test_bernstein_expansion_equals_polynomial_exactly(degrees, box, elevate):
    p = H.random_poly(H.rng(len(degrees) * 10 + degrees[0]), degrees)
    f = bernstein_coefficients(p, box, elevate)
    assert f.prec is None and all(isinstance(c, fmpq) for c in f.coeffs)
    assert f.degrees == (elevate or degrees)
    assert _sympy_equal(f, p)
    # round trip back to the power basis
    assert to_poly(f) == p


def test_bernstein_of_a_known_polynomial():
    # x^2 on [0,1] in degree 2: coefficients 0, 0, 1; degree 3: 0, 0, 1/3, 1
    x = Poly.variable(0, 1)
    assert bernstein_coefficients(x**2).coeffs == [0, 0, 1]
    assert bernstein_coefficients(x**2, degrees=(3,)).coeffs == [0, 0, fmpq(1, 3), 1]
    # 1 has all Bernstein coefficients 1 (partition of unity) in every degree
    one = Poly.constant(1, 2)
    assert bernstein_coefficients(one, degrees=(3, 2)).coeffs == [1] * 12


@pytest.mark.parametrize("prec", [64, 128, 256])
def test_arb_conversion_encloses_exact_and_is_tight(prec):
    p = H.random_poly(H.rng(prec), (12, 12))
    box = [(fmpq(1, 4), fmpq(1, 2)), (0, fmpq(1, 8))]
    exact = bernstein_coefficients(p, box)
    ball = bernstein_coefficients(p.to_arb(prec), box)
    assert ball.prec == prec and ball.box == exact.box
    scale = max(abs(c) for c in p.coeffs) + 1
    tol = fmpq(1, 2 ** (prec - 20)) * scale
    for b, e in zip(ball.coeffs, exact.coeffs):
        assert ball_contains(b, e)
        assert exact_fmpq(b.rad()) <= tol
    assert flint.ctx.prec == 53


# ---------------------------------------------------------------------------- subdivision


def test_repeated_arb_splits_stay_tight():
    p = H.random_poly(H.rng(3), (12, 12), lo=-99, hi=99, denom=99)
    f, fe = bernstein_coefficients(p.to_arb(128)), bernstein_coefficients(p)
    scale = max(abs(c) for c in fe.coeffs)
    for level in range(12):
        side = level % 3 % 2
        f, fe = f.split(level % 2)[side], fe.split(level % 2)[side]
    assert f.box == fe.box and f.box[0][1] - f.box[0][0] == fmpq(1, 64)
    assert all(ball_contains(b, e) for b, e in zip(f.coeffs, fe.coeffs))
    assert max(exact_fmpq(b.rad()) for b in f.coeffs) <= scale / 2 ** (128 - 20)



@pytest.mark.parametrize("degrees", [(4,), (3, 5), (2, 3, 2), (2, 1, 2, 1)])
def test_split_equals_direct_conversion_on_halves(degrees):
    p = H.random_poly(H.rng(sum(degrees) + 100), degrees)
    box = [(fmpq(-1, 2), fmpq(3, 2))] + [(0, 1)] * (len(degrees) - 1)
    f = bernstein_coefficients(p, box)
    for axis in range(len(degrees)):
        lo, hi = f.split(axis)
        (a, b) = f.box[axis]
        m = (a + b) / 2
        box_lo = list(f.box)
        box_lo[axis] = (a, m)
        box_hi = list(f.box)
        box_hi[axis] = (m, b)
        assert lo.box == tuple(box_lo) and hi.box == tuple(box_hi)
        assert lo.coeffs == bernstein_coefficients(p, box_lo).coeffs
        assert hi.coeffs == bernstein_coefficients(p, box_hi).coeffs
        # the ball split encloses the exact one
        blo, bhi = BernsteinForm(f.shape, f.coeffs, f.box, 80).split(axis)
        assert all(ball_contains(x, y) for x, y in zip(blo.coeffs + bhi.coeffs, lo.coeffs + hi.coeffs))


def test_split_at_general_fraction_and_restrict():
    p = H.random_poly(H.rng(21), (4, 3))
    f = bernstein_coefficients(p, [(0, 2), (1, 2)])
    lo, hi = f.split(1, fmpq(1, 3))
    assert lo.box[1] == (1, fmpq(4, 3))
    assert lo.coeffs == bernstein_coefficients(p, lo.box).coeffs
    assert hi.coeffs == bernstein_coefficients(p, hi.box).coeffs
    sub = [(fmpq(1, 5), fmpq(7, 4)), (fmpq(5, 4), fmpq(3, 2))]
    assert f.restrict(sub).coeffs == bernstein_coefficients(p, sub).coeffs
    with pytest.raises(ValueError):
        f.restrict([(0, 3), (1, 2)])


def test_elevation_and_derivative_exact():
    p = H.random_poly(H.rng(23), (3, 2))
    box = [(fmpq(1, 2), 1), (0, 2)]
    f = bernstein_coefficients(p, box)
    assert f.elevate((5, 4)).coeffs == bernstein_coefficients(p, box, (5, 4)).coeffs
    for axis in range(2):
        assert f.diff(axis).coeffs == bernstein_coefficients(p.diff(axis), box).coeffs


def test_bernstein_product_matches_power_product():
    r = H.rng(29)
    p, q = H.random_poly(r, (3, 2)), H.random_poly(r, (2, 4))
    box = [(fmpq(-1, 3), 1), (fmpq(1, 4), fmpq(1, 2))]
    fp, fq = bernstein_coefficients(p, box), bernstein_coefficients(q, box)
    assert (fp * fq).coeffs == bernstein_coefficients(p * q, box).coeffs
    assert (fp - fq).coeffs == bernstein_coefficients(p - q, box, (3, 4)).coeffs
    assert (2 - fp * fmpq(1, 3)).coeffs == bernstein_coefficients(2 - p / 3, box).coeffs
    balls = BernsteinForm(fp.shape, fp.coeffs, fp.box, 90) * fq
    assert all(ball_contains(b, e) for b, e in zip(balls.coeffs, (fp * fq).coeffs))
    with pytest.raises(ValueError):
        fp * bernstein_coefficients(q)  # different boxes


# ---------------------------------------------------------------------------- enclosure


def _grid(box, m):
    (a, b), (c, d) = box
    return [
        (a + (b - a) * fmpq(i, m), c + (d - c) * fmpq(j, m)) for i in range(m + 1) for j in range(m + 1)
    ]


coeff = st.integers(-50, 50)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    dx=st.integers(0, 4),
    dy=st.integers(0, 4),
    data=st.data(),
    lo=st.fractions(-2, 2, max_denominator=8),
    width=st.fractions(0, 3, max_denominator=8).filter(lambda w: w > 0),
)
def test_range_enclosure_contains_sampled_values(dx, dy, data, lo, width):
    coeffs = data.draw(st.lists(coeff, min_size=(dx + 1) * (dy + 1), max_size=(dx + 1) * (dy + 1)))
    p = Poly.from_dense((dx + 1, dy + 1), coeffs)
    lo = fmpq(lo.numerator, lo.denominator)
    width = fmpq(width.numerator, width.denominator)
    box = [(lo, lo + width), (-lo, -lo + width)]
    f = bernstein_coefficients(p, box)
    e_lo, e_hi = range_enclosure(f)
    b_lo, b_hi = range_enclosure(bernstein_coefficients(p.to_arb(64), box))
    points = _grid(box, 6)
    unit = st.fractions(0, 1, max_denominator=50)
    for u, v in data.draw(st.lists(st.tuples(unit, unit), max_size=5)):
        points.append(
            (
                lo + width * fmpq(u.numerator, u.denominator),
                -lo + width * fmpq(v.numerator, v.denominator),
            )
        )
    for pt in points:
        v = p(*pt)
        assert e_lo <= v <= e_hi
        assert exact_fmpq(b_lo) <= v <= exact_fmpq(b_hi)
    # the ball enclosure contains the exact one
    assert exact_fmpq(b_lo) <= e_lo and e_hi <= exact_fmpq(b_hi)
    # corner coefficients are the corner values
    assert f.coeffs[0] == p(lo, -lo) and f.coeffs[-1] == p(lo + width, -lo + width)


def _zoom(f, target):
    """The dyadic half along every axis that contains ``target`` (never a dyadic number here)."""
    for axis in range(f.nvars):
        a, b = f.split(axis)
        f = a if target[axis] < a.box[axis][1] else b
    return f


def test_range_enclosure_gap_shrinks_quadratically():
    # p has a strict minimum 0 at the non-dyadic point (1/3, 2/3): the true minimum on every
    # small box around it is 0, so the gap of the coefficient bound is exactly -min coeff.
    a, b = fmpq(1, 3), fmpq(2, 3)
    x, y = Poly.variable(0, 2) - a, Poly.variable(1, 2) - b
    r = H.rng(31)
    p = x**2 + 2 * y**2 + x * y / 2
    for i in range(5):
        for j in range(5):
            if 3 <= i + j and i <= 4 and j <= 4:
                p = p + fmpq(r.randint(-5, 5), 20) * x**i * y**j
    p = Poly(p.terms(), 2)  # degrees (4, 4) in the original variables
    f = bernstein_coefficients(p)
    for _ in range(3):
        f = _zoom(f, (a, b))
    gaps = []
    for _level in range(7):
        e_lo, e_hi = range_enclosure(f)
        samples = [p(*pt) for pt in _grid(f.box, 4)]
        assert e_lo <= 0 <= min(samples) and max(samples) <= e_hi
        gaps.append(-e_lo)
        f = _zoom(f, (a, b))
    ratios = [gaps[i] / gaps[i + 1] for i in range(len(gaps) - 1)]
    assert gaps[-1] > 0
    # 4 per halving (a linear, first-order bound would give 2)
    for q in ratios[-4:]:
        assert 3 < q < 5, ratios


def test_control_net_converges_quadratically():
    # max |b_k - p(Greville point k)| = O(h^2) for a generic polynomial and point
    p = H.random_poly(H.rng(37), (4, 3), lo=-9, hi=9, denom=3)
    f = bernstein_coefficients(p)
    target = (fmpq(2, 7), fmpq(3, 5))
    errors = []
    for _level in range(8):
        (a0, a1), (b0, b1) = f.box
        n0, n1 = f.degrees
        greville = [
            (a0 + (a1 - a0) * fmpq(i, n0), b0 + (b1 - b0) * fmpq(j, n1))
            for i in range(n0 + 1)
            for j in range(n1 + 1)
        ]
        errors.append(max(abs(c - p(*g)) for c, g in zip(f.coeffs, greville)))
        f = _zoom(f, target)
    ratios = [errors[i] / errors[i + 1] for i in range(len(errors) - 1)]
    for q in ratios[-4:]:
        assert fmpq(7, 2) < q < fmpq(9, 2), ratios


def test_lower_bound_and_exact_fmpq():
    with flint.ctx.workprec(60):
        third = arb(1) / 3
    lb = lower_bound([third, arb(2)])
    assert isinstance(lb, fmpq) and lb < fmpq(1, 3) and fmpq(1, 3) - lb < fmpq(1, 2**55)
    assert exact_fmpq(arb(3) / 4) == fmpq(3, 4)
    assert exact_fmpq(third) is None
    lo, hi = range_enclosure([arb("nan"), arb(1)])
    assert not lo.is_finite() and lo < 0 and hi > 0


# ---------------------------------------------------------------------------- positivity


def test_certainly_positive():
    assert certainly_positive([arb(1), arb("0.5 +/- 0.25")])
    assert not certainly_positive([arb(1), arb("0 +/- 0.01")])  # contains 0
    assert not certainly_positive([arb("0.01 +/- 0.01")])  # touches 0
    assert not certainly_positive([arb(1), arb("nan")])
    assert not certainly_positive([arb.pos_inf()])
    assert not certainly_positive([arb(1), arb("1 +/- inf")])
    assert not certainly_positive([])
    assert certainly_positive([fmpq(1, 10**30)])
    assert not certainly_positive([fmpq(0), fmpq(1)])
    assert certainly_positive(arb(2)) and not certainly_positive(fmpq(-1))
    x = Poly.variable(0, 1)
    f = bernstein_coefficients((x - fmpq(1, 2)) ** 2 + fmpq(1, 100))  # > 0 but coefficients are not
    assert not certainly_positive(f)
    for _ in range(3):  # subdivision makes the certificate succeed
        f = [g for h in ([f] if isinstance(f, BernsteinForm) else f) for g in h.split(0)]
    assert all(certainly_positive(g) for g in f)
    assert all(certainly_positive(BernsteinForm(g.shape, g.coeffs, g.box, 53)) for g in f)


# ---------------------------------------------------------------------------- det J


def _bicubic_map(seed):
    """A bicubic perturbation of the identity map, exact, given by random Bezier control nets."""
    r = H.rng(seed)
    x, y = Poly.variable(0, 2), Poly.variable(1, 2)
    g1 = x + fmpq(1, 10) * H.random_poly(r, (3, 3), lo=-3, hi=3, denom=5)
    g2 = y + fmpq(1, 10) * H.random_poly(r, (3, 3), lo=-3, hi=3, denom=5)
    return g1, g2


def test_det_jacobian_bernstein_reproduces_sympy():
    g1, g2 = _bicubic_map(41)
    box = [(0, fmpq(1, 2)), (fmpq(1, 4), fmpq(3, 4))]
    det = jacobian_determinant([g1, g2])
    assert det.degrees == (5, 5)  # (2,3)*(3,2) + (3,2)*(2,3)
    f = bernstein_coefficients(det, box)
    sym = sp.Matrix([H.to_sympy(g1), H.to_sympy(g2)]).jacobian(X[:2]).det()
    assert sp.expand(H.bernstein_to_sympy(f) - sym) == 0
    # the same coefficients from Bernstein arithmetic (derivatives and products on the box)
    fg = jacobian_determinant(
        [bernstein_coefficients(g1, box), bernstein_coefficients(g2, box)]
    )
    assert fg.coeffs == bernstein_coefficients(det, box, fg.degrees).coeffs
    # balls at 128 bits enclose them, and the map is a small perturbation of the identity
    fb = bernstein_coefficients(jacobian_determinant([g1.to_arb(128), g2.to_arb(128)]), box)
    assert all(ball_contains(b, e) for b, e in zip(fb.coeffs, f.coeffs))
    assert certainly_positive(fb) == certainly_positive(f)


def test_det_jacobian_of_a_known_map():
    # G(x, y) = (x + x^3 y^3 / 3, y - x y^2): det J = 1 - 2xy + x^2 y^3 - 2/3 x^3 y^3... check by hand
    x, y = Poly.variable(0, 2), Poly.variable(1, 2)
    g1 = x + x**3 * y**3 / 3
    g2 = y - x * y**2
    det = jacobian_determinant([g1, g2])
    # (1 + x^2 y^3)(1 - 2xy) - (x^3 y^2)(-y^2) = 1 - 2xy + x^2 y^3 - 2 x^3 y^4 + x^3 y^4
    expect = 1 - 2 * x * y + x**2 * y**3 - x**3 * y**4
    assert det == expect
    f = bernstein_coefficients(det, [(0, fmpq(1, 4)), (0, fmpq(1, 4))])
    assert certainly_positive(f)
    assert lower_bound(f) == min(f.coeffs)
    # det J = 1 at the origin, so every box containing it has min coefficient <= 1
    assert lower_bound(f) <= 1


def test_four_variable_conversion_and_split():
    r = H.rng(43)
    p = H.random_poly(r, (3, 3, 2, 2))
    f = bernstein_coefficients(p, [(0, 1), (0, 1), (0, fmpq(1, 2)), (0, 1)])
    assert to_poly(f) == p
    lo, hi = f.split(2)
    assert hi.coeffs == bernstein_coefficients(p, hi.box).coeffs


@pytest.mark.slow
def test_high_degree_bernstein_matches_sympy():
    p = H.random_poly(H.rng(47), (12, 12))
    f = bernstein_coefficients(p, [(fmpq(1, 8), fmpq(1, 4)), (fmpq(3, 4), 1)])
    assert _sympy_equal(f, p)


def test_bernstein_form_validation():
    with pytest.raises(ValueError):
        bernstein_coefficients(Poly.variable(0, 2), degrees=(0, 1))  # below the degree
    with pytest.raises(ValueError):
        BernsteinForm((2, 2), [1, 2, 3])
    with pytest.raises(TypeError):
        BernsteinForm((1,), [0.5])
    with pytest.raises(TypeError):
        bernstein_coefficients(Poly.variable(0, 1), [(0.0, 1)])
    f = bernstein_coefficients(Poly.variable(0, 1))
    with pytest.raises(ValueError):
        f.split(0, fmpq(1))
    with pytest.raises(TypeError):
        f * 0.5
    assert comb(4, 2) == 6  # keep the import honest


def test_bezier_net_to_poly_and_det_j_of_a_bicubic_patch():
    # a bicubic Bezier patch given by its control net on the box [1/2, 1] x [0, 1/2]
    r = H.rng(53)
    box = [(fmpq(1, 2), 1), (0, fmpq(1, 2))]
    nets = [
        [fmpq(i, 3) + fmpq(r.randint(-2, 2), 40) for i in range(4) for _ in range(4)],
        [fmpq(j, 3) + fmpq(r.randint(-2, 2), 40) for _ in range(4) for j in range(4)],
    ]
    patch = [BernsteinForm((4, 4), net, box) for net in nets]
    polys = [to_poly(f) for f in patch]
    for f, p in zip(patch, polys):
        assert _sympy_equal(f, p)
        assert bernstein_coefficients(p, box).coeffs == f.coeffs
    det_b = jacobian_determinant(patch)
    det_p = jacobian_determinant(polys)
    assert det_b.coeffs == bernstein_coefficients(det_p, box, det_b.degrees).coeffs
    # ball nets (as read from a table) enclose the exact determinant's coefficients
    balls = jacobian_determinant([BernsteinForm(f.shape, f.coeffs, f.box, 100) for f in patch])
    assert all(ball_contains(b, e) for b, e in zip(balls.coeffs, det_b.coeffs))
    mid = Poly.from_dense(polys[0].shape, polys[0].coeffs).to_arb(64).midpoint()
    assert mid.is_exact
    assert all(abs(a - b) <= (1 + abs(b)) / 2**62 for a, b in zip(mid.coeffs, polys[0].coeffs))
