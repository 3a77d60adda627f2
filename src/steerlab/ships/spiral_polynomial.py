r"""The (reversed) spiral polynomial shared by the Norrbin and Bech models and identification.

Steady turning of a ship is summarised by the reversed-spiral characteristic: the rudder
angle that holds a steady rate of turn ``r`` (Bech 1968; van Amerongen 1982, Sec. 2.3.2,
eq 2.26 in standard form)::

    H(r) = c3 r^3 + c2 r^2 + c2a r|r| + c1 r + c0

``c0`` (hull asymmetry, single-screw flow) and ``c2`` (the thesis' and Morawski's quadratic
term) make the curve asymmetric; ``c2a r|r|`` is the symmetric quadratic of Fossen's form of
Norrbin's model (use one or the other; the unused one is 0). ``c1 < 0`` means a
course-unstable ship. The units of the coefficients follow from those of ``H`` and ``r``; in
steerlab kernels ``r`` is in rad/s.
"""

from __future__ import annotations

from steerlab.jit.numba_stamped import numba
import numpy as np


@numba.njit(cache=True)
def spiral_polynomial(r, c0, c1, c2, c2a, c3):
    """``H(r) = c3 r^3 + c2 r^2 + c2a r|r| + c1 r + c0`` (see the module docstring)."""
    return ((c3 * r + c2) * r + c1) * r + c0 + c2a * r * abs(r)


def spiral_polynomial_array(r, c0, c1, c2, c2a, c3) -> np.ndarray:
    """Vectorised :func:`spiral_polynomial` for plotting and fitting (same formula)."""
    r = np.asarray(r, dtype=float)
    return ((c3 * r + c2) * r + c1) * r + c0 + c2a * r * np.abs(r)
