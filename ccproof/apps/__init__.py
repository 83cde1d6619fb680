"""ccproof.apps (layer of docs/architecture.md)."""
