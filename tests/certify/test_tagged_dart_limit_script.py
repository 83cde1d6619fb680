"""scripts/tagged_dart_limit.py: its closed-form secular equation for a dart's even one-ring against
independent computations (the verifier's exact characteristic polynomial, the exact resolvent, tan s = s)."""

import importlib.util
import math
from pathlib import Path

import pytest
from flint import acb, arb, ctx, fmpq

from ccproof.certify.verify.tagged_modes import mode_spectrum

SCRIPTS = Path(__file__).resolve().parents[2] / "scripts"


def _load():
    spec = importlib.util.spec_from_file_location("tagged_dart_limit", SCRIPTS / "tagged_dart_limit.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.mark.parametrize("k", [12, 40])
def test_lam2_from_the_secular_equation_is_the_verifiers_even_root(k):
    # the verifier isolates lam2 among the roots of S_in's exact characteristic polynomial (fmpq, factored);
    # the script solves G(sigma, 1/K) = 0 with cot and sinc: two independent routes
    mod = _load()
    with ctx.workprec(128):
        even = [z.real for z, q, src, _ in mode_spectrum("dart", k) if src == "E" and q != 1 and z.imag.contains(0)]
        lam2 = max(even, key=lambda r: r.mid())
        s = mod.sigma_of(arb(fmpq(1, k)))
        got = mod.lam_of((2 * s / k).cos())
        assert abs(got - lam2) < 1e-25
        lam1 = mod.lam_of((2 * arb.pi() / k).cos())
        assert got < lam1 and got > mod.lam_of((4 * arb.pi() / k).cos())


def test_the_limit_is_the_root_of_tan_s_equals_s():
    mod = _load()
    a, b = math.pi + 1e-9, 1.5 * math.pi - 1e-9  # tan s - s increases from -s to +inf on (pi, 3 pi/2)
    for _ in range(100):
        m = (a + b) / 2
        a, b = (m, b) if math.tan(m) < m else (a, m)
    with ctx.workprec(128):
        assert abs(float(mod.sigma_of(arb(0)).mid()) - a) < 1e-12


def test_closed_form_equals_the_exact_resolvent_and_sees_a_changed_row(monkeypatch):
    mod = _load()
    with ctx.workprec(128):
        lam = fmpq(3, 5)
        assert abs(mod.f_closed(lam, 9) - acb(mod.f_exact(lam, 9))) < 1e-25
        ring = mod.one_ring

        def changed(k, dart):
            S = ring(k, dart)
            if dart:  # the sharp edge point (C + e_0)/2 moved a little towards e_1
                S[1, 1] -= fmpq(1, 100)
                S[1, 2] += fmpq(1, 100)
            return S

        monkeypatch.setattr(mod, "one_ring", changed)
        assert not abs(mod.f_closed(lam, 9) - acb(mod.f_exact(lam, 9))) < 1e-3


def test_the_uniform_bracket_holds_and_a_wrong_one_fails():
    mod = _load()
    with ctx.workprec(128):
        assert mod.part_c(101, boxes=16, quiet=True) == 16
        assert mod.part_c(101, lo="4.30", hi="4.45", boxes=16, quiet=True) == 0  # sigma(K) > 4.45 for K >= 101


def test_closed_form_y_is_the_verifiers_even_vector():
    # the script's y (three columns, a null vector of S - lam2 on them) against the verifier's even_vector
    # (bordered system on S_E's one-ring, then the outer rows), both normalized at ray K/2's (1,0)
    from ccproof.certify.verify.tagged import labels
    from ccproof.certify.verify.tagged_modes import even_vector

    mod = _load()
    k = 40
    with ctx.workprec(128):
        x, y, l1, l2, res = mod.closed_form_vectors(k)
        assert res < 1e-12
        pts = labels("dart", k)
        at = pts.index(("r", k // 2, 1, 0))
        even = [z.real for z, q, src, _ in mode_spectrum("dart", k) if src == "E" and q != 1 and z.imag.contains(0)]
        lam2 = max(even, key=lambda r: r.mid())
        ref = even_vector(k, lam2, at)
        assert max(abs(float(r.mid()) - v) for r, v in zip(ref, y)) < 1e-10


def test_re_one_minus_f_positive_on_the_circle_for_every_k_and_not_inside_lam2(monkeypatch, capsys):
    # Re(1 - F) > 0 on |lam| = lam(cos(10.8/K)) for every K >= 101 (three regions of boxes); on the circle
    # through sigma = 4 (between lam2 and lam1) the winding number is +1, so Re(1 - F) <= 0 somewhere and
    # the same cover must fail
    mod = _load()
    with ctx.workprec(128):
        mod.part_d_uniform(101)
        out = capsys.readouterr().out
        assert "region N: Re > 0" in out and "region I: Re > 0" in out and "region F: Re > 0" in out
        assert "on 16/16 h-boxes" in out
        monkeypatch.setattr(mod, "_SIG_R", fmpq(4))
        with pytest.raises(ValueError, match="undecided"):
            mod.part_d_uniform(101)


def test_the_regions_agree_with_the_float_closed_form():
    # region N is h (1 - F), region I is v (1 - F) with t = v^2, w = h/v, region F is 1 - F: each against the
    # plain closed form in floats at K = 200
    import cmath

    mod = _load()
    k, h = 200, 1 / 200
    c = math.cos(10.8 / k)
    r = (5 + c + math.sqrt((1 + c) * (9 + c))) / 16

    def ref(t):
        return (1 - mod._f_float(r * cmath.exp(1j * t), k)).real

    with ctx.workprec(128):
        hb = arb(fmpq(1, k))
        assert abs(float(mod.region_n(arb(3), hb).mid()) - h * ref(3 * h * h)) < 1e-9
        assert abs(float(mod.region_i(arb("0.2"), hb / arb("0.2")).mid()) - 0.2 * ref(0.04)) < 1e-9
        assert abs(float(mod.region_f(arb("1.5"), hb, 101).mid()) - ref(1.5)) < 1e-9
