"""Forgeries by someone who can run our own tools: each ends in FAIL with a reason naming what failed.

The verifier derives the statement from the valence and the rules, so a forger's only levers are the
certificate file itself and the prover (which they can run on any nets they like). Each test changes
one of them as the audit of the verifier did and checks the verdict and its reason.
"""

import json
import time

import pytest
from flint import arb, ctx

from ccproof.certify import prover as P
from ccproof.certify import verify as V
from ccproof.certify.verify import statement as St
from ccproof.tables.format import certificates_dir

CERTS = certificates_dir() / "injectivity"


def load(k, kind="injectivity"):
    return json.loads((certificates_dir() / kind / f"k{k:03d}.json").read_text())


def run(cert):
    lines = []
    res = V.verify_certificate(cert, log=lines.append)
    return res, "\n".join(lines + [res.error or ""])


def failed_with(cert, *reasons):
    res, log = run(cert)
    assert not res, log
    for r in reasons:
        assert r in log, log
    return log


def test_another_valence_relabelled():
    """k = 5's certificate (its N and boxes) claimed for k = 8."""
    c = load(5)
    c["valence"] = 8
    failed_with(c, "FAIL  ")


def _prove_with_nets_of(monkeypatch, claimed, actual_nets, actual_lam):
    """Run our own prover for valence ``claimed`` on other nets (what a forger with our code can do)."""
    monkeypatch.setattr(P, "nets_for_valence", lambda k, prec: actual_nets)
    monkeypatch.setattr(P, "c_lam", lambda k, prec: (None, actual_lam))
    return P.prove_valence(claimed, progress=False)


def test_another_valences_nets_with_a_regenerated_certificate(monkeypatch):
    nets3, lam3 = St.nets_for_valence(3, 128), St.c_lam(3, 128)[1]
    forged = _prove_with_nets_of(monkeypatch, 5, nets3, lam3)
    assert forged["valence"] == 5
    failed_with(forged, "FAIL  ")


def test_identity_nets_as_valence_5(monkeypatch):
    """The k = 4 map (the identity) with lam = 1/2, certified by our prover and labelled valence 5."""
    nets4, lam4 = St.nets_for_valence(4, 128), St.c_lam(4, 128)[1]
    forged = _prove_with_nets_of(monkeypatch, 5, nets4, lam4)
    failed_with(forged, "FAIL  ")


def test_scaled_nets_with_a_regenerated_certificate(monkeypatch):
    """arb nets scaled by 1.01 (the exact forms untouched): det J_Phi grows by 1.0201, so the claimed
    bounds of part B exceed the true map's coefficients."""
    with ctx.workprec(128):
        nets = {n: [[tuple(x * arb("1.01") for x in p) for p in row] for row in net]
                for n, net in St.nets_for_valence(5, 128).items()}
    forged = _prove_with_nets_of(monkeypatch, 5, nets, St.c_lam(5, 128)[1])
    failed_with(forged, "FAIL  B regularity P2", "is not above the claimed bound")


def test_asymmetric_perturbation_under_the_symmetry_shortcut(monkeypatch):
    """P3's nets alone scaled by 1.05 (P1 left alone, so the map is no longer mirror-symmetric) while the
    prover keeps the shortcut (parts B, D, E on the side u <= v only): its boxes describe a map that is
    not the characteristic map, and the verifier, which derives the nets (and the symmetry) itself, names
    the part that does not hold."""
    with ctx.workprec(128):
        nets = St.nets_for_valence(5, 128)
        nets = dict(nets, P3=[[tuple(x * arb("1.05") for x in p) for p in row] for row in nets["P3"]])
    forged = _prove_with_nets_of(monkeypatch, 5, nets, St.c_lam(5, 128)[1])
    failed_with(forged, "FAIL  B regularity P3")


def test_lam_excluding_the_root(monkeypatch):
    """A prover run with lam(5) + 0.01 (a ball excluding lam(5)); a certificate cannot carry lam at all."""
    with ctx.workprec(128):
        lam = St.c_lam(5, 128)[1] + arb("0.01")
    forged = _prove_with_nets_of(monkeypatch, 5, St.nets_for_valence(5, 128), lam)
    failed_with(forged, "FAIL  ")
    c = load(8)
    c["lam"] = {"mid": "0.6", "rad": "0.1"}
    failed_with(c, "unknown field(s) 'lam'")


def test_extra_cells_with_false_bounds():
    c = load(5)
    c["parts"]["cells"]["7,7,2,2"] = [{"path": "", "bound": "1000"}]
    failed_with(c, "7,7,2,2", "not required by the statement")


