r"""Manoeuvre program: the zig-zag (Kempf) rudder logic.

Van Amerongen (1982) Sec. 2.5.1 (after Kempf 1944; Fig. 2.21): "a certain rudder angle is
given which is kept constant until the change of heading equals [a fixed value]. At that
moment the same amount of rudder is given in the opposite direction and so on."
IMO MSC.137(76) names it delta/psi (e.g. 10/10, 20/20). Packed parameters::

    p = [MODE, t_0, delta_1, psi_s, psi_0]
        t_0     execute time [s] (rudder ordered to delta_1)
        delta_1 first rudder order [rad], signed (> 0: starboard first)
        psi_s   heading change that reverses the rudder [rad] (> 0)
        psi_0   initial heading [rad]

Controller state ``z[0]``: the present order (``delta_1`` at the start). With
``e = wrap_to_pi(psi - psi_0)`` the order switches to ``-|delta_1|`` when it is to starboard
and ``e >= psi_s``, and to ``+|delta_1|`` when it is to port and ``e <= -psi_s`` (checked at
every controller sample, so the switch lags the crossing by at most one sample).
"""

from __future__ import annotations

import numpy as np

from steerlab.angles import wrap_to_pi
from steerlab.jit.numba_stamped import numba
from steerlab.ships.state import IPSI

Z_T0, Z_DELTA, Z_PSI_S, Z_PSI0 = 1, 2, 3, 4
N_PARAMS = 5


@numba.njit(cache=True)
def zigzag_update(z, p, t, x, ref, h):
    """Zig-zag rudder order [rad]; ``z[0]`` holds the present order (see the module docstring)."""
    if t < p[Z_T0]:
        return 0.0
    e = wrap_to_pi(x[IPSI] - p[Z_PSI0])
    a = abs(p[Z_DELTA])
    if z[0] > 0.0 and e >= p[Z_PSI_S]:
        z[0] = -a
    elif z[0] < 0.0 and e <= -p[Z_PSI_S]:
        z[0] = a
    return z[0]


def pack_zigzag(mode: float, t0: float, delta1: float, psi_s: float, psi0: float) -> np.ndarray:
    """``[mode, t_0, delta_1, psi_s, psi_0]`` (SI)."""
    return np.array([mode, t0, delta1, psi_s, psi0], dtype=float)
