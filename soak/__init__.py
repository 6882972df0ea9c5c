"""Soak and load drivers for the sim node; see docs/hardening.md."""
