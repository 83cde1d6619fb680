"""ccproof.tables (layer of docs/architecture.md)."""
