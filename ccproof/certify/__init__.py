"""ccproof.certify: the prover (untrusted search) and the verifier (the trusted base, docs/trusted_base.md)."""
