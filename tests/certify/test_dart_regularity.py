"""R for every dart K >= K0 (verify.dart_tail): the evaluators a record's leaves are replayed on."""

import importlib.util
from pathlib import Path

import pytest
from flint import arb, ctx, fmpq

from ccproof.certify.verify.dart_tail import DartModels, TaylorHints
from ccproof.certify.verify.tagged_map import PIECES

LO, HI = fmpq(4484, 1000), fmpq(44935, 10000)  # the bracket of sigma(K), K >= 101
BOX = [(fmpq(1, 4), fmpq(26, 100)), (fmpq(0), fmpq(1, 101))]  # s in [1/4, 0.26], every K >= 101


def _hints(order=12, grid=6):
    return TaylorHints(r=fmpq(1, 32), disc_grid=grid, sigma_boxes=10, order=order, layer_order=14, exp_order=24)


@pytest.fixture(scope="module")
def models():
    return DartModels(LO, HI, _hints(), 0, 128)


def test_a_bulk_leaf_is_proved_for_every_k(models):
    b = models.sigma_box(0)
    val = b.evaluate("R", "bulk", BOX)
    assert val > 0
    # the union over the three pieces' coefficients is informative, not a huge ball that happens to be > 0
    assert val.rad() < 1


def test_an_order_too_low_for_the_cauchy_tail_proves_nothing(models):
    low = DartModels(LO, HI, _hints(order=4), 0, 128).sigma_box(0)
    assert not low.evaluate("R", "bulk", BOX) > 0


def test_boxes_outside_the_disc_and_unknown_sigma_boxes_are_refused(models):
    with pytest.raises(ZeroDivisionError):
        models.sigma_box(0).evaluate("R", "bulk", [(fmpq(1, 4), fmpq(26, 100)), (fmpq(0), fmpq(1, 16))])
    with pytest.raises(IndexError):
        models.sigma_box(10)


@pytest.mark.slow
def test_the_models_enclose_the_per_k_verifiers_det_at_k_101():
    """K det J_Phi's Bernstein coefficients of quadrant 30 of dart:101 from the per-K verifier's exact
    eigenvectors (even_vector, mode_vector, quadrant_nets, regularity_form) lie in the evaluator's ball on the
    point box (s, h) = (30/101, 1/101) of the sigma box holding sigma(101) = 4.48477 (box 0)."""
    path = Path(__file__).with_name("test_tagged_dart_charmap_script.py")
    spec = importlib.util.spec_from_file_location("charmap_script_test", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    k, q = 101, 30
    with ctx.workprec(128):
        ref = mod._verifier_kdet(k, q)
        models = DartModels(LO, HI, _hints(grid=12), 0, 128)
        ball = models.sigma_box(0).evaluate("R", "bulk", [(fmpq(q, k), fmpq(q, k)), (fmpq(1, k), fmpq(1, k))])
        values = [c for p in PIECES for c in ref[p]]
        assert all(ball.overlaps(c) for c in values)
        lo = min((c.lower() for c in values), key=lambda x: x)
        hi = max((c.upper() for c in values), key=lambda x: x)
        # tight: the ball exceeds the values' own span by the sigma box and the Cauchy tail only
        assert ball.upper() - ball.lower() < (hi - lo) + arb("0.05")
