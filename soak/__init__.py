"""Soak and load drivers for the sim node (issue 5 items 4 and 6); see docs/hardening.md."""
