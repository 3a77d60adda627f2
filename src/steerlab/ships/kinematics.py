r"""Planar kinematics shared by every ship model: body velocities to the earth frame.

Fossen (2011), eq (2.40) in the horizontal plane, with a uniform current (van Amerongen 1982,
Sec. 2.4.2: the current moves the track, not the heading)::

    x_n' = u cos psi - v sin psi + V_c cos beta_c
    y_e' = u sin psi + v cos psi + V_c sin beta_c

``u, v`` are the surge and sway speeds through the water [m/s] (``v = 0`` for models without
sway), ``V_c = w[W_CURRENT_SPEED]`` [m/s] the current speed and ``beta_c = w[W_CURRENT_DIR]``
[rad] the direction it flows towards, clockwise from north. The current terms are skipped
when ``V_c == 0`` (no cost, and exactly the numbers without current).
"""

import math

import numba

from steerlab.environment.channels import W_CURRENT_DIR, W_CURRENT_SPEED


@numba.njit(cache=True, inline="always")
def earth_velocity(psi, u, v, w, dx):
    """Write ``dx[0] = x_n'`` and ``dx[1] = y_e'`` [m/s] (see the module docstring)."""
    c = math.cos(psi)
    s = math.sin(psi)
    dx[0] = u * c - v * s
    dx[1] = u * s + v * c
    vc = w[W_CURRENT_SPEED]
    if vc != 0.0:
        dx[0] += vc * math.cos(w[W_CURRENT_DIR])
        dx[1] += vc * math.sin(w[W_CURRENT_DIR])
