"""The spectrum of every dart K >= K0 (ccproof.certify.verify.dart_spectrum) against independent computations.

The one-ring matrices below are written here from the Catmull-Clark rules (centre, the K edge points, the K
face points), independently of the trusted base; numpy's determinants and eigenvalues of them are the
reference for the closed form of 1 - F in the three regions and for the eigenvalue count.
"""

from __future__ import annotations

import cmath
import math

import numpy as np
import pytest
from flint import arb, ctx, fmpq

from ccproof.certify.tagged_dart import cover, spectrum_covers
from ccproof.certify.verify.dart_spectrum import (
    SpectralRegions,
    check_construction,
    check_mode0_roots,
    check_ranges,
    check_secular,
    region_roots,
    w1_of,
)
from ccproof.certify.verify.errors import CertificateError
from ccproof.certify.verify.statement import lam_of

SIG_R = fmpq(27, 5)


def one_ring(k, dart):
    """The smooth (dart=False) or dart (ray 0 sharp) one-ring operator: C, e_0..e_{K-1}, f_0..f_{K-1}."""
    m = 2 * k + 1
    S = np.zeros((m, m))
    S[0, 0] = 1 - 7 / (4 * k)
    for r in range(k):
        e, e1, em, f, fm = 1 + r, 1 + (r + 1) % k, 1 + (r - 1) % k, 1 + k + r, 1 + k + (r - 1) % k
        S[0, e] += 3 / (2 * k * k)
        S[0, f] += 1 / (4 * k * k)
        S[f, [0, e, e1, f]] += 0.25  # face point: centroid of C, e_r, e_r+1, f_r
        if dart and r == 0:
            S[e, [0, e]] += 0.5  # sharp edge: the midpoint
            continue
        S[e, [0, e]] += 3 / 8
        S[e, [em, e1, fm, f]] += 1 / 16
    return S


def one_minus_f(lam, k):
    I = np.eye(2 * k + 1)
    (s1, l1), (s0, l0) = (np.linalg.slogdet(lam * I - one_ring(k, dart)) for dart in (True, False))
    return s1 / s0 * np.exp(l1 - l0)


def _q(x, den=10**9):
    return fmpq(round(x * den), den)


@pytest.fixture(autouse=True)
def _prec():
    with ctx.workprec(128):
        yield


def test_construction_derives_d_as_stated():
    """d = C/8 + e_0/8 - (e_-1 + e_1 + f_-1 + f_0)/16: the sharp midpoint minus the smooth edge rule."""
    d, bound = check_construction()
    want = {("C",): fmpq(1, 8), ("r", 0, 1, 0): fmpq(1, 8), ("r", -1, 1, 0): fmpq(-1, 16),
            ("r", 1, 1, 0): fmpq(-1, 16), ("q", -1, 1, 1): fmpq(-1, 16), ("q", 0, 1, 1): fmpq(-1, 16)}
    assert d == want and bound == fmpq(15, 64)
    assert check_secular()



@pytest.mark.parametrize("k", [101, 400])
def test_regions_equal_the_exact_determinant_ratio(k):
    """Each region's closed form at a point equals det(lam - S)/det(lam - S0) of the one-ring (numpy)."""
    reg, h = SpectralRegions(SIG_R, 101), fmpq(1, k)
    r = float(lam_of((2 * arb(SIG_R) * arb(h)).cos()).mid())
    for t in (1e-4, 2e-3):  # N: tau = t/h^2
        ref = one_minus_f(r * cmath.exp(1j * t), k).real
        tau = _q(t) / (h * h)
        got = reg.n([(tau, tau), (h, h)]) / arb(h)
        assert abs(float(got.mid()) - ref) < 1e-8 * max(1, abs(ref)), (t, got, ref)
    for t in (0.01, 0.1):  # I: v = sqrt t, w = h/v
        v = _q(math.sqrt(t))
        ref = one_minus_f(r * cmath.exp(1j * float(v) ** 2), k).real
        got = reg.i([(v, v), (h / v, h / v)]) / arb(v)
        assert abs(float(got.mid()) - ref) < 1e-8, (t, got, ref)
    for t in (0.3, 1.5, 3.1):  # F
        tq = _q(t)
        ref = one_minus_f(r * cmath.exp(1j * float(tq)), k).real
        got = reg.f([(tq, tq), (h, h)])
        assert abs(float(got.mid()) - ref) < 1e-8, (t, got, ref)
        assert got.rad() < 1e-6  # tight, not just enclosing


