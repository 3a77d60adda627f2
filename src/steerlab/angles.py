"""Angle helpers. Radians inside; degrees only at the edges."""

import math

import numba


@numba.njit(cache=True, inline="always")
def wrap_to_pi(angle):
    """Wrap an angle [rad] to the half-open interval [-pi, pi).

    A 359 deg -> 1 deg course change is therefore a +2 deg turn:
    ``wrap_to_pi(radians(1) - radians(359)) == radians(2)``.
    """
    return (angle + math.pi) % (2.0 * math.pi) - math.pi


def wrap_to_2pi(angle: float) -> float:
    """Wrap an angle [rad] to [0, 2*pi) (a compass heading)."""
    return angle % (2.0 * math.pi)
