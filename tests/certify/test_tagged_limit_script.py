"""scripts/tagged_c1_limit.py: its H(theta) against the verifier's own J_xy, and its exact identity check."""

import importlib.util
from pathlib import Path

import pytest
from flint import acb, arb, ctx, fmpq

from ccproof.certify.verify.statement import lam_of
from ccproof.certify.verify.tagged import labels
from ccproof.certify.verify.tagged_c1 import _jacobian
from ccproof.certify.verify.tagged_modes import mode_vector

SCRIPTS = Path(__file__).resolve().parents[2] / "scripts"


def _load():
    spec = importlib.util.spec_from_file_location("tagged_c1_limit", SCRIPTS / "tagged_c1_limit.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.mark.parametrize("fam,n", [("crease", 40), ("corner", 101)])
def test_h_is_the_verifiers_jacobian_times_the_ray_values(fam, n):
    # H uses f = v - v o R with v^(1,0) = 1, so f is 2 i sin(j theta) at ray 1's point (1,0); the verifier's
    # vectors (its own pivot, its sector indexing) normalized there give J with H = -4 sin(t) sin(2t) J.
    mod = _load()
    with ctx.workprec(128):
        pts = labels(fam, n)
        at = pts.index(("r", 1, 1, 0))
        vec = {}
        for j in (1, 2):
            f = mode_vector(fam, n, j, lam_of(arb(fmpq(j, n)).cos_pi()))
            vec[j] = [v if isinstance(v, fmpq) else (v / f[at]).real for v in f]
        J = _jacobian(fam, n, 0, vec[1], vec[2])
        th = arb.pi() / n
        h = mod.H(acb(th))
        assert h.imag.contains(0) and abs(h.imag) < 1e-20
        assert h.real.overlaps(-4 * th.sin() * (2 * th).sin() * J)
        assert h.real > 0 and J < 0


def test_reflection_identity_fails_for_a_perturbed_stencil(monkeypatch):
    mod = _load()
    assert mod.reflection_identity()
    block = mod.ring_block

    def perturbed(w):
        rows = block(w)
        rows[0][1] += w / 100  # not symmetric under w -> 1/w with the swap
        return rows

    monkeypatch.setattr(mod, "ring_block", perturbed)
    assert not mod.reflection_identity()
