"""ccproof.reparam (see DESIGN.md section 1)."""
