"""ccproof.evaluate (see DESIGN.md section 1)."""
