r"""Han's tracking differentiator (TD) and its time-optimal synthesis function ``fst``.

Source: LOS + ADRC berthing paper (2019), eqs (21)-(22), after Han (2009)::

    v1' = v2,   v2' = fst(v1 - v, v2, r, h0)                                        (21)

    d = r h0,  d0 = d h0,  y = x1 + h0 x2,  a0 = sqrt(d^2 + 8 r |y|)
    a = x2 + y / h0                  if |y| <= d0
        x2 + (a0 - d)/2 sgn(y)       otherwise
    fst = -r a / d                   if |a| <= d
          -r sgn(a)                  otherwise                                      (22)

(the paper prints ``y = x1 - u + h x2``, with ``u`` the target ``v``; steerlab passes the
tracking error ``x1 = v1 - v`` directly, wrapped to [-pi, pi) for a heading). ``r`` [rad/s^2]
bounds the acceleration of the tracked signal (the "tracking speed factor"), ``h0`` [s] is the
filtering factor. The TD is advanced by forward Euler at the controller sample time ``h``.
"""

from __future__ import annotations

import math

from steerlab.angles import wrap_to_pi
from steerlab.jit.numba_stamped import numba
from steerlab.records import Field, Layout

TD = Layout("TD state", "TD_", [
    Field("V1", "v1", "rad", "tracked heading v1 of (21)"),
    Field("V2", "v2", "rad/s", "its rate v2 of (21)"),
], size_name="N_TD")
TD.export(globals())     # TD_V1 = 0, TD_V2 = 1, N_TD = 2


@numba.njit(cache=True)
def fst(x1, x2, r, h0):
    """Eq (22): the TD acceleration for tracking error ``x1`` and rate ``x2``."""
    d = r * h0
    d0 = d * h0
    y = x1 + h0 * x2
    if abs(y) <= d0:
        a = x2 + y / h0
    else:
        a0 = math.sqrt(d * d + 8.0 * r * abs(y))
        a = x2 + 0.5 * (a0 - d) * math.copysign(1.0, y)
    if abs(a) <= d:
        return -r * a / d
    return -r * math.copysign(1.0, a)


@numba.njit(cache=True)
def td_step(v, i, v_target, r, h0, h):
    """Advance the TD state (layout :data:`TD`: a heading [rad] and its rate [rad/s]) held at
    offset ``i`` of ``v`` in place by one Euler step of (21)."""
    v1 = v[i + TD_V1]
    v2 = v[i + TD_V2]
    a = fst(wrap_to_pi(v1 - v_target), v2, r, h0)
    v[i + TD_V1] = wrap_to_pi(v1 + h * v2)
    v[i + TD_V2] = v2 + h * a
