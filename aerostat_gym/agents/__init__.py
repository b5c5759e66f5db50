"""Baseline controllers (winch LQR) and response metrics for the aerostat environment."""
