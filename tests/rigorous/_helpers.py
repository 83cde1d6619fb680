"""Shared helpers for the rigorous-layer tests: sympy is the independent reference."""

import random
from math import comb

import sympy as sp
from flint import fmpq

from ccproof.certify.poly import Poly

SYMS = sp.symbols("x0:4")


def q2s(c):
    """fmpq -> sympy Rational."""
    return sp.Rational(int(c.p), int(c.q))


def s2q(r):
    """sympy Rational -> fmpq."""
    r = sp.Rational(r)
    return fmpq(int(r.p), int(r.q))


def to_sympy(p):
    """Exact Poly -> sympy expression in x0..x3."""
    xs = SYMS[: p.nvars]
    return sp.Add(*[q2s(c) * sp.Mul(*[x**k for x, k in zip(xs, e)]) for e, c in p.terms().items()])


def from_sympy(expr, nvars):
    xs = SYMS[:nvars]
    poly = sp.Poly(sp.expand(expr), *xs)
    return Poly({tuple(m): s2q(c) for m, c in poly.terms()}, nvars)


def bernstein_to_sympy(form):
    """Expand sum_k b_k prod_i B_{k_i, n_i}((x_i - lo_i)/(hi_i - lo_i)) with sympy (exact form)."""
    xs = SYMS[: form.nvars]
    ts = [(x - q2s(lo)) / (q2s(hi) - q2s(lo)) for x, (lo, hi) in zip(xs, form.box)]
    total = 0
    idx = [()]
    for n in form.shape:
        idx = [e + (k,) for e in idx for k in range(n)]
    for e, b in zip(idx, form.coeffs):
        term = q2s(b)
        for t, k, n in zip(ts, e, form.shape):
            term *= comb(n - 1, k) * t**k * (1 - t) ** (n - 1 - k)
        total += term
    return sp.expand(total)


def random_poly(rng, degrees, lo=-20, hi=20, denom=7):
    terms = {}
    idx = [()]
    for d in degrees:
        idx = [e + (k,) for e in idx for k in range(d + 1)]
    for e in idx:
        terms[e] = fmpq(rng.randint(lo, hi), rng.randint(1, denom))
    return Poly(terms, len(degrees))


def rng(seed):
    return random.Random(seed)
