"""The certificate for every k >= 40 at once: lam as a Taylor-model variable.

Independent references: the arb nets of single valences come from ccproof.algebra.specialize (the
symbolic nets specialized at c = cos(2 pi/k)), not from the verifier's zeta models; lam(k) from the
closed form of R2.
"""

import copy
import json

import pytest
from flint import arb, ctx, fmpq

from ccproof.algebra.specialize import characteristic_map_patches
from ccproof.certify import verify as V
from ccproof.certify.poly import Poly, ball_contains
from ccproof.certify.verify import interval as I
from ccproof.certify.verify import replay as R
from ccproof.certify.verify.statement import PATCHES, derivation
from ccproof.tables.format import certificates_dir

PREC = 128
CERT = certificates_dir() / "injectivity" / "k_ge_40.json"


@pytest.fixture(scope="module")
def cert():
    return json.loads(CERT.read_text())


@pytest.fixture(scope="module")
def exact():
    return derivation().integer_forms()


def lam_of(k):
    c = arb(fmpq(2, k)).cos_pi()
    return (5 + c + ((1 + c) * (9 + c)).sqrt()) / 16


def zeta_of(lam, La, Lb):
    return (lam - (La + Lb) / 2) / ((Lb - La) / 2)


def horner(coeffs, z):
    acc = arb(0)
    for c in reversed(coeffs):
        acc = acc * z + c
    return acc


@pytest.mark.parametrize("k", [40, 57, 128, 10**6])
@pytest.mark.parametrize("layer", [0, 3])
def test_zeta_nets_contain_the_exact_nets_of_single_valences(cert, exact, k, layer):
    La, Lb = (R.parse_decimal(x) for x in cert["pieces"][0]["lam"])
    with ctx.workprec(PREC):
        zn = I.parameter_nets(exact, La, Lb, layer, cert["parameter"]["taylor_degree"], PREC)
        lam = lam_of(k)
        z = zeta_of(lam, La, Lb)
        assert -1 <= z.lower() and z.upper() <= 1
        ref = characteristic_map_patches(k, "bezier", "arb", PREC)
        widths = []
        for name in PATCHES:
            for i in range(4):
                for j in range(4):
                    for d in range(2):
                        model = horner(zn[name][i][j][d], z)
                        true = ref[name][i][j][d] * lam**layer
                        assert model.contains(true), (name, i, j, d, model, true)
                        widths.append(model.rad())
        # tight: the remainder of the degree-3 Taylor model is far below the cell margins (~4e-4)
        assert max(widths) < 1e-8


def test_hull_nets_contain_every_valence_and_are_not_vacuous(cert, exact):
    La, Lb = (R.parse_decimal(x) for x in cert["pieces"][0]["lam"])
    with ctx.workprec(PREC):
        hull = I.hull_nets(I.parameter_nets(exact, La, Lb, 0, 3, PREC), PREC)
        for k in (40, 41, 100, 5000):
            ref = characteristic_map_patches(k, "bezier", "arb", PREC)
            assert all(hull[n][i][j][d].contains(ref[n][i][j][d])
                       for n in PATCHES for i in range(4) for j in range(4) for d in range(2))
        # the variation over k >= 40 is real (k = 40 vs k = 10^6 differ), so the hull is wide but < 0.05
        rad = max(hull[n][i][j][d].rad() for n in PATCHES for i in range(4) for j in range(4) for d in range(2))
        assert 1e-4 < rad < 0.05


def test_lam_range_covers_exactly_the_claimed_valences(cert):
    La, Lb = R.parse_decimal(cert["pieces"][0]["lam"][0]), R.parse_decimal(cert["pieces"][-1]["lam"][1])
    assert I.lam_interval_ok(40, La, Lb, PREC)
    assert not I.lam_interval_ok(39, La, Lb, PREC)  # lam(39) < La: k = 39 is not covered
    assert not I.lam_interval_ok(40, La, fmpq(654508, 1000000), PREC)  # below (3 + sqrt 5)/8 = 0.6545085


