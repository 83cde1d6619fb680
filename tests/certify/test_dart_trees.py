"""The trees of a dart:>=K0 record (verify.replay.read_tree, replay_tree): partition per cell before
arithmetic, the outside rule, the bound's sign, and the replay on a real evaluator (forgeries FAIL with a
reason)."""

import pytest
from flint import arb, fmpq

from ccproof.certify.verify.dart_tail import DartModels, TaylorHints
from ccproof.certify.verify.errors import CertificateError
from ccproof.certify.verify.replay import read_tree, replay_tree

UNIT = [(fmpq(0), fmpq(1)), (fmpq(0), fmpq(1))]


def _tree(*leaves, grid=(1, 1)):
    return {"grid": list(grid), "leaves": [dict(cell=c, path=p, **extra) for c, p, extra in leaves]}


def test_a_tree_that_misses_part_of_its_root_fails():
    good = _tree(([0, 0], "0L", {"bound": "1"}), ([0, 0], "0H1L", {"bound": "1"}), ([0, 0], "0H1H", {"bound": "1"}))
    assert len(read_tree(good, UNIT, "t", 1)) == 3
    gap = _tree(([0, 0], "0L", {"bound": "1"}), ([0, 0], "0H1L", {"bound": "1"}))
    with pytest.raises(CertificateError, match="gap"):
        read_tree(gap, UNIT, "t", 1)
    # a whole grid cell without leaves
    cells = _tree(([0, 0], "", {"bound": "1"}), grid=(2, 1))
    with pytest.raises(CertificateError, match="no leaf"):
        read_tree(cells, UNIT, "t", 1)
    overlap = _tree(([0, 0], "", {"bound": "1"}), ([0, 0], "0L", {"bound": "1"}))
    with pytest.raises(CertificateError, match="overlap"):
        read_tree(overlap, UNIT, "t", 1)


def test_bounds_of_the_wrong_sign_and_malformed_leaves_fail():
    with pytest.raises(CertificateError, match="wrong sign"):
        read_tree(_tree(([0, 0], "", {"bound": "-1e-3"})), UNIT, "t", 1)
    with pytest.raises(CertificateError, match="wrong sign"):
        read_tree(_tree(([0, 0], "", {"bound": "1e-3"})), UNIT, "t", -1)
    for bad in ({"grid": [1], "leaves": []}, {"grid": [65, 1], "leaves": []}, {"grid": [1, 1], "leaves": [],
                                                                              "extra": 1}):
        with pytest.raises(CertificateError):
            read_tree(bad, UNIT, "t", 1)
    with pytest.raises(CertificateError, match="not a cell"):
        read_tree(_tree(([1, 0], "", {"bound": "1"})), UNIT, "t", 1)


def test_an_outside_leaf_must_miss_every_k_from_k0_on():
    root = [(fmpq(0), fmpq(1, 20)), (fmpq(0), fmpq(1, 3))]  # the middle: (s, w), h = s w
    far = _tree(([0, 0], "0L", {"bound": "1"}), ([0, 0], "0H1L", {"bound": "1"}), ([0, 0], "0H1H",
                                                                                    {"outside": True}))
    # the leaf [1/40, 1/20] x [1/6, 1/3]: s_lo w_lo = 1/240 > 1/K0 only for K0 > 240
    assert read_tree(far, root, "m", 1, k0=241, outside=True)[2][1] is None
    with pytest.raises(CertificateError, match="meets h"):
        read_tree(far, root, "m", 1, k0=101, outside=True)
    with pytest.raises(CertificateError, match="only in the middle"):
        read_tree(far, root, "bulk", 1, k0=241, outside=False)


def test_replay_accepts_only_bounds_the_enclosure_reaches():
    leaves = [([(fmpq(1), fmpq(2))], fmpq(1, 2))]
    assert replay_tree(leaves, lambda box: arb(box[0][0]).union(arb(box[0][1])), 1, "r") == (1, fmpq(1, 2))
    with pytest.raises(CertificateError, match="claims 3/2"):
        replay_tree([([(fmpq(1), fmpq(2))], fmpq(3, 2))], lambda box: arb(1).union(arb(2)), 1, "r")
    def outside_the_disc(box):
        raise ZeroDivisionError("h outside the Cauchy disc")
    with pytest.raises(CertificateError, match="cannot be evaluated"):
        replay_tree(leaves, outside_the_disc, 1, "r")


def test_a_w_sign_tree_on_the_real_models():
    """X > 0 on s in [1/4, 7/20] for every K >= 101, from a two-cell tree on sigma box 0; a forged leaf
    claiming Y > 0 across Y's zero (s near 0.30) FAILs."""
    hints = TaylorHints(r=fmpq(1, 32), disc_grid=6, sigma_boxes=10, order=12, layer_order=14, exp_order=24)
    box0 = DartModels(fmpq(4484, 1000), fmpq(44935, 10000), hints, 0, 128).sigma_box(0)
    root = [(fmpq(1, 4), fmpq(7, 20)), (fmpq(0), fmpq(1, 101))]
    tree = _tree(*[([i, 0], "", {"bound": "1e-3"}) for i in range(10)], grid=(10, 1))
    count, least = replay_tree(read_tree(tree, root, "X>0 bulk", 1), box0.evaluator(("X", "bulk", None)), 1, "X>0 bulk")
    assert count == 10 and least == fmpq(1, 1000)
    with pytest.raises(CertificateError, match="claims"):
        replay_tree(read_tree(tree, root, "Y>0 bulk", 1), box0.evaluator(("Y", "bulk", None)), 1, "Y>0 bulk")