def test_the_table_files_are_not_evidence(tmp_path, monkeypatch):
    """Tables are caches: the verifier reads none, so a forged table (nets of k = 5 in k = 8's file, hash
    recomputed) changes no verdict: the genuine k = 8 certificate still verifies and k = 5's boxes still
    fail as valence 8."""
    import shutil

    from ccproof.tables.format import content_hash

    root = tmp_path / "certificates"
    shutil.copytree(certificates_dir() / "tables", root / "tables")
    t8 = json.loads((root / "tables" / "k008.json").read_text())
    t5 = json.loads((root / "tables" / "k005.json").read_text())
    t8["exact"], t8["arb"] = t5["exact"], t5["arb"]
    t8["hash"] = content_hash(t8)
    (root / "tables" / "k008.json").write_text(json.dumps(t8))
    genuine8, c = load(8), load(5)
    monkeypatch.setenv("CCPROOF_CERTIFICATES", str(root))
    res, log = run(genuine8)
    assert res, log
    c["valence"] = 8
    failed_with(c, "FAIL  ")


def test_a_faked_summary_is_rejected_and_report_shows_only_verified_numbers(tmp_path):
    from ccproof.cli.report import _row

    c = load(5)
    c["summary"] = {"min_bound_det_J_phi_local": "0.9"}
    failed_with(c, "unknown field(s) 'summary'")
    p = tmp_path / "k005.json"
    p.write_text(json.dumps(c))
    assert _row(p)["ok"] is False and "detPhi" not in _row(p)
    p.write_text(json.dumps(load(5)))
    row = _row(p)
    claimed = min(float(V.replay.parse_decimal(b["bound"])) for boxes in load(5)["parts"]["regularity"].values()
                  for b in boxes)
    assert row["ok"] and abs(row["detPhi"] - 4 * claimed) < 1e-12


@pytest.mark.parametrize("bound", ["1e-999999999", "1e999999999", "1" * 5001, "0." + "0" * 70 + "1", "1e-401"])
def test_huge_tiny_and_overlong_decimals_fail_fast(bound, tmp_path):
    c = load(5)
    c["parts"]["corner"]["P2"][0]["bound"] = bound
    p = tmp_path / "k.json"
    p.write_text(json.dumps(c))
    t = time.perf_counter()
    res = V.verify_file(p, log=lambda s: None)
    assert time.perf_counter() - t < 1.0
    assert not res and ("exponent" in res.error or "at most 64 characters" in res.error)


def test_verify_all_goes_on_past_a_bad_file(tmp_path, capsys):
    from ccproof.cli.verify import run as verify_run

    good = tmp_path / "good.json"
    good.write_text(json.dumps(load(3, "c1")))
    bad = tmp_path / "bad.json"
    bad.write_text('{"schema": "ccproof.c1/2", "valence": [1, 2]}')
    deep = tmp_path / "deep.json"
    deep.write_text("[" * 100000 + "]" * 100000)

    class A:
        files, all, jobs, quiet = [str(bad), str(deep), str(good)], False, 1, False

    assert verify_run(A()) == 1
    out = capsys.readouterr().out
    assert "VERIFIED " + str(good) in out and out.count("FAILED") >= 2 and "1 of 3 certificates verified" in out


class _IdentityDerivation:
    """What a forger would put in place of the derivation: the identity map's B-spline nets (the k = 4
    nets), independent of lam, as exact forms."""

    symmetric = True

    def integer_forms(self, which="bspline"):
        def f(num):
            return [[num], [0], [2]]  # num / 2
        nets = {"P1": lambda i, j: (f(i), f(j - 1)), "P2": lambda i, j: (f(i), f(j)),
                "P3": lambda i, j: (f(i - 1), f(j))}
        return {n: [[g(i, j) for j in range(4)] for i in range(4)] for n, g in nets.items()}


@pytest.mark.slow
def test_identity_nets_for_every_k_ge_40(monkeypatch):
    """Our interval prover run on the identity nets (every exact form replaced by the identity) finds a
    certificate for that map; the verifier, which derives the k >= 40 nets itself, rejects it at part B."""
    monkeypatch.setattr(P, "derivation", lambda: _IdentityDerivation())
    forged = P.prove_interval(40, progress=False, max_pieces=1)
    failed_with(forged, "FAIL  [piece 0] B regularity P2", "is not above the claimed bound")


def test_boxes_for_the_mirrored_piece_or_an_old_schema_fail():
    """Under the mirror symmetry parts B and E check P2 and P3 only: a P1 block (unchecked hints) is
    refused, not ignored, and so is a file of the previous schema, which listed P1."""
    c = load(5)
    c["parts"]["corner"]["P1"] = c["parts"]["corner"]["P2"]
    failed_with(c, "P1")
    c = load(5)
    c["schema"] = "ccproof.injectivity/2"
    failed_with(c, "unknown certificate schema")
