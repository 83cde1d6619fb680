"""The prover's covers for dart:>=K0 (certify.tagged_dart): what it writes, the verifier's trees accept; a
bound raised past the enclosure, or a claim that is false, is refused."""

import pytest
from flint import arb, fmpq

from ccproof.certify.tagged_dart import cover
from ccproof.certify.verify.dart_curves import CurveModels
from ccproof.certify.verify.dart_family import TaylorHints
from ccproof.certify.verify.dart_trees import read_tree, replay_tree
from ccproof.certify.verify.errors import CertificateError

H = (fmpq(0), fmpq(1, 101))


@pytest.fixture(scope="module")
def box0():
    hints = TaylorHints(r=fmpq(1, 32), disc_grid=6, sigma_boxes=10, order=12, layer_order=14, exp_order=24)
    return CurveModels(fmpq(4484, 1000), fmpq(44935, 10000), hints, 1, 128).sigma_box(0)


def test_a_cover_round_trips_through_the_verifiers_trees(box0):
    root = [(fmpq(1, 4), fmpq(7, 20)), H]
    tree = cover(root, box0.x_bulk, 1, [4, 1])
    count, least = replay_tree(read_tree(tree, root, "X>0 bulk", 1), box0.x_bulk, 1, "X>0 bulk")
    assert count == len(tree["leaves"]) and least > 0
    # a bound raised past what the model encloses FAILs in the verifier
    forged = {"grid": tree["grid"], "leaves": [dict(leaf) for leaf in tree["leaves"]]}
    forged["leaves"][0]["bound"] = str(float(forged["leaves"][0]["bound"]) * 10)
    with pytest.raises(CertificateError, match="claims"):
        replay_tree(read_tree(forged, root, "X>0 bulk", 1), box0.x_bulk, 1, "X>0 bulk")


def test_negative_claims_and_the_layer(box0):
    root = [(fmpq(0), fmpq(1, 1010))]
    tree = cover(root, lambda b: box0.y_layer(0, b), -1, [1])
    assert all(leaf["bound"].startswith("-") for leaf in tree["leaves"])
    assert replay_tree(read_tree(tree, root, "Y<0 layer", -1), lambda b: box0.y_layer(0, b), -1, "l")[0] >= 1


def test_a_false_claim_stays_undecided():
    with pytest.raises(ValueError, match="undecided"):
        cover([(fmpq(-1), fmpq(1))], lambda b: arb(b[0][0]).union(arb(b[0][1])), 1, [1], max_depth=4)
