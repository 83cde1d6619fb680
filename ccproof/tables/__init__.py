"""ccproof.tables (see DESIGN.md section 1)."""
