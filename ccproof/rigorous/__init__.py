"""ccproof.rigorous (see DESIGN.md section 1)."""
