r"""Integral action on the heading error with conditional-integration anti-windup.

Added to the rudder order of the laws without one of their own (sliding mode, backstepping A
and B) in their design rule, so that a constant yaw moment (a ship's asymmetry, a propeller
side force, wind) leaves no steady heading error::

    u = u_law + k_i xi,      xi' = wrap(psi_ref - psi)          (Fossen 2011, Sec. 12.2.7:
    k_i = (omega_n / 10) omega_n^2 / b                            Ki = omega_n Kp / 10)

``omega_n^2 / b`` [rad/rad] is the proportional gain of a PD loop with natural frequency
``omega_n`` on ``r' = -a r + b delta``. Anti-windup (conditional integration): ``xi`` is frozen
while the order is limited, unless the error would bring it back, and ``|k_i xi|`` never
exceeds the limit ``u_max``. With ``k_i = 0`` (the paper presets) the order is the law's own,
bit for bit. And the integral is off in course changes: it runs only while the heading error
changes slower than ``r_band = omega_n INTEGRAL_BAND / 4`` (``INTEGRAL_BAND`` = 5 deg, a quarter
of the reference turn; the reference turn's yaw rate peaks near ``0.37 omega_n`` x 20 deg): a
ship held on or off her course by a yaw moment, not one turning onto it, as the classic
autopilot's integral is off in turns (van Amerongen 1982, Fig. 3.3), so a turn's transient does
not charge it (with ``omega_n`` ~ 0.007 rad/s on a slow ship the charge took longer than
1 600 s to run out). This holds within 5 deg of the course too: the final approach of a turn,
whose error is small but still closing faster than ``r_band``, charged the integral as well
(backstepping B on the B-481 at 0.97 kn, ``omega_n`` = 0.0024 rad/s: the last 5 deg took
1 000 s and the charge overshot the course by 1.2 deg, which ran out at ``omega_n / 10``,
~4 000 s). The design may start the integral at the ship model's straight-course rudder
(:data:`steerlab.control.design_context.HELM_RULE`).
"""

from __future__ import annotations

from steerlab.jit.numba_stamped import numba

#: ``k_i = omega_n Kp / INTEGRAL_DIVISOR`` with ``Kp = omega_n^2 / b`` (Fossen 2011, Sec. 12.2.7).
INTEGRAL_DIVISOR = 10.0
#: 5 deg [rad]: the turn detector's scale, ``r_band = omega_n INTEGRAL_BAND TURN_RATE_FRACTION``.
INTEGRAL_BAND = 0.08726646259971647
#: ``r_band = omega_n INTEGRAL_BAND TURN_RATE_FRACTION`` [rad/s]: the turn detector of the integral.
TURN_RATE_FRACTION = 0.25


def integral_gain(omega_n: float, b: float) -> float:
    """``k_i`` [1/s] of the rule above for ``omega_n`` [rad/s] and ``b = K/T`` [1/s^2]."""
    return omega_n ** 3 / (INTEGRAL_DIVISOR * b)


@numba.njit(cache=True)
def integral_step(z, iz, ki, e, edot, r_band, u_law, umax, h):
    """The limited order ``u_law + ki z[iz]`` [rad]; advances ``z[iz]`` (the integral of the heading
    error ``e`` [rad], rate ``edot`` [rad/s], over the sample ``h`` [s]) by conditional integration;
    ``r_band`` [rad/s]: the integral runs only while ``|edot| < r_band`` (off in course changes)."""
    u = u_law + ki * z[iz]
    us = min(max(u, -umax), umax)
    if ki > 0.0 and abs(edot) < r_band and (u == us or e * u < 0.0):
        lim = umax / ki
        z[iz] = min(max(z[iz] + h * e, -lim), lim)
    return us