def test_covers_match_the_script_and_every_leaf_is_positive():
    re = spectrum_covers(101, SIG_R, fmpq(50), fmpq(2, 5))
    assert {k: len(v["leaves"]) for k, v in re.items()} == {"N": 168, "I": 251, "F": 200}
    assert all(float(leaf["bound"]) > 0 for v in re.values() for leaf in v["leaves"])


def test_control_circle_inside_lam2_is_not_covered():
    """Through sigma = 4 (between lam2 and lam1) 1 - F winds once: Re(1 - F) < 0 at lam = r (t = 0), and the
    region N cannot be covered there."""
    reg = SpectralRegions(fmpq(4), 101)
    h = fmpq(1, 202)
    assert reg.n([(fmpq(0), fmpq(0)), (h, h)]) < 0
    r = float(lam_of((2 * arb(4) * arb(h)).cos()).mid())
    assert one_minus_f(r, 202).real < 0  # the numpy reference agrees
    with pytest.raises(ValueError, match="undecided"):
        cover(region_roots(101, fmpq(50), fmpq(2, 5))["N"], reg.n, 1, [40, 4], max_depth=4)


@pytest.mark.parametrize("k", [101, 160])
def test_count_outside_the_circle_numpy(k):
    """The one-ring of dart:K has exactly three eigenvalues outside |lam| = r: 1, lam1 and lam2, and mode 0's
    other two lie below r (the claims of the spectral step)."""
    r = float(lam_of((2 * arb(SIG_R) * arb(fmpq(1, k))).cos()).mid())
    ev = np.linalg.eigvals(one_ring(k, True))
    out = sorted(ev[abs(ev) > r].real, reverse=True)
    c = math.cos(2 * math.pi / k)
    lam1 = (5 + c + math.sqrt((1 + c) * (9 + c))) / 16
    assert len(out) == 3 and abs(out[0] - 1) < 1e-12 and abs(out[1] - lam1) < 1e-12 and out[2] < lam1
    h = 1 / k
    B0 = np.array([[1 - 7 * h / 4, 3 * h / 2, h / 4], [3 / 8, 1 / 2, 1 / 8], [1 / 4, 1 / 2, 1 / 4]])
    e0 = sorted(np.linalg.eigvals(B0).real)
    assert abs(e0[2] - 1) < 1e-12 and e0[1] < r and abs(np.linalg.eigvals(B0).imag).max() == 0


def test_mode0_and_ranges_refuse():
    assert check_mode0_roots(SIG_R, 101, 16) > 0
    with pytest.raises(CertificateError, match="below r"):
        check_mode0_roots(fmpq(10), 7, 4)  # r below mode 0's second root at K = 7
    with pytest.raises(CertificateError, match="sigma_hi < sigma_r"):
        check_ranges(101, fmpq(4484, 1000), fmpq(55, 10), SIG_R, fmpq(50), fmpq(2, 5))
    with pytest.raises(CertificateError, match="pi < sigma_lo"):
        check_ranges(101, fmpq(3), fmpq(4), SIG_R, fmpq(50), fmpq(2, 5))
    assert w1_of(fmpq(50)) ** 2 * 50 >= 1 > (w1_of(fmpq(50)) - fmpq(1, 1024)) ** 2 * 50
    # a forger's tiny tau1: region I's root must still reach w = 1/sqrt(tau1) (no cap on w1)
    tiny = fmpq(1, 10**20)
    assert w1_of(tiny) ** 2 * tiny >= 1
