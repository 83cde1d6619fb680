"""T and W for every dart K >= K0 (verify.dart_tail): the evaluators a record's leaves are replayed on."""

import pytest
from flint import fmpq

from ccproof.certify.verify.dart_tail import DartModels, TaylorHints

LO, HI = fmpq(4484, 1000), fmpq(44935, 10000)  # the bracket of sigma(K), K >= 101
H = (fmpq(0), fmpq(1, 101))  # every K >= 101


@pytest.fixture(scope="module")
def box0():
    hints = TaylorHints(r=fmpq(1, 32), disc_grid=6, sigma_boxes=10, order=12, layer_order=14, exp_order=24)
    return DartModels(LO, HI, hints, 1, 128).sigma_box(0)


def test_the_signs_of_w_on_bulk_boxes(box0):
    assert box0.evaluate("X", "bulk", [(fmpq(1, 4), fmpq(26, 100)), H]) > 0
    assert box0.evaluate("Y", "bulk", [(fmpq(1, 10), fmpq(11, 100)), H]) < 0
    assert box0.evaluate("Y", "bulk", [(fmpq(45, 100), fmpq(46, 100)), H]) > 0
    # Y changes sign near s = 0.30 (rays 25 to 35 at K = 101): a box across its zero proves neither sign
    across = box0.evaluate("Y", "bulk", [(fmpq(25, 100), fmpq(35, 100)), H])
    assert not across > 0 and not across < 0


def test_transversality_on_a_bulk_box_and_the_layer_sign(box0):
    assert box0.evaluate("T", "bulk", [(fmpq(1, 4), fmpq(26, 100)), H]) > 0
    # K Y < 0 on layer quadrant 0 for small h; the whole range [0, 1/101] at once is too coarse for the model
    assert box0.evaluate("Y", "layer", [(fmpq(0), fmpq(1, 1010))], 0) < 0


def test_boxes_outside_the_disc_are_refused(box0):
    with pytest.raises(ZeroDivisionError):
        box0.evaluate("X", "bulk", [(fmpq(1, 4), fmpq(26, 100)), (fmpq(0), fmpq(1, 16))])
