"""The vectorized characteristic map against an independent exact evaluation of the nets.

Expected values: de Casteljau on the arb Bezier nets of :func:`characteristic_map_patches` with
the layer logic written out here in exact rational arithmetic; central differences for the
Jacobian; the identity for k = 4; Phi(1, 0) = (1, 0) (normalization, R3).
"""

from fractions import Fraction
from functools import lru_cache

import numpy as np
import pytest
from flint import arb, ctx, fmpq

from ccproof.algebra.specialize import characteristic_map_patches, subdominant_eigenvalue
from ccproof.errors import CCProofError
from ccproof.inverse import characteristic_map


@lru_cache(maxsize=16)
def _nets(k):
    return characteristic_map_patches(k, "bezier", "arb", 160)


def exact_phi(k, r, s):
    """Phi(r, s) in arb for exact rational r, s: find the layer and piece by exact comparisons."""
    r, s = Fraction(r), Fraction(s)
    if r == 0 and s == 0:
        return 0.0, 0.0
    n = 0
    while max(r, s) * Fraction(2) ** n > 1:
        n -= 1
    while max(r, s) * Fraction(2) ** n <= Fraction(1, 2):
        n += 1
    u, v = r * Fraction(2) ** n, s * Fraction(2) ** n
    if u >= Fraction(1, 2) and v < Fraction(1, 2):
        name, sl, tl = "P1", 2 * u - 1, 2 * v
    elif u >= Fraction(1, 2):
        name, sl, tl = "P2", 2 * u - 1, 2 * v - 1
    else:
        name, sl, tl = "P3", 2 * u, 2 * v - 1
    net = _nets(k)[name]
    with ctx.workprec(160):
        S, T = arb(fmpq(sl.numerator, sl.denominator)), arb(fmpq(tl.numerator, tl.denominator))
        B = lambda z: [(1 - z) ** 3, 3 * z * (1 - z) ** 2, 3 * z**2 * (1 - z), z**3]
        bs, bt = B(S), B(T)
        lam = subdominant_eigenvalue(k, "arb", 160) ** n
        x = lam * sum((bs[i] * bt[j] * net[i][j][0] for i in range(4) for j in range(4)), arb(0))
        y = lam * sum((bs[i] * bt[j] * net[i][j][1] for i in range(4) for j in range(4)), arb(0))
    return float(x.mid()), float(y.mid())


@pytest.mark.parametrize("k", [3, 5, 6, 8, 13, 100])
def test_against_exact_net_evaluation(k):
    rng = np.random.default_rng(k)
    r = np.r_[rng.random(60), rng.random(20) * 1e-6, rng.random(20) * 3, [1, 0.5, 0.25, 1, 0, 2**-40]]
    s = np.r_[rng.random(60), rng.random(20) * 1e-6, rng.random(20) * 3, [0, 0.5, 0.125, 1, 0.7, 0]]
    x, y = characteristic_map(k, r, s)
    for i in range(r.size):
        ex, ey = exact_phi(k, r[i], s[i])
        scale = max(1.0, abs(ex), abs(ey))
        assert abs(x[i] - ex) <= 4e-16 * scale * 4 and abs(y[i] - ey) <= 4e-16 * scale * 4, (r[i], s[i])


def test_identity_normalization_symmetry_scaling():
    rng = np.random.default_rng(0)
    r, s = rng.random(1000) * 2, rng.random(1000) * 2
    x, y = characteristic_map(4, r, s)
    assert np.array_equal(x, r) and np.array_equal(y, s)
    for k in (3, 7, 50):
        lam = subdominant_eigenvalue(k, "float")
        x, y = characteristic_map(k, [1.0, 0.0], [0.0, 1.0])
        assert np.allclose(x, [1, 0], rtol=0, atol=4e-16) and np.allclose(y, [0, 1], rtol=0, atol=4e-16)
        assert y[0] == 0 and x[1] == 0
        x1, y1 = characteristic_map(k, r, s)
        x2, y2 = characteristic_map(k, s, r)
        assert np.array_equal(x1, y2) and np.array_equal(y1, x2)
        x3, y3 = characteristic_map(k, r / 8, s / 8)
        assert np.allclose(x3, lam**3 * x1, rtol=1e-14, atol=0)
        assert np.allclose(y3, lam**3 * y1, rtol=1e-14, atol=1e-300)
        # the quadrant onto itself: axes to axes
        x, y = characteristic_map(k, r, 0 * r)
        assert np.all(y == 0) and np.all(x > 0)


@pytest.mark.parametrize("k", [3, 5, 9, 1000])
def test_jacobian_central_differences(k):
    rng = np.random.default_rng(1)
    r = rng.uniform(0.05, 1.5, 300)
    s = rng.uniform(0.05, 1.5, 300)
    x, y, J = characteristic_map(k, r, s, jacobian=True)
    h = 1e-6
    xp, yp = characteristic_map(k, r + h, s)
    xm, ym = characteristic_map(k, r - h, s)
    assert np.allclose(J[:, 0, 0], (xp - xm) / (2 * h), atol=1e-7)
    assert np.allclose(J[:, 1, 0], (yp - ym) / (2 * h), atol=1e-7)
    xp, yp = characteristic_map(k, r, s + h)
    xm, ym = characteristic_map(k, r, s - h)
    assert np.allclose(J[:, 0, 1], (xp - xm) / (2 * h), atol=1e-7)
    assert np.allclose(J[:, 1, 1], (yp - ym) / (2 * h), atol=1e-7)
    assert np.all(np.linalg.det(J) > 0)  # regular (R7)


def test_shapes_and_bad_input():
    x, y = characteristic_map(5, np.zeros((2, 3)), 0.5)
    assert x.shape == (2, 3)
    x, y = characteristic_map(5, 0.25, 0.5)
    assert x.shape == ()
    for bad in ([np.nan], [np.inf], [-1e-300]):
        with pytest.raises(CCProofError):
            characteristic_map(5, bad, [0.5])
    with pytest.raises(CCProofError):
        characteristic_map(2, 0.5, 0.5)
    with pytest.raises(CCProofError):
        characteristic_map(5, "a", 0.5)
