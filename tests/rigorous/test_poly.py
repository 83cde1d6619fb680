"""Poly arithmetic against sympy (independent exact reference) and ball containment."""

import importlib.util
import pathlib

import flint
import pytest
import sympy as sp
from flint import arb, fmpq

from ccproof.certify.poly import Poly, ball_contains
from ccproof.rigorous import jacobian_determinant

_spec = importlib.util.spec_from_file_location(
    "rig_helpers", pathlib.Path(__file__).with_name("_helpers.py")
)
H = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(H)

X = H.SYMS


@pytest.mark.parametrize("degrees", [(3,), (2, 3), (1, 2, 2), (2, 1, 1, 2)])
def test_ring_operations_match_sympy(degrees):
    r = H.rng(sum(degrees))
    p, q = H.random_poly(r, degrees), H.random_poly(r, degrees[::-1])
    gens = X[: len(degrees)]

    def S(poly):
        return sp.Poly(H.to_sympy(poly), *gens)

    sp_p, sp_q = S(p), S(q)
    assert S(p + q) == sp_p + sp_q
    assert S(p - q) == sp_p - sp_q
    assert S(p * q) == sp_p * sp_q
    assert S(p**3) == sp_p**3
    assert S(fmpq(2, 3) * p - 5) == sp_p * sp.Rational(2, 3) - 5
    assert S(3 - p / 4) == 3 - sp_p * sp.Rational(1, 4)
    for axis in range(len(degrees)):
        assert S(p.diff(axis)) == sp_p.diff(gens[axis])


def test_evaluate_matches_sympy_and_balls_enclose():
    r = H.rng(5)
    p = H.random_poly(r, (3, 4))
    pt = (fmpq(2, 7), fmpq(-5, 3))
    exact = p(*pt)
    assert H.q2s(exact) == H.to_sympy(p).subs({X[0]: H.q2s(pt[0]), X[1]: H.q2s(pt[1])})
    ball = p.to_arb(80)(*pt)
    assert ball_contains(ball, exact)
    # exact polynomial at a ball point
    wide = p.evaluate([arb(pt[0], fmpq(1, 1000)), pt[1]], prec=64)
    assert ball_contains(wide, exact) and ball_contains(wide, p(pt[0] + fmpq(1, 1000), pt[1]))


def _sympy_compose(w, phi, nvars):
    """w(phi_0, phi_1, ...) with sympy's own polynomial arithmetic (sp.Poly, exact)."""
    gens = X[:nvars]
    qs = [sp.Poly(H.to_sympy(q), *gens) for q in phi]
    total = sp.Poly(0, *gens)
    for e, c in w.terms().items():
        term = sp.Poly(H.q2s(c), *gens)
        for q, k in zip(qs, e):
            term = term * q**k
        total = total + term
    return total


def test_compose_matches_sympy():
    r = H.rng(11)
    w = H.random_poly(r, (3, 3))  # a bivariate cubic piece
    phi = [H.random_poly(r, (3, 3)), H.random_poly(r, (3, 3))]  # a bicubic map
    got = w.compose(phi)
    assert got.degrees == (18, 18)
    assert sp.Poly(H.to_sympy(got), *X[:2]) == _sympy_compose(w, phi, 2)
    # composition into a different number of variables (here 3)
    t = [H.random_poly(r, (1, 1, 2)), H.random_poly(r, (2, 0, 1))]
    assert sp.Poly(H.to_sympy(w.compose(t)), *X[:3]) == _sympy_compose(w, t, 3)
    # ball composition encloses the exact one
    assert w.to_arb(100).compose([q.to_arb(100) for q in phi]).contains(got)


def test_affine_matches_sympy_on_each_axis():
    r = H.rng(3)
    p = H.random_poly(r, (3, 2))
    a, b = fmpq(-1, 3), fmpq(5, 4)
    got = p.affine(0, a, b)
    expect = H.to_sympy(p).subs(X[0], H.q2s(a) + (H.q2s(b) - H.q2s(a)) * X[0])
    assert sp.expand(H.to_sympy(got) - expect) == 0
    got = p.affine(0, fmpq(1, 4), fmpq(1, 2)).affine(1, -2, 3)
    expect = H.to_sympy(p).subs(
        {X[0]: sp.Rational(1, 4) + sp.Rational(1, 4) * X[0], X[1]: -2 + 5 * X[1]}, simultaneous=True
    )
    assert sp.expand(H.to_sympy(got) - expect) == 0
    assert p.to_arb(90).affine(0, fmpq(1, 4), fmpq(1, 2)).affine(1, -2, 3).contains(got)


