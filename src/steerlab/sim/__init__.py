"""Simulation: scenarios, the readable loop, the compiled (batch) engine and results."""
