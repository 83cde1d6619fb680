"""The prover: certificates it writes verify; it finds none for a map that folds."""

import numpy as np
import pytest
from flint import fmpq_poly

from ccproof.certify import prover as P
from ccproof.certify import verify as V
from ccproof.certify.verify import maps as M
from ccproof.certify.verify import replay as R
from ccproof.tables.numeric import load_table


def test_prover_output_verifies(tmp_path):
    cert = P.prove_valence(5, progress=False)
    path = P.write_certificate(cert, tmp_path / "k005.json")
    assert V.verify_file(path, log=lambda s: None)
    assert cert["N"] == 3


def _steep_weight(p):
    # a weight that drops from 1 to 0 within 1/50: its gradient makes G fold near the corner
    if p == 0:
        return fmpq_poly([1, -50])
    return fmpq_poly([0])


def test_folding_weight_gives_no_certificate_and_forged_one_fails(monkeypatch):
    genuine = P.prove_valence(5, progress=False)
    monkeypatch.setattr(M, "weight_piece", _steep_weight)
    with pytest.raises(P.ProofFailed):
        P.prove_valence(5, progress=False)
    lines = []
    assert not V.verify_certificate(genuine, log=lines.append)
    assert any("FAIL" in s for s in lines)


def _bezier(net, s, t):
    from math import comb

    bs = np.stack([comb(3, i) * s**i * (1 - s) ** (3 - i) for i in range(4)])
    bt = np.stack([comb(3, i) * t**i * (1 - t) ** (3 - i) for i in range(4)])
    return np.einsum("i...,j...,ijd->...d", bs, bt, net)


def _b(x):
    """The weight b of R5 in floats, straight from B-splines (independent of the verifier)."""
    def B(z):
        z = np.abs(z)
        return np.where(z <= 1, (4 - 6 * z**2 + 3 * z**3) / 6, np.where(z <= 2, (2 - z) ** 3 / 6, 0.0))
    return B(6 * x + 1) + B(6 * x) + B(6 * x - 1)


@pytest.mark.parametrize("k", [3, 5, 6, 8, 13, 14])
def test_certified_corner_minimum_against_float_sampling(k):
    """det J_G / h^2 on the corner, from finite differences of G itself (no polynomial algebra):
    on the actual layers i = N..N+6 it stays above the certified bound; with the scale variables
    decoupled as in the certificate (rho, kappa independent in (0, 1]) its sampled minimum is
    within 0.01 of the bound, i.e. the bound is tight for the statement it certifies."""
    import json

    from ccproof.tables.format import certificates_dir

    cert = json.loads((certificates_dir() / "injectivity" / f"k{k:03d}.json").read_text())
    bound = min(float(R.parse_decimal(b["bound"])) for n in cert["parts"]["corner"] for b in cert["parts"]["corner"][n])
    tab = load_table(k)
    lam, N = tab.lam, cert["N"]
    s, t = np.meshgrid(np.linspace(0, 1, 41), np.linspace(0, 1, 41), indexing="ij")
    offs = {0: (0.5, 0.0), 1: (0.5, 0.5), 2: (0.0, 0.5)}
    eps = 1e-6

    def det_over_h2(p, sc, h):
        def G(ss, tt):
            P_ = _bezier(tab.bezier[p], ss, tt) * sc
            y = np.stack([(offs[p][0] + ss / 2) * h, (offs[p][1] + tt / 2) * h], -1)
            w = (_b(P_[..., 0]) * _b(P_[..., 1]))[..., None]
            return w * y + (1 - w) * P_
        ds = (G(s + eps, t) - G(s - eps, t)) / (2 * eps)
        dt = (G(s, t + eps) - G(s, t - eps)) / (2 * eps)
        return ((ds[..., 0] * dt[..., 1] - ds[..., 1] * dt[..., 0]) / h**2).min()

    layers = min(det_over_h2(p, lam**i, 2.0**-i) for i in range(N, N + 7) for p in range(3))
    assert layers >= bound - 1e-6
    relaxed = np.inf
    for rho in np.linspace(0.1, 1, 10):
        for kappa in (1e-4, 1e-2, 0.3, 1.0):
            sc = lam**N * rho ** (1 / 3)
            h = sc**4 / ((2 * lam**4) ** N * kappa)
            relaxed = min(relaxed, min(det_over_h2(p, sc, h) for p in range(3)))
    assert relaxed >= bound - 1e-5
    assert relaxed - bound < 0.01
