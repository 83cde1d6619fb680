"""The prover's covers for dart:>=K0 (certify.tagged_dart): what it writes, the verifier's trees accept; a
bound raised past the enclosure, or a claim that is false, is refused."""

import pytest
from flint import arb, fmpq

from ccproof.certify.tagged_dart import cover, map_covers
from ccproof.certify.verify.dart_tail import DartModels, TaylorHints, read_map, replay_map
from ccproof.certify.verify.errors import CertificateError
from ccproof.certify.verify.replay import read_tree, replay_tree

H = (fmpq(0), fmpq(1, 101))


@pytest.fixture(scope="module")
def box0():
    hints = TaylorHints(r=fmpq(1, 32), disc_grid=6, sigma_boxes=10, order=12, layer_order=14, exp_order=24)
    return DartModels(fmpq(4484, 1000), fmpq(44935, 10000), hints, 1, 128).sigma_box(0)


def test_a_cover_round_trips_through_the_verifiers_trees(box0):
    root = [(fmpq(1, 4), fmpq(7, 20)), H]
    tree = cover(root, box0.evaluator(("X", "bulk", None)), 1, [4, 1])
    count, least = replay_tree(read_tree(tree, root, "X>0 bulk", 1), box0.evaluator(("X", "bulk", None)), 1, "X>0 bulk")
    assert count == len(tree["leaves"]) and least > 0
    # a bound raised past what the model encloses FAILs in the verifier
    forged = {"grid": tree["grid"], "leaves": [dict(leaf) for leaf in tree["leaves"]]}
    forged["leaves"][0]["bound"] = str(float(forged["leaves"][0]["bound"]) * 10)
    with pytest.raises(CertificateError, match="claims"):
        replay_tree(read_tree(forged, root, "X>0 bulk", 1), box0.evaluator(("X", "bulk", None)), 1, "X>0 bulk")


def test_negative_claims_and_the_layer(box0):
    root = [(fmpq(0), fmpq(1, 1010))]
    tree = cover(root, lambda b: box0.evaluate("Y", "layer", b, 0), -1, [1])
    assert all(leaf["bound"].startswith("-") for leaf in tree["leaves"])
    layer0 = box0.evaluator(("Y", "layer", 0))
    assert replay_tree(read_tree(tree, root, "Y<0 layer", -1), layer0, -1, "l")[0] >= 1


def test_a_false_claim_stays_undecided():
    with pytest.raises(ValueError, match="undecided"):
        cover([(fmpq(-1), fmpq(1))], lambda b: arb(b[0][0]).union(arb(b[0][1])), 1, [1], max_depth=4)


def _hints(grid=12):
    return TaylorHints(r=fmpq(1, 32), disc_grid=grid, sigma_boxes=10, order=12, layer_order=14, exp_order=24)


def _regions():
    return dict(k0=101, sig_lo=fmpq(4484, 1000), sig_hi=fmpq(44935, 10000), s0=fmpq(1, 20), layer=3,
                winding=(fmpq(1, 4), fmpq(7, 20)), prec=128)


def _replay(parts, hints, k0, sig_lo, sig_hi, s0, layer, winding, prec):
    return replay_map(read_map(parts, k0, hints, s0, layer, winding), sig_lo, sig_hi, hints, layer, prec)


def test_malformed_map_parts_fail_before_any_model_is_built():
    r = _regions()
    tree = {"grid": [1, 1], "leaves": [{"cell": [0, 0], "path": "", "bound": "1"}]}
    ltree = {"grid": [1], "leaves": [{"cell": [0], "path": "", "bound": "1"}]}
    cov = {"bulk": [tree] * 10, "middle": [tree] * 10, "layer": {q: [ltree] * 10 for q in "012"}}
    signs = {"Y<0 bulk": [tree] * 10, "X>0 bulk": [tree] * 10, "Y>0 bulk": [tree] * 10, "Y<0 middle": [tree] * 10,
             "Y<0 layer": {q: [ltree] * 10 for q in "012"}}
    parts = {"regularity": cov, "transversal": cov, "winding": signs}
    with pytest.raises(CertificateError, match="wrong sign"):  # the Y<0 lists need negative bounds
        _replay(parts, hints=_hints(), **r)
    with pytest.raises(CertificateError, match="one tree per sigma box"):
        _replay(dict(parts, regularity=dict(cov, bulk=[tree] * 9)), hints=_hints(), **r)
    with pytest.raises(CertificateError):
        _replay(dict(parts, extra=1), hints=_hints(), **r)
    with pytest.raises(CertificateError, match="s0 < s_a"):
        _replay(parts, hints=_hints(), **dict(r, winding=(fmpq(1, 30), fmpq(7, 20))))
    with pytest.raises(CertificateError, match="T >= 3"):
        _replay(parts, hints=_hints(), **dict(r, layer=2))


@pytest.mark.slow
def test_the_whole_map_part_for_every_k_from_101_round_trips():
    """R, T and W for every K >= 101 (3,239 leaves: the scripts' covers) written by the prover and replayed
    by the trusted trees on fresh models; a bulk tree with its last cell's leaves dropped FAILs."""
    r = _regions()
    parts = map_covers(r["k0"], r["sig_lo"], r["sig_hi"], _hints(), r["s0"], r["layer"], r["winding"])
    summary = _replay(parts, hints=_hints(), **r)
    tree = parts["regularity"]["bulk"][3]
    # every leaf the prover wrote (one tree per sigma box) is replayed; the count follows the prover's cover
    written = sum(len(t["leaves"]) for t in parts["regularity"]["bulk"])
    assert summary["R bulk"][0] == written > 1000 and summary["R bulk"][1] > 0
    assert summary["Y<0 layer 0"][1] < 0
    last = max(leaf["cell"][0] for leaf in tree["leaves"])
    tree["leaves"] = [leaf for leaf in tree["leaves"] if leaf["cell"][0] != last]
    with pytest.raises(CertificateError, match="no leaf"):
        _replay(parts, hints=_hints(), **r)
