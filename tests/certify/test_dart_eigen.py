"""The eigenvector lemma for every dart K >= K0 (ccproof.certify.verify.dart_spectrum), cross-checked at single K
against the per-K verifier's exact even eigenvector and mode vector, and against S itself."""

from functools import partial

import pytest
from flint import acb, arb, ctx, fmpq

from ccproof.certify.verify import dart_spectrum as E
from ccproof.certify.verify.dart_family import Family
from ccproof.certify.verify.errors import CertificateError
from ccproof.certify.verify.tagged import labels, sector_rows
from ccproof.certify.verify.tagged_modes import even_vector, mode_spectrum, mode_vector

LO, HI = fmpq(4484, 1000), fmpq(44935, 10000)


@pytest.fixture(autouse=True)
def _prec():
    old = ctx.prec
    ctx.prec = 128
    yield
    ctx.prec = old


def test_passes_on_the_records_bracket():
    out = E.check_eigenvector(LO, HI, 101, 128)
    assert out.startswith("eigenvector lemma for every K >= 101") and "64 h-balls" in out


@pytest.mark.parametrize("lo, hi, why", [
    (fmpq(440, 100), fmpq(445, 100), "no certain sign change"),     # sigma(K) > 4.48 for every K >= 101
    (fmpq(4485, 1000), HI, "no certain sign change"),                 # sigma(101) = 4.48477 below the bracket
    (LO, fmpq(4493, 1000), "no certain sign change"),                 # the limit 4.49341 above it
    (fmpq(3), HI, "not inside"),
])
def test_fails_for_a_bracket_without_sigma(lo, hi, why):
    with pytest.raises(CertificateError, match=why):
        E.check_eigenvector(lo, hi, 101, 128)


def test_fails_with_a_flipped_alpha_or_too_small_k0_or_too_few_balls():
    with pytest.raises(CertificateError, match="identity 2"):  # the sharp midpoint's row
        E.check_eigenvector(LO, HI, 101, 128, family=partial(Family, flip_mode0=True))
    with pytest.raises(CertificateError, match="K0 = 5"):
        E.check_eigenvector(LO, HI, 5, 128)
    with pytest.raises(CertificateError, match="sign change"):
        E.check_eigenvector(LO, HI, 101, 128, balls=8)


def test_exact_identities_fail_when_perturbed(monkeypatch):
    N = [list(c) for c in E.N_POLYS]
    N[0][2] += fmpq(1, 1000)
    monkeypatch.setattr(E, "N_POLYS", N)
    with pytest.raises(CertificateError, match="mode-0"):
        E.check_mode0()
    with pytest.raises(CertificateError, match="crease vertex"):
        E.check_crease_row()
    monkeypatch.undo()
    real = E.ring_block

    def bent(w):  # the (2,0) row reads a little more of its own (2,0) point: no longer the crease identity
        rows = real(w)
        rows[1][1] += fmpq(1, 64)
        return rows
    monkeypatch.setattr(E, "ring_block", bent)
    with pytest.raises(CertificateError, match="crease vertex"):
        E.check_crease_row()
    with pytest.raises(CertificateError, match="degree"):
        E.check_crease_row(points=20)


def test_reach_fails_for_a_wider_stencil(monkeypatch):
    rows = list(E.ring_stencil())
    rows[2] = dict(rows[2]) | {(1, (1, 1)): fmpq(0)}  # a quadrant row reading the next quadrant
    monkeypatch.setattr(E, "ring_stencil", lambda: tuple(rows))
    with pytest.raises(CertificateError, match="beyond the windows"):
        E.check_reach()


def _family_vector(fam, k):
    """y of the family on the points of labels('dart', k) (acb)."""
    y, yc = fam.layer_level0()[1], fam.yc
    return [acb(yc)] + [acb(y(p[1], p[2:])) for p in labels("dart", k)[1:]]


def _residual(k, vals, lam):
    rows = sector_rows("dart", k)
    return [sum((x * vals[j] for j, x in row.items()), acb(0)) - lam * vals[i] for i, row in enumerate(rows)]


