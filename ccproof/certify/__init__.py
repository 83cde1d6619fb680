"""ccproof.certify (see DESIGN.md section 1)."""
