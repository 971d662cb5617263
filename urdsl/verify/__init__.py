"""Offline verifier: run a program on a simulated robot and report findings."""
