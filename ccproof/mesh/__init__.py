"""ccproof.mesh (see DESIGN.md section 1)."""
