"""TaylorForm (Taylor model in z with Bernstein coefficients in x) against exact rational evaluation.

The reference is independent of the class: random exact polynomials in the power basis, combined with
``Poly`` in exact fmpq arithmetic and evaluated exactly at random rational points; the TaylorForm of the
same expression, evaluated in arb through its own definition sum c[e,k] z^e B_k(x), must enclose the
exact value (with and without truncation) and be tight (exact inputs: radius ~ 2^-prec; truncation: the
width is at most twice the dropped terms' size).
"""

import random
from math import comb

import pytest
from flint import arb, ctx, fmpq

from ccproof.certify.poly import Poly, ball_contains, bernstein_coefficients, taylor_form
from ccproof.rigorous import TaylorForm, jacobian_determinant

PREC = 128


def random_poly(r, shape):
    terms = {}
    for e in range(shape[0]):
        for a in range(shape[1]):
            for b in range(shape[2]):
                terms[(e, a, b)] = fmpq(r.randint(-9, 9), r.randint(1, 5))
    return Poly(terms, 3)


def tf(p):
    return taylor_form(p.to_arb(PREC) if hasattr(p, "to_arb") else p, PREC)


def evaluate(f, z, x):
    """sum c[e, k] z^e B_k(x) from the definition (arb, exact point)."""
    m, n1, n2 = f.shape
    total = arb(0)
    with ctx.workprec(PREC):
        for e in range(m):
            for i in range(n1):
                for j in range(n2):
                    B = comb(n1 - 1, i) * x[0] ** i * (1 - x[0]) ** (n1 - 1 - i) * \
                        comb(n2 - 1, j) * x[1] ** j * (1 - x[1]) ** (n2 - 1 - j)
                    total += f.coeffs[(e * n1 + i) * n2 + j] * arb(z**e * B)
    return total


def points(r, n=12):
    out = [(fmpq(-1), (fmpq(0), fmpq(1))), (fmpq(1), (fmpq(1), fmpq(0)))]
    for _ in range(n):
        out.append((fmpq(r.randint(-64, 64), 64), (fmpq(r.randint(0, 64), 64), fmpq(r.randint(0, 64), 64))))
    return out


@pytest.mark.parametrize("seed", range(4))
def test_ring_operations_and_derivatives_enclose_the_exact_values_tightly(seed):
    r = random.Random(seed)
    p, q = random_poly(r, (2, 3, 2)), random_poly(r, (3, 2, 3))
    exact = {
        "p*q - 3": p * q - 3,
        "(p + 1/2) * p + q": (p + fmpq(1, 2)) * p + q,
        "d/dx1 (p*q)": (p * q).diff(1),
        "d/dx2 q - p": q.diff(2) - p,
        "jac": p.diff(1) * q.diff(2) - p.diff(2) * q.diff(1),
    }
    P, Q = tf(p), tf(q)
    with ctx.workprec(PREC):
        balls = {
            "p*q - 3": P * Q - 3,
            "(p + 1/2) * p + q": (P + fmpq(1, 2)) * P + Q,
            "d/dx1 (p*q)": (P * Q).diff(1),
            "d/dx2 q - p": Q.diff(2) - P,
            "jac": jacobian_determinant([P, Q], (1, 2)),
        }
    for name, e in exact.items():
        for z, x in points(r):
            v = e.evaluate([z, *x])
            b = evaluate(balls[name], z, x)
            assert ball_contains(b, v), (name, z, x)
            assert float(b.rad()) < 1e-25 * (1 + abs(float(v))), (name, b)  # exact inputs: rounding only


@pytest.mark.parametrize("seed", range(4))
def test_truncation_encloses_the_dropped_powers_and_is_tight(seed):
    r = random.Random(100 + seed)
    p = random_poly(r, (4, 3, 3))
    P = tf(p)
    for degree in (0, 1, 2):
        T = P.truncate(degree)
        assert T.shape == (degree + 1, 3, 3)
        dropped = sum((abs(c) for i, c in enumerate(P.coeffs) if i >= (degree + 1) * 9), arb(0))
        for z, x in points(r):
            v = p.evaluate([z, *x])
            b = evaluate(T, z, x)
            assert ball_contains(b, v), (degree, z, x, b, v)
            assert b.rad() <= 2 * dropped + 1e-25, (b.rad(), dropped)


def test_a_ball_containing_zero_is_kept_by_truncate():
    with ctx.workprec(PREC):
        f = TaylorForm((3, 1, 1), [arb(1), arb(0), arb(0, fmpq(1, 10**6))], PREC)
        t = f.truncate(1)
        assert t.coeffs[0].contains(arb(1) + arb(fmpq(1, 10**6))) and t.coeffs[0].contains(arb(1) - arb(fmpq(1, 10**6)))


def test_bernstein_gives_the_form_on_the_z_box():
    r = random.Random(7)
    p = random_poly(r, (3, 2, 2))
    B = tf(p).bernstein()
    assert B.box[0] == (fmpq(-1), fmpq(1))
    exactB = bernstein_coefficients(p, box=((-1, 1), (0, 1), (0, 1)))
    assert all(ball_contains(b, e) and b.rad() < 1e-30 for b, e in zip(B.coeffs, exactB.coeffs))


def test_bad_input_is_refused():
    with pytest.raises(ValueError, match="prec"):
        TaylorForm((1, 1), [1], None)
    with pytest.raises(ValueError, match="coefficients"):
        TaylorForm((2, 2), [1, 2, 3], PREC)
    f = TaylorForm.variable(1, 2, PREC)
    with pytest.raises(ValueError, match="not an x axis"):
        f.diff(0)
    with pytest.raises(ValueError, match="degree"):
        f.truncate(-1)
