"""Quadrant maps F^alpha (bmz04 section 4.2) and Phi^-1 (section 4.3) with their derivatives.

Expected values: polar closed forms for F^alpha (|F| = rho^alpha, same direction,
det J = alpha rho^(2 alpha - 2)); for Phi^-1 the forward map (Phi(Phi^-1(t)) = t) and central
differences of the inverse itself; lam from the exact arb eigenvalue of ccproof.algebra.
"""

import math

import numpy as np
import pytest

from ccproof.algebra.specialize import subdominant_eigenvalue
from ccproof.errors import CCProofError
from ccproof.inverse import characteristic_map
from ccproof.reparam.quadrant import (
    alpha_bound,
    check_alpha,
    default_alpha,
    inverse_characteristic_map_derivatives,
    subdominant_lambda,
    vanishing_map,
)

VALENCES = [3, 5, 6, 8, 13, 20]


@pytest.mark.parametrize("k", [3, 4, 5, 7, 13, 20, 100])
def test_lambda_and_bound(k):
    lam = float(subdominant_eigenvalue(k, "arb", 128).mid())
    assert abs(subdominant_lambda(k) - lam) < 1e-15
    assert abs(alpha_bound(k) - (-math.log(2) / math.log(lam))) < 1e-13
    assert default_alpha(k) > alpha_bound(k)
    assert default_alpha(k) >= 1.55  # > 1: the radial blend is increasing (section 4.2)
    # 2^(1/alpha) lam < 1 (eq. 5): the derivatives of f o F^alpha vanish at the vertex
    assert 2 ** (1 / default_alpha(k)) * lam < 1


@pytest.mark.parametrize("k", [3, 5, 13])
def test_alpha_checks(k):
    b = alpha_bound(k)
    with pytest.raises(CCProofError, match="not above the bound"):
        check_alpha(b, k)
    with pytest.raises(CCProofError, match="not above the bound"):
        check_alpha(0.5 * b, k)
    with pytest.raises(CCProofError, match="real number"):
        check_alpha("x", k)
    with pytest.raises(CCProofError, match="finite"):
        check_alpha(float("nan"), k)
    assert check_alpha(b * 1.01, k) == b * 1.01


@pytest.mark.parametrize("alpha", [0.8, 1.3, 2.0, 3.1])
def test_vanishing_map_closed_form(alpha):
    rng = np.random.default_rng(3)
    s, t = rng.random(5000), rng.random(5000)
    s[0] = t[0] = 0.0
    F, J, H = vanishing_map(s, t, alpha, 2)
    rho = np.hypot(s, t)
    pos = rho > 0
    assert np.allclose(np.hypot(F[:, 0], F[:, 1])[pos], rho[pos] ** alpha, rtol=1e-14, atol=0)
    assert np.abs(F[pos, 0] * t[pos] - F[pos, 1] * s[pos]).max() < 1e-14  # same direction
    det = np.linalg.det(J[pos])
    assert np.allclose(det, alpha * rho[pos] ** (2 * alpha - 2), rtol=1e-12)
    assert (F[0] == 0).all()
    h = 1e-6 * rho[pos]
    for i in range(2):
        e = np.zeros((pos.sum(), 2))
        e[:, i] = h
        Fp, Jp = vanishing_map(s[pos] + e[:, 0], t[pos] + e[:, 1], alpha, 1)
        Fm, Jm = vanishing_map(s[pos] - e[:, 0], t[pos] - e[:, 1], alpha, 1)
        scale = np.abs(J[pos]).max(axis=(1, 2))[:, None]
        assert (np.abs((Fp - Fm) / (2 * h[:, None]) - J[pos][:, :, i]) / scale).max() < 1e-8
        hs = np.abs(H[pos]).max(axis=(1, 2, 3))[:, None, None]
        assert (np.abs((Jp - Jm) / (2 * h[:, None, None]) - H[pos][:, :, :, i]) / hs).max() < 1e-7


@pytest.mark.parametrize("k", VALENCES)
def test_characteristic_inverse(k):
    rng = np.random.default_rng(k)
    r, th = 0.5 * 2.0 ** -rng.uniform(0, 40, 1000), rng.uniform(0.05, np.pi / 2 - 0.05, 1000)
    s = np.concatenate([rng.uniform(1e-3, 0.5, 3000), r * np.cos(th), [0.3, 0.0]])
    t = np.concatenate([rng.uniform(1e-3, 0.5, 3000), r * np.sin(th), [0.0, 0.3]])
    F, J, H = inverse_characteristic_map_derivatives(k, s, t, 2)
    x, y, JP = characteristic_map(k, F[:, 0], F[:, 1], jacobian=True)
    scale = np.hypot(s, t)
    assert (np.hypot(x - s, y - t) / scale).max() < 1e-13
    assert np.abs(np.einsum("nab,nbc->nac", J, JP) - np.eye(2)).max() < 1e-11
    # sides onto themselves: Phi^-1 keeps the axes
    assert F[-2, 1] == 0.0 and F[-1, 0] == 0.0
    assert (F[:, 0] <= 1).all() and (F[:, 1] <= 1).all()  # [0,1/2]^2 inside Phi([0,1]^2) (R7)
    # Jacobian and second derivatives against central differences of Phi^-1 itself
    h = 1e-6 * scale[:-2]
    for i in range(2):
        e = np.zeros((h.size, 2))
        e[:, i] = h
        Fp, Jp = inverse_characteristic_map_derivatives(k, s[:-2] + e[:, 0], t[:-2] + e[:, 1], 1)
        Fm, Jm = inverse_characteristic_map_derivatives(k, s[:-2] - e[:, 0], t[:-2] - e[:, 1], 1)
        sc = np.abs(J[:-2]).max(axis=(1, 2))[:, None]
        assert (np.abs((Fp - Fm) / (2 * h[:, None]) - J[:-2, :, i]) / sc).max() < 1e-7
        sh = np.abs(H[:-2]).max(axis=(1, 2, 3))[:, None, None]
        assert (np.abs((Jp - Jm) / (2 * h[:, None, None]) - H[:-2, :, :, i]) / sh).max() < 1e-6


def test_characteristic_inverse_origin():
    F, J, H = inverse_characteristic_map_derivatives(5, np.array([0.0]), np.array([0.0]), 2)
    assert (F == 0).all() and np.isnan(J).all() and np.isnan(H).all()
