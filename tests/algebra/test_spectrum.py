import numpy as np
import pytest
from flint import arb, ctx, fmpq

from ccproof.algebra.specialize import subdominant_eigenvalue
from ccproof.algebra.spectrum import check_charpoly_factorization, spectral_conditions
from ccproof.algebra.subdivision import ring_subdivision_matrix, subdivision_matrix_fmpq


@pytest.mark.parametrize("k", range(3, 51))
def test_lam_matches_opensubdiv_limit_tangent_formula(k):
    """OpenSubdiv / Halstead et al. write lam = (5 + cos(2pi/k) + cos(pi/k) sqrt(18 + 2 cos(2pi/k)))/16."""
    with ctx.workprec(200):
        c2 = arb(fmpq(2, k)).cos_pi()
        c1 = arb(fmpq(1, k)).cos_pi()
        osd = (5 + c2 + c1 * (18 + 2 * c2).sqrt()) / 16
        lam = subdominant_eigenvalue(k, "arb", 200)
        d = lam - osd
        assert d.contains(0) and abs(d).upper() < arb("1e-30")


@pytest.mark.parametrize("k", [3, 4, 5, 6, 7, 9, 12, 20, 33])
def test_lam_is_double_eigenvalue_of_numeric_spectrum(k):
    S = np.array([[float(x) for x in row] for row in ring_subdivision_matrix(k)])
    ev = np.sort(np.abs(np.linalg.eigvals(S)))[::-1]
    lam = float(subdominant_eigenvalue(k, "arb").mid())
    assert abs(ev[0] - 1) < 1e-12
    assert abs(ev[1] - lam) < 1e-9 and abs(ev[2] - lam) < 1e-9
    assert ev[3] < lam - 1e-6


@pytest.mark.parametrize("k", [3, 4, 5, 6, 7, 8, 10, 13, 16])
def test_charpoly_factorization_exact(k):
    assert check_charpoly_factorization(k)


@pytest.mark.parametrize("k", [3, 5, 7])
def test_lam_is_a_root_of_multiplicity_two_of_exact_charpoly(k):
    """Rigorous root isolation of the exact characteristic polynomial (flint)."""
    cp = subdivision_matrix_fmpq(k).charpoly()
    num = cp.numer()
    lam = subdominant_eigenvalue(k, "arb", 128)
    roots = num.complex_roots()
    hits = [(r, m) for r, m in roots if r.real.overlaps(lam) and r.imag.contains(0)]
    assert sum(m for _, m in hits) == 2
    others = [abs(r) for r, m in roots if not r.real.overlaps(lam)]
    one = [m for r, m in roots if r.real.overlaps(arb(1))]
    assert one == [1]
    assert all((o < lam) or o.overlaps(arb(1)) for o in others)


def test_charpoly_factorization_detects_a_wrong_matrix(monkeypatch):
    import ccproof.algebra.subdivision as sub

    real = sub.ring_subdivision_matrix

    def wrong(k, ring="two_ring"):
        from fractions import Fraction

        S = real(k, ring)
        S[1][0] += Fraction(1, 1000)  # rows still sum to 1, the spectrum moves
        S[1][1] -= Fraction(1, 1000)
        return S

    monkeypatch.setattr(sub, "ring_subdivision_matrix", wrong)
    with pytest.raises(AssertionError):
        check_charpoly_factorization(5)


@pytest.mark.parametrize("k", list(range(3, 41)) + [100, 1000, 10**6])
def test_spectral_ordering_certified(k):
    res = spectral_conditions(k)
    assert res["ok"]
    assert res["gap"] > 0
