r"""Planar kinematics shared by every ship model: body velocities to the earth frame.

Fossen (2011), eq (2.40) in the horizontal plane, with a uniform current (van Amerongen 1982,
Sec. 2.4.2: the current moves the track, not the heading)::

    x_n' = u cos psi - v sin psi + V_c cos beta_c
    y_e' = u sin psi + v cos psi + V_c sin beta_c

``u, v`` are the surge and sway speeds through the water [m/s] (``v = 0`` for models without
sway), ``V_c`` [m/s] the current speed and ``beta_c`` [rad] the direction it flows towards,
clockwise from north; the kernel reads the current as its north and east components
``w[W_CURRENT_N] = V_c cos beta_c``, ``w[W_CURRENT_E] = V_c sin beta_c`` (written with the
speed and direction by :func:`steerlab.environment.channels.set_current`).

``cos psi`` and ``sin psi`` come from :func:`steerlab.sincos.sincos` (plain arithmetic, no
branches), so that the batch engine can vectorise this kernel across runs.
"""

from steerlab.environment.channels import W_CURRENT_E, W_CURRENT_N, W_RUDDER
from steerlab.jit.numba_stamped import numba
from steerlab.ships.state import IPSI, IR, IU, IV, IX, IY
from steerlab.sincos import sincos


@numba.njit(cache=True, inline="always")
def earth_velocity(psi, u, v, w, dx):
    """Write ``dx[IX] = x_n'`` and ``dx[IY] = y_e'`` [m/s] (see the module docstring)."""
    s, c = sincos(psi)
    dx[IX] = (u * c - v * s) + w[W_CURRENT_N]
    dx[IY] = (u * s + v * c) + w[W_CURRENT_E]


@numba.njit(cache=True, inline="always")
def planar_start(x, delta, w, dx):
    """The start every 3-DOF ship kernel shares (``esso``, ``mmg``, ``mmg_standard``, ``mss_tanker``).

    Reads ``psi, u, v, r`` from the planar state, writes the track rates (:func:`earth_velocity`)
    and ``dx[IPSI] = r``, and returns ``(psi, u, v, r, d)`` with ``d = delta + w[W_RUDDER]`` [rad],
    the rudder angle plus the equivalent rudder of the disturbance row (steerlab sign). Inlined
    into each kernel, so it costs nothing and the arithmetic is the kernels' own.
    """
    psi = x[IPSI]
    u = x[IU]
    v = x[IV]
    r = x[IR]
    earth_velocity(psi, u, v, w, dx)
    dx[IPSI] = r
    return psi, u, v, r, delta + w[W_RUDDER]
