"""ccproof.algebra (see DESIGN.md section 1)."""
