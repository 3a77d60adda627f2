"""Guidance: references for the heading controller."""
