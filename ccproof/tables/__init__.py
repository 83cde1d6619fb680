"""ccproof.tables: the characteristic-map tables (exact, arb, float64), written once and read as caches by
the prover and the numerics (docs/tables.md)."""
