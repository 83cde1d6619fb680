"""The published injectivity certificates are what the prover writes today, byte for byte (so the
prover and the verifier agree on the statement's forms), and they verify."""

import pytest

from ccproof.certify import prover as P
from ccproof.certify.verify import verify_file
from ccproof.tables.format import certificates_dir

PUBLISHED = certificates_dir() / "injectivity"


@pytest.mark.parametrize("k", [3, 6, 14])
def test_single_valences_regenerate_byte_for_byte(k, tmp_path):
    out = P.write_certificate(P.prove_valence(k, progress=False), tmp_path / f"k{k:03d}.json")
    assert out.read_bytes() == (PUBLISHED / f"k{k:03d}.json").read_bytes()
    assert verify_file(out, log=lambda line: None)


@pytest.mark.slow
@pytest.mark.parametrize("k0, trunc", [(40, 2), (10, 3)])
def test_interval_certificates_regenerate_byte_for_byte(k0, trunc, tmp_path):
    cert = P.prove_interval(k0, progress=False, truncation_degree=trunc)
    out = P.write_certificate(cert, tmp_path / f"k_ge_{k0}.json")
    assert out.read_bytes() == (PUBLISHED / f"k_ge_{k0}.json").read_bytes()