def test_jacobian_determinant_matches_sympy():
    r = H.rng(7)
    g = [H.random_poly(r, (3, 3)), H.random_poly(r, (3, 3))]
    det = jacobian_determinant(g)
    jac = sp.Matrix([H.to_sympy(q) for q in g]).jacobian([X[0], X[1]])
    assert sp.expand(H.to_sympy(det) - jac.det()) == 0
    # 3 components in 4 variables, derivatives w.r.t. variables 1, 2, 3
    g3 = [H.random_poly(r, (1, 1, 1, 1)) for _ in range(3)]
    det3 = jacobian_determinant(g3, variables=(1, 2, 3))
    jac3 = sp.Matrix([H.to_sympy(q) for q in g3]).jacobian([X[1], X[2], X[3]])
    assert sp.expand(H.to_sympy(det3) - jac3.det()) == 0


def test_ball_arithmetic_encloses_exact_and_keeps_global_precision():
    r = H.rng(9)
    p, q = H.random_poly(r, (4, 4)), H.random_poly(r, (3, 5))
    before = flint.ctx.prec
    pb, qb = p.to_arb(64), q.to_arb(128)
    prod = pb * qb
    assert prod.prec == 128 and prod.contains(p * q)
    assert (pb - q).contains(p - q) and (pb - q).prec == 64
    assert (pb**2).contains(p**2)
    assert flint.ctx.prec == before


def test_trim_terms_and_equality():
    x, y = Poly.variable(0, 2), Poly.variable(1, 2)
    p = (x + y) ** 2 - x * x - 2 * x * y
    assert p.degrees == (2, 2)
    assert Poly(p.terms(), 2).degrees == (0, 2)
    assert p == y**2
    assert p.terms() == {(0, 2): fmpq(1)}
    assert Poly.constant(3, 2) == 3
    with pytest.raises(TypeError):
        _ = p.to_arb(53) == p


@pytest.mark.parametrize(
    "bad",
    [
        lambda: Poly({(0, 1): 0.5}),
        lambda: Poly.variable(0, 2) * 0.5,
        lambda: Poly.variable(0, 2) + 1.0,
        lambda: Poly.variable(0, 2).affine(0, 0.0, 1),
        lambda: Poly.variable(0, 2)(0.5, 1),
    ],
)
def test_floats_are_refused(bad):
    with pytest.raises(TypeError):
        bad()


def test_input_validation():
    with pytest.raises(ValueError):
        Poly({(0, 0, 0, 0, 1): 1})  # five variables
    with pytest.raises(ValueError):
        Poly({(0, -1): 1})
    with pytest.raises(TypeError):
        Poly({(0, 1): arb(1)})  # arb in an exact polynomial
    with pytest.raises(TypeError):
        Poly.variable(0, 2) * arb(2)
    with pytest.raises(ValueError):
        Poly.variable(0, 2).evaluate([arb(1), 1])  # exact poly at a ball needs prec
    with pytest.raises(ValueError):
        Poly.variable(0, 2).to_arb(1)


def test_truncate_keeps_a_ball_that_contains_zero():
    """(1 + [+-1e-6] z^2).truncate(1): the z^2 term's ball contains 0 but is not 0; it must go into the
    remainder (arb's `!=` means "certainly different", so a test `x != 0` would drop it)."""
    from flint import arb, fmpq

    z = Poly.variable(0, 1, 64)
    p = 1 + arb(0, fmpq(1, 10**6)) * z**2
    r = p.truncate(1)
    c0 = r.coefficient((0,))
    assert c0.contains(1) and c0.rad() >= fmpq(1, 10**6)
    for zv in (fmpq(-1), fmpq(1, 3), fmpq(1)):  # encloses p pointwise on [-1, 1]: p(z) in [1 - 1e-6 z^2, 1 + ...]
        assert c0.contains(1 + fmpq(1, 10**6) * zv**2) and c0.contains(1 - fmpq(1, 10**6) * zv**2)


def test_truncate_encloses_random_ball_polynomials():
    import random

    from flint import arb, ctx, fmpq

    rng = random.Random(7)
    with ctx.workprec(64):
        for _ in range(50):
            coeffs = {(i, j): arb(fmpq(rng.randint(-9, 9), 7), fmpq(rng.randint(0, 3), 10**rng.randint(1, 9)))
                      for i in range(5) for j in range(3)}
            p = Poly(coeffs, 2, 64)
            r = p.truncate(2)
            for _ in range(5):
                zv, sv = fmpq(rng.randint(-8, 8), 8), fmpq(rng.randint(0, 8), 8)
                # every polynomial in the family of p evaluated at (zv, sv): take the coefficients' mid-points
                mid = sum((arb(c.mid()) * zv**i * sv**j for (i, j), c in coeffs.items()), arb(0))
                assert r(zv, sv).contains(mid)
