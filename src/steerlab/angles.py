"""Angle helpers. Radians inside; degrees only at the edges."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any, overload

from steerlab.jit.numba_stamped import numba

if TYPE_CHECKING:
    import numpy as np


@numba.njit(cache=True, inline="always")
def wrap_to_pi(angle: float) -> float:
    """Wrap an angle [rad] to the half-open interval [-pi, pi).

    A 359 deg -> 1 deg course change is therefore a +2 deg turn:
    ``wrap_to_pi(radians(1) - radians(359)) == radians(2)``.
    """
    a = angle + math.pi
    if 0.0 <= a < 2.0 * math.pi:       # fast path, bit-identical: fmod(a, 2 pi) == a here
        return a - math.pi
    return a % (2.0 * math.pi) - math.pi


@overload
def wrap_to_2pi(angle: float) -> float: ...
@overload
def wrap_to_2pi(angle: np.ndarray) -> np.ndarray: ...
def wrap_to_2pi(angle: Any) -> Any:
    """Wrap an angle [rad] (a float or a numpy array) to [0, 2*pi) (a compass heading), strictly.

    ``a % (2 pi)`` alone rounds a tiny negative angle (``-1e-17``) to exactly ``2 pi``; that
    value is north, so it is returned as 0.
    """
    a = angle % (2.0 * math.pi)
    if hasattr(a, "shape") and getattr(a, "ndim", 0) > 0:       # a numpy array: elementwise
        a[a >= 2.0 * math.pi] = 0.0
        return a
    return 0.0 if a >= 2.0 * math.pi else a


def wrap_to_pi_array(angle: object) -> np.ndarray:
    """:func:`wrap_to_pi` for numpy arrays (the kernel itself is scalar): same numbers."""
    import numpy as np

    return (np.asarray(angle, dtype=float) + math.pi) % (2.0 * math.pi) - math.pi
