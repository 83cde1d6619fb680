"""ccproof.algebra (layer of docs/architecture.md)."""