def test_off_the_root_only_the_centre_row_fails_and_its_residual_is_the_closed_form():
    """Items 1 to 3 at one K, against S from the rules: at sigma != sigma(K) every row but the centre's
    holds, and the centre row's residual times K is scaled_centre_residual."""
    k = 101
    for sigma in (arb("4.45"), arb("4.49"), arb("4.6")):
        fam = Family(acb(fmpq(1, k)), sigma)
        res = _residual(k, _family_vector(fam, k), fam.lam2)
        assert all(abs(r) < 1e-30 for r in res[1:])
        assert abs(res[0]) > 1e-6
        assert (res[0] * k).overlaps(E.scaled_centre_residual(fam))
        assert abs(res[0] * k - E.scaled_centre_residual(fam)) < 1e-30


@pytest.mark.parametrize("k", [101, 150])
def test_family_at_the_exact_lam2_is_even_vector_and_x_is_mode_vector(k):
    """The family at sigma(K) from the per-K verifier's exact lam2 against even_vector (an independent exact
    computation: the bordered system on S_E), and x against mode_vector at lam1."""
    ev = mode_spectrum("dart", k)
    lam2 = max(t[0].real for t in ev if t[2] == "E" and t[1] != 1)
    lam1 = max(t[0].real for t in ev if t[3] == 1)
    h = arb(fmpq(1, k))
    cstar = (16 * lam2 * lam2 - 10 * lam2 + 1) / (2 * lam2)
    sigma = cstar.acos() / (2 * h)
    assert LO < sigma < HI
    fam = Family(acb(h), sigma)
    assert abs(fam.lam2 - lam2) < 1e-30 and abs(fam.lam1 - lam1) < 1e-30
    pts = labels("dart", k)
    piv = pts.index(("r", k // 2, 1, 0))
    y = _family_vector(fam, k)
    exact = even_vector(k, lam2, piv)
    assert all(abs(a / y[piv] - b) < 1e-25 for a, b in zip(y, exact))
    assert abs(_residual(k, y, fam.lam2)[0]) < 1e-25  # the centre row too, at sigma(K)
    x = fam.layer_level0()[0]
    f = mode_vector("dart", k, 1, lam1)
    xs = [acb(0)] + [acb(x(p[1], p[2:])) * acb(0, 2) for p in pts[1:]]
    assert all(abs(a - b) < 1e-25 for a, b in zip(xs, f))


def test_the_limit_h_0_is_the_secular_limit_tan_sigma_sigma():
    """At h = 0 the scaled centre residual is (3/2 + rho(1,1)/4)(sin(sigma)/sigma - cos(sigma)), rho = v^(0)
    (here (5 + sqrt 5)/4): its zero is the root 4.4934 of tan s = s, the limit of sigma(K)."""
    factor = (5 + arb(5).sqrt()) / 4
    for s in (arb("4.3"), arb("4.6"), arb(2)):
        r = E.scaled_centre_residual(Family(acb(0), s))
        assert abs(r - factor * (s.sin() / s - s.cos())) < 1e-30


def _script():
    import importlib.util
    from pathlib import Path
    path = Path(__file__).resolve().parents[2] / "scripts" / "tagged_dart_limit.py"
    spec = importlib.util.spec_from_file_location("tagged_dart_limit", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.mark.parametrize("k", [101, 1000, 10**4, 10**6])
def test_the_centre_residual_vanishes_at_the_root_of_the_secular_equation(k):
    """The zero of r/h in sigma at h = 1/K (bisection) is the root of the untrusted script's G (an independent
    closed form: the secular equation of the one-ring resolvent), where no per-K exact computation reaches."""
    ctx.prec = 128
    h = acb(fmpq(1, k))
    a, b = arb(LO), arb(HI)
    ra = E.scaled_centre_residual(Family(h, a)).real
    for _ in range(45):
        m = arb(((a + b) / 2).mid())
        rm = E.scaled_centre_residual(Family(h, m)).real
        if (rm > 0) == (ra > 0):
            a, ra = m, rm
        else:
            b = m
    root = _script().sigma_of(arb(fmpq(1, k)))
    assert abs(a - root) < 1e-11
