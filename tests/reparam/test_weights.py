"""The weight b of bmz04 section 4.2 (docs/readings.md R5) against an exact sympy construction.

Expected values: B built from its truncated-power formula in sympy rationals (not the piecewise
formulas of the implementation), one-sided derivatives computed exactly by sympy, and the
partition of unity of the integer translates of B.
"""

from fractions import Fraction

import numpy as np
import pytest
import sympy as sp

from ccproof.reparam.weights import bump, weight_radial, weight_tensor

X = sp.Symbol("x", real=True)


def _B(z):
    """Centred uniform cubic B-spline (support [-2, 2]) by truncated powers."""
    return sum(sp.Rational((-1) ** j * sp.binomial(4, j), 6) * sp.Max(0, z + 2 - j) ** 3 for j in range(5))


B_EXPR = _B(6 * X + 1) + _B(6 * X) + _B(6 * X - 1)
BREAKS = [sp.Rational(0), sp.Rational(1, 6), sp.Rational(1, 3), sp.Rational(1, 2)]


def _piece(a, b):
    """The polynomial of b on (a, b): B_EXPR with every Max resolved at the midpoint."""
    mid = (a + b) / 2
    expr = B_EXPR.replace(lambda e: isinstance(e, sp.Max), lambda e: e if e.args[1].subs(X, mid) > 0 else 0)
    expr = expr.replace(lambda e: isinstance(e, sp.Max), lambda e: e.args[1])
    return sp.expand(expr)


PIECES = [_piece(BREAKS[i], BREAKS[i + 1]) for i in range(3)] + [sp.Integer(0)]


def test_first_piece_is_one_minus_36x3():
    assert sp.expand(PIECES[0] - (1 - 36 * X**3)) == 0
    assert PIECES[3] == 0


@pytest.mark.parametrize("i", [1, 2, 3])
def test_c2_at_breakpoints_exactly(i):
    x0 = BREAKS[i]
    for d in range(3):
        left = sp.diff(PIECES[i - 1], X, d).subs(X, x0)
        right = sp.diff(PIECES[i], X, d).subs(X, x0)
        assert left == right, (x0, d)
    # and not C3 (the breakpoints are genuine)
    assert sp.diff(PIECES[i - 1], X, 3).subs(X, x0) != sp.diff(PIECES[i], X, 3).subs(X, x0)


def test_float_values_at_breakpoints_and_rationals():
    pts = BREAKS + [sp.Rational(p, q) for q in (7, 12, 48, 97) for p in range(0, q // 2 + 2)]
    for x0 in pts:
        exact = B_EXPR.subs(X, x0)
        piece = min(int(6 * x0), 3)
        for d in range(3):
            want = sp.diff(PIECES[piece], X, d).subs(X, x0)
            got = bump(np.array([float(x0)]), 2)[d][0]
            assert abs(got - float(want)) <= 4e-16 * max(1.0, 36 * abs(float(want))) * 8, (x0, d, got, want)
        assert abs(bump(np.array([float(x0)]))[0][0] - float(exact)) <= 2.3e-16
    # the breakpoint values themselves, exactly
    want = [1.0, float(Fraction(5, 6)), float(Fraction(1, 6)), 0.0]
    assert bump(np.array([0.0, 1 / 6, 1 / 3, 0.5]))[0].tolist() == want


def test_even_and_support():
    y = np.linspace(0, 1, 1001)
    x = np.concatenate([-y[::-1], y])
    b0, b1, b2 = bump(x, 2)
    assert np.array_equal(b0, b0[::-1]) and np.array_equal(b1, -b1[::-1]) and np.array_equal(b2, b2[::-1])
    assert (b0[np.abs(x) >= 0.5] == 0).all() and (b0[np.abs(x) < 0.5] > 0).all()
    assert (b1[(x > 0)] <= 0).all()  # decreasing on [0, 1/2]


def test_partition_of_unity():
    """sum_m b(x - m/2) = sum_i B(6x - i) = 1; on [0, 1/2]: b(x) + b(1/2 - x) = 1."""
    x = np.linspace(0, 0.5, 100001)
    s = bump(x)[0] + bump(0.5 - x)[0]
    assert np.abs(s - 1).max() <= 4.5e-16  # two rounding errors
    assert bump(np.array([0.25]))[0][0] == 0.5


def test_derivatives_by_differences():
    rng = np.random.default_rng(1)
    x = rng.uniform(-0.6, 0.6, 2000)
    h = 1e-6
    b = bump(x, 2)
    assert np.abs((bump(x + h)[0] - bump(x - h)[0]) / (2 * h) - b[1]).max() < 1e-7
    assert np.abs((bump(x + h, 1)[1] - bump(x - h, 1)[1]) / (2 * h) - b[2]).max() < 1e-6


@pytest.mark.parametrize("weight", [weight_tensor, weight_radial])
def test_weights_derivatives(weight):
    rng = np.random.default_rng(2)
    s, t = rng.uniform(1e-5, 0.6, 3000), rng.uniform(1e-5, 0.6, 3000)
    s[:2], t[:2] = 0.0, [0.0, 0.1]
    W = weight(s, t, 2)
    h = 1e-6
    for i, (ds, dt) in enumerate(((h, 0), (0, h))):
        p = weight(s[2:] + ds, t[2:] + dt, 1)
        m = weight(s[2:] - ds, t[2:] - dt, 1)
        W2 = [w[2:] for w in W]
        assert np.abs((p[0] - m[0]) / (2 * h) - W2[1 + i]).max() < 1e-6
        assert np.abs((p[1] - m[1]) / (2 * h) - W2[3 + i]).max() < 1e-5
        assert np.abs((p[2] - m[2]) / (2 * h) - W2[4 + i]).max() < 1e-5
    assert W[0][0] == 1.0 and W[1][0] == 0 and W[2][0] == 0 and W[3][0] == 0 and W[5][0] == 0
    corner = (s >= 0.5) | (t >= 0.5)
    assert (W[0][corner] == 0).all()
    radial = weight is weight_radial
    if radial:
        assert (W[0][np.hypot(s, t) >= 0.5] == 0).all()
    else:
        assert np.array_equal(W[0], bump(s)[0] * bump(t)[0])
