"""ccproof.apps (see DESIGN.md section 1)."""
