"""ccproof.inverse (see DESIGN.md section 1)."""
