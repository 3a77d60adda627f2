"""Unit conversions used at the edges of steerlab (CLI, TOML, plots, reports)."""

import math

KNOT = 1852.0 / 3600.0
"""One knot in m/s."""

G = 9.81
"""Gravitational acceleration [m/s^2]."""


def knots_to_ms(v_kn: float) -> float:
    """Speed in knots -> m/s."""
    return v_kn * KNOT


def ms_to_knots(v_ms: float) -> float:
    """Speed in m/s -> knots."""
    return v_ms / KNOT


def deg(x):
    """Radians -> degrees (works on floats and numpy arrays)."""
    return x * (180.0 / math.pi)


def rad(x):
    """Degrees -> radians (works on floats and numpy arrays)."""
    return x * (math.pi / 180.0)


def rps_to_rpm(n: float) -> float:
    """Propeller rate rev/s -> rev/min."""
    return n * 60.0


def rpm_to_rps(n: float) -> float:
    """Propeller rate rev/min -> rev/s."""
    return n / 60.0
