"""Linter for URScript files."""
