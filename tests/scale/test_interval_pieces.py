"""The lam pieces of the k >= k0 certificate as tasks: the wave-by-wave search finds the serial pieces.

The piece prover is replaced by a stand-in that fails on wide pieces near a chosen lam (a real piece
takes minutes), so the bisection tree is uneven; the serial depth-first search and the waves must
return the same pieces in the same order and fail at the same ``max_pieces``.
"""

from fractions import Fraction

import pytest

from ccproof.certify import prover


@pytest.fixture
def fake_pieces(monkeypatch):
    calls = []

    def fake(exact, La, Lb, N, degree, trunc, prec, progress, label):
        calls.append(label)
        lo, hi = Fraction(int(La.p), int(La.q)), Fraction(int(Lb.p), int(Lb.q))
        hard = Fraction(6530, 10000)  # a lam where the stand-in needs narrow pieces
        if lo <= hard <= hi and hi - lo > Fraction(1, 4000):
            raise prover.ProofFailed(f"{label}: too wide")
        return {"regularity": {}, "cells": {}, "corner": {"width": str(hi - lo)}}

    monkeypatch.setattr(prover, "_prove_piece", fake)
    return calls


def test_waves_find_the_serial_pieces(fake_pieces):
    serial = prover.prove_interval(40, progress=False, max_pieces=16)
    waves = prover.prove_interval(40, progress=False, max_pieces=16, scheduler="serial")
    assert len(serial["pieces"]) >= 4  # the tree is uneven: several bisections near lam = 0.653
    assert waves == serial
    # the pieces tile [La, Lb]: each piece starts where the previous one ends
    for p, q in zip(serial["pieces"], serial["pieces"][1:]):
        assert p["lam"][1] == q["lam"][0]


def test_waves_give_up_at_max_pieces_like_serial(fake_pieces):
    needed = len(prover.prove_interval(40, progress=False, max_pieces=64)["pieces"])
    for sched in (None, "serial"):
        assert len(prover.prove_interval(40, progress=False, max_pieces=needed, scheduler=sched)["pieces"]) == needed
        with pytest.raises(prover.ProofFailed):
            prover.prove_interval(40, progress=False, max_pieces=needed - 1, scheduler=sched)
