r"""Manoeuvre program: hold a rate of turn (Bech's reversed-spiral test).

Van Amerongen (1982) Sec. 2.5.1: "Bech, 1968 has proposed modifying the conventional spiral
test and carrying out the reversed-spiral test. Instead of measuring [the rate of turn] as a
function of delta, the mean rudder angle needed to maintain a certain mean rate of turn is
being measured." Here a PI law on the yaw rate holds each set rate ``r_i`` of a staircase::

    e       = r_set(t) - r
    delta_c = sat_{u_max}( K_p e + K_i I )
    I      <- I + e h       only if not saturated, or if e drives the output back (clamping)

Packed parameters::

    p = [MODE, K_p [s], K_i [1], u_max [rad], n, t_1, r_1, ..., t_n, r_n]    (r [rad/s])

``r_set = 0`` before ``t_1``. State ``z[0] = I`` [rad]. The integral is not reset between
steps: it carries the rudder the ship needs. Gains: :func:`rate_hold_gains`.
"""

from __future__ import annotations

import math

import numpy as np

from steerlab.jit.numba_stamped import numba
from steerlab.ships.state import IR

R_KP, R_KI, R_UMAX, R_N, R_TABLE = 1, 2, 3, 4, 5


@numba.njit(cache=True)
def rate_hold_update(z, p, t, x, ref, h):
    """PI rudder order [rad] that holds the scheduled yaw rate (see the module docstring)."""
    n = int(p[R_N])
    r_set = 0.0
    for i in range(n):
        if t >= p[R_TABLE + 2 * i]:
            r_set = p[R_TABLE + 2 * i + 1]
        else:
            break
    e = r_set - x[IR]
    ud = p[R_KP] * e + p[R_KI] * z[0]
    umax = p[R_UMAX]
    u = min(max(ud, -umax), umax)
    if u == ud or e * ud < 0.0:
        z[0] += e * h
    return u


def rate_hold_gains(a: float, b: float, omega: float, zeta: float = 1.0) -> tuple[float, float]:
    r"""PI gains ``(K_p [s], K_i [1])`` placing the yaw-rate loop's poles.

    Design model (first-order Nomoto in rate form, any sign of ``a``)::

        r' = a r + b delta,     a = -1/T [1/s],   b = K/T [1/s^2]

    With ``delta = K_p e + K_i \int e`` the loop is ``s^2 + (b K_p - a) s + b K_i``; matching
    ``s^2 + 2 zeta omega s + omega^2`` gives ``K_p = (2 zeta omega + a)/b``,
    ``K_i = omega^2 / b``. Works for course-unstable ships (``a > 0``) as long as ``b > 0``.
    """
    if not (b > 0.0 and math.isfinite(b)):
        raise ValueError(f"rudder effectiveness b must be > 0, got {b}")
    kp = (2.0 * zeta * omega + a) / b
    ki = omega * omega / b
    return max(kp, 0.0), ki


def pack_rate_hold(mode: float, kp: float, ki: float, u_max: float, times, rates) -> np.ndarray:
    """``[mode, K_p, K_i, u_max, n, t_1, r_1, ...]`` (SI)."""
    times = np.asarray(times, dtype=float)
    rates = np.asarray(rates, dtype=float)
    if np.any(np.diff(times) <= 0.0):
        raise ValueError("schedule times must increase")
    table = np.column_stack([times, rates]).ravel()
    return np.concatenate([[float(mode), kp, ki, u_max, float(len(times))], table])
