r"""The thesis' simple wind model (van Amerongen 1982, Section 2.4.3, eqs 2.45-2.54).

The equations did not survive the text extraction; their standard form (the thesis' words,
and Fossen 1994, Guidance and Control of Ocean Vehicles, Section 6.1, which quotes them)::

    F_w = 0.5 rho_a C_w(gamma) V_wr^2 S                                   (2.45)
    X_w = 0.5 rho_a C_X(gamma) V_wr^2 S_wx                                (2.46)
    Y_w = 0.5 rho_a C_Y(gamma) V_wr^2 S_wy                                (2.47)
    N_w = 0.5 rho_a C_N(gamma) V_wr^2 S_wy L                              (2.48)
    C(gamma) = sum_k (a_k cos k gamma + b_k sin k gamma)                  (2.49)
    C_X = -c_x cos gamma,  C_Y = c_y sin gamma,  C_N = c_n sin 2 gamma    (2.50-2.52)

after Wagner (1967) / Isherwood (1973); Fossen gives ``c_x = 0.50-0.90``, ``c_y = 0.70-0.95``,
``c_n = 0.05-0.20`` (defaults here: the middles 0.7, 0.825, 0.125). ``S_wx`` is the frontal
and ``S_wy`` the lateral projected area above water, ``L`` the waterline length, ``V_wr``
the relative wind speed and ``gamma`` the relative wind angle.

Signs in steerlab (converted once, here): ``gamma`` is the direction the relative wind comes
FROM, clockwise from the bow (as ``psi_a`` of :mod:`steerlab.environment.wind_fujiwara`;
0 head wind, +pi/2 from starboard); forces in body axes (x forward, y starboard, N > 0 turns
the bow to starboard). A head wind pushes aft (``X < 0``); a wind from starboard pushes to
port (``Y < 0``); with ``c_n > 0`` a wind on the starboard bow turns the bow to port, away
from the wind (``N < 0``: the hull-like moment that turns a ship broadside; a ship with its
windage far aft has ``c_n < 0``)::

    X = -q S_wx c_x cos gamma,   Y = -q S_wy c_y sin gamma,   N = -q S_wy L c_n sin 2 gamma,
    q = 0.5 rho_a V_wr^2

Equivalent rudder (2.53)-(2.54), for ships without a wind model: for the first-order Nomoto
model ``tau r' + r = K (delta + delta_w)``, ``delta_w = -A sin 2 gamma`` where the amplitude
``A`` is "the maximum rudder angle (for 2 gamma = pi/2) ... necessary in the steady state to
compensate for this disturbance"; steerlab scales it with the relative wind speed,
``delta_w = -A (V_wr / V_ref)^2 sin 2 gamma`` (``A`` given at ``V_wr = V_ref``).
"""

from __future__ import annotations

import math

import numpy as np

from steerlab.environment.wind_fujiwara import RHO_AIR, relative_wind
from steerlab.errors import require_finite_range
from steerlab.jit.numba_stamped import numba

CX_DEFAULT = 0.7
CY_DEFAULT = 0.825
CN_DEFAULT = 0.125


@numba.njit(cache=True)
def thesis_wind_coefficients(cx, cy, cn, gamma):
    """Eqs (2.50)-(2.52) in steerlab axes: ``(C_X, C_Y, C_N)`` at relative wind angle ``gamma`` [rad]."""
    return -cx * math.cos(gamma), -cy * math.sin(gamma), -cn * math.sin(2.0 * gamma)


@numba.njit(cache=True)
def thesis_wind_force(cx, cy, cn, rho_a, S_wx, S_wy, L, V_wr, gamma):
    """Eqs (2.46)-(2.48): wind ``(X [N], Y [N], N [N m])`` in steerlab body axes (module doc)."""
    CX, CY, CN = thesis_wind_coefficients(cx, cy, cn, gamma)
    q = 0.5 * rho_a * V_wr * V_wr
    return q * S_wx * CX, q * S_wy * CY, q * S_wy * L * CN


def wind_equivalent_rudder(amplitude: float, v_ref: float, speed, psi, wind_speed, wind_from) -> np.ndarray:
    """Eq (2.54), scaled by the relative wind: ``-A (V_wr/V_ref)^2 sin 2 gamma`` [rad] per sample.

    ``speed`` [m/s] the ship's speed over ground along ``psi`` [rad] (arrays or scalars),
    ``wind_speed`` [m/s], ``wind_from`` [rad] the true wind (arrays or scalars).
    """
    require_finite_range("environment.wind_rudder.amplitude_deg [rad]", amplitude, -math.pi / 2, math.pi / 2)
    require_finite_range("environment.wind_rudder.reference_speed [m/s]", v_ref, 0.0, 100.0, lo_open=True)
    speed, psi, ws, wd = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (speed, psi, wind_speed, wind_from)))
    out = np.empty(speed.shape)
    for i in np.ndindex(speed.shape):
        vr, g = relative_wind(float(speed[i]), 0.0, float(psi[i]), float(ws[i]), float(wd[i]))
        out[i] = -amplitude * (vr / v_ref) ** 2 * math.sin(2.0 * g)
    return out


__all__ = ["RHO_AIR", "thesis_wind_coefficients", "thesis_wind_force", "wind_equivalent_rudder",
           "CX_DEFAULT", "CY_DEFAULT", "CN_DEFAULT"]