def test_truncated_taylor_model_encloses_the_polynomial_pointwise():
    # p in (z, s, t); truncation at degree 1 in z must enclose p(z*, s, t) for every z* in [-1, 1]
    z, s, t = (Poly.variable(a, 3, PREC) for a in range(3))
    p = (1 + z * s - 3 * z**2 * t + 2 * z**3 * s * t) * (s - t * z)
    r = p.truncate(1)
    assert r.degrees[0] == 1
    exact_p = p.midpoint()
    for zs in (fmpq(-1), fmpq(-1, 3), fmpq(0), fmpq(7, 10), fmpq(1)):
        for ss, ts in ((fmpq(1, 5), fmpq(2, 3)), (fmpq(1), fmpq(0)), (fmpq(1, 2), fmpq(1, 2))):
            with ctx.workprec(PREC):
                val = exact_p(zs, ss, ts)
                assert ball_contains(r(zs, ss, ts), val)
    # and the derivative in s of the truncation encloses the derivative of p (families survive d/ds)
    dp, dr = exact_p.diff(1), r.diff(1)
    with ctx.workprec(PREC):
        assert ball_contains(dr(fmpq(-2, 3), fmpq(1, 3), fmpq(3, 4)), dp(fmpq(-2, 3), fmpq(1, 3), fmpq(3, 4)))
    # it is a real enclosure, not the dropped polynomial: z^2 terms moved into radii
    assert r.coefficient((0, 1, 1)).rad() >= 3


def test_interval_certificate_structure(cert):
    assert cert["valence"] == {"min": 40}
    assert cert["N"] == 5
    assert cert["parameter"] == {"variable": "lam", "taylor_degree": 3, "truncation_degree": 2}
    assert len(cert["pieces"]) >= 1
    # every cell box is in three variables (zeta, s, t) and every bound is positive
    for pc in cert["pieces"]:
        for boxes in pc["parts"]["cells"].values():
            for b in boxes:
                R.parse_path(b["path"], 3)
                assert R.parse_decimal(b["bound"]) > 0


def run(c):
    lines = []
    res = V.verify_certificate(c, log=lines.append)
    return res.ok, "\n".join(lines + [res.error or ""])


def test_lam_range_tampering_fails_fast(cert):
    bad = copy.deepcopy(cert)
    bad["pieces"][0]["lam"][0] = "0.6528"  # above lam(40) = 0.652706: k = 40 no longer covered
    ok, log = run(bad)
    assert not ok and "FAIL  lam(k) in" in log


def test_widened_to_valence_3_fails(cert):
    # widen the interval down to lam(3) = 0.4114: the claim with these boxes is not established there
    bad = copy.deepcopy(cert)
    bad["pieces"][0]["lam"][0] = "0.41"
    ok, log = run(bad)
    assert not ok, log
    assert "FAIL" in log or "denominator" in log


def test_widened_to_k0_30_fails(cert):
    # lam(30) = 0.651308: the range claim holds, but the bounds claimed for k >= 40 are not established
    # on the wider range (the hull of the nets grows; det J_Phi's claimed bound on P2 is no longer below
    # every coefficient), so the verifier names the part and stops
    bad = copy.deepcopy(cert)
    bad["pieces"][0]["lam"][0] = "0.6513"
    ok, log = run(bad)
    assert not ok
    assert "PASS  lam(k) in" in log and "FAIL  [piece 0] B regularity P2" in log, log


def test_pieces_must_be_contiguous(cert):
    bad = copy.deepcopy(cert)
    pc = copy.deepcopy(bad["pieces"][0])
    lo, hi = pc["lam"]
    bad["pieces"] = [dict(pc, lam=[lo, "0.6535"]), dict(pc, lam=["0.6536", hi])]
    ok, log = run(bad)
    assert not ok and "contiguous" in log


@pytest.mark.parametrize("mutate, reason", [
    (lambda c: c.pop("parameter"), "parameter"),
    (lambda c: c["parameter"].update(truncation_degree=5), "truncation_degree"),
    (lambda c: c["parameter"].update(variable="c"), "variable"),
    (lambda c: c.update(pieces=[]), "1..64 lam pieces"),
    (lambda c: c["pieces"][0]["lam"].append("0.7"), "low, high"),
    (lambda c: c["pieces"][0]["parts"]["cells"].update({"1,1,0,0": [{"path": "3L", "bound": "1e-3"}]}), "axis"),
])
def test_malformed_interval_certificates(cert, mutate, reason):
    bad = copy.deepcopy(cert)
    mutate(bad)
    ok, log = run(bad)
    assert not ok and reason in log


@pytest.mark.slow
def test_interval_certificate_verifies_and_a_removed_cell_fails(cert):
    ok, log = run(cert)
    assert ok, log
    assert "[piece 0] D det J_G > 0 on every cell" in log
    bad = copy.deepcopy(cert)
    key = sorted(bad["pieces"][0]["parts"]["cells"])[7]
    del bad["pieces"][0]["parts"]["cells"][key]
    ok, log = run(bad)
    assert not ok and f"D cell {key}" in log
