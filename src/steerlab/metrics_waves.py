r"""Step metrics that mean something in waves: judged on the low-passed heading.

In a seaway the heading error after a course change never settles in the usual sense: the
wave-frequency yaw (periods of encounter of 5-20 s) keeps ``|e|`` crossing any band of the
order of its amplitude until the end of the record, so "the last time ``|e|`` was outside
+-1 deg" measures the sea, not the autopilot (the default run of 0.2, sea state 6: 1385 s of
1500 s). An autopilot cannot and should not take that yaw out (van Amerongen 1982, 4.5.2:
the wave filter is there so that the rudder does *not* follow it); what it can do is bring the
*mean* heading to the new course. So, in waves, steerlab judges the step metrics on the
heading low-passed without phase lag (``t_c`` the onset of the last set-point change; the
heading is continuous through the change, the set heading need not be)::

    psi_L(t) = quadratic least-squares fit to psi over [t - T_avg/2, t + T_avg/2], at t
               (Savitzky-Golay smoother; the first / last window's parabola at the ends)
    sigma_w  = std of (psi - psi_L) over the second half of [t_c, t_end]
               (course keeping after the change: the wave-frequency yaw)
    in waves  <=>  sigma_w >= WAVE_YAW_STD_MIN (0.05 deg)

with ``T_avg = 90 s`` (:data:`T_AVG`). The smoother follows a turn's curvature exactly up to a
cubic (a moving average would not: on a critically damped 20 deg turn, ``w_n`` 0.04 rad/s, a
60 s mean moved the 10-90 % rise time by 12 s; this smoother moves it by 3 s and the settling
times by under 1 s) and cuts a sinusoidal yaw of period ``T_e`` to at most 5 % for
``T_e <= 10 s`` (the default sea's encounter period is 9.5 s) and 10.3 % for ``T_e <= 20 s``
(the peak period of sea state 9 met head on; ``tests/test_metrics_waves.py``).
In waves the overshoot, rise time and both settling times of
:func:`steerlab.metrics.step_metrics` are those of ``psi_L``; ``wave_yaw_std_deg`` =
``sigma_w`` [deg] and ``step_lowpass_s`` = ``T_avg`` say so in the metrics (``0`` = judged on
the raw heading, as in calm water). A run whose low-passed error still does not settle (a
slow limit cycle, following seas whose encounter period is of the order of ``T_avg``) reports "not
settled" (``None``). Below the threshold nothing changes: calm runs and the eq (39) noise of
the paper experiments (``sigma_w`` about 0.005 deg) keep their raw step metrics bit for bit.

The threshold is steerlab's choice: 1/20 of the 1-deg band, so the wave yaw (about +-3
``sigma_w``) could move a raw 1-deg settling time by more than a few samples. Calm default
(eq 39 noise): 0.005 deg; JONSWAP sea state 5 (Esso, 45 deg): about 0.08 deg; sea state 6:
about 0.35 deg.
"""

from __future__ import annotations

import math

import numpy as np

T_AVG = 90.0
"""Length [s] of the zero-phase low-pass (quadratic Savitzky-Golay) that takes out the wave yaw."""

WAVE_YAW_STD_MIN = math.radians(0.05)
"""Wave-frequency yaw std [rad] from which the step metrics are judged on the low-passed error."""


def savgol_weights(m: int) -> np.ndarray:
    """Weights of the quadratic (= cubic) Savitzky-Golay smoother over ``2 m + 1`` samples.

    ``c_k = 3 (3 m^2 + 3 m - 1 - 5 k^2) / ((2m - 1)(2m + 1)(2m + 3))``, ``k = -m..m``
    (Savitzky & Golay 1964, Anal. Chem. 36:1627; the least-squares parabola's centre value).
    They sum to 1 and reproduce any polynomial of degree <= 3 exactly.
    """
    k = np.arange(-m, m + 1, dtype=float)
    return 3.0 * (3.0 * m * m + 3.0 * m - 1.0 - 5.0 * k * k) / ((2.0 * m - 1.0) * (2.0 * m + 1.0) * (2.0 * m + 3.0))


def low_pass(time, x, window: float = T_AVG) -> np.ndarray:
    """``x`` smoothed by the quadratic Savitzky-Golay filter over ``window`` seconds (zero phase).

    Parameters
    ----------
    time : ndarray
        Sample times [s], uniformly spaced.
    x : ndarray
        Signal (any unit).
    window : float
        Window length [s]: ``2 m + 1`` samples, ``m = round(window / (2 dt))``.

    Returns
    -------
    ndarray
        Same shape as ``x``. Within ``m`` samples of either end of the record the value is that of
        the least-squares parabola through the first (last) ``2 m + 1`` samples; a record shorter
        than the window is fitted by one parabola.
    """
    x = np.asarray(x, dtype=float)
    n = len(x)
    if n < 4:
        return x.copy()
    dt = float(time[1] - time[0])
    m = max(int(round(window / (2.0 * dt))), 2)
    if n < 2 * m + 1:
        u = np.arange(n, dtype=float)
        return np.polyval(np.polyfit(u, x, 2), u)
    out = np.empty(n)
    out[m:n - m] = np.convolve(x, savgol_weights(m), mode="valid")
    u = np.arange(2 * m + 1, dtype=float)
    out[:m] = np.polyval(np.polyfit(u, x[:2 * m + 1], 2), u[:m])
    out[n - m:] = np.polyval(np.polyfit(u, x[n - 2 * m - 1:], 2), u[m + 1:])
    return out


def wave_yaw(time, psi, t_c: float) -> tuple[float, np.ndarray]:
    """``(sigma_w [rad], psi_L [rad])``: the wave-frequency yaw in course keeping and the low-passed heading.

    Parameters
    ----------
    time : ndarray
        Sample times [s], uniformly spaced.
    psi : ndarray
        Heading [rad] (unwrapped here before averaging).
    t_c : float
        Onset of the last set-point change [s]; ``sigma_w`` is taken over the second half of
        ``[t_c, t_end]``, away from the turn, whose curvature a 60 s mean does not follow.
    """
    time = np.asarray(time)
    psi = np.unwrap(np.asarray(psi, dtype=float))
    psi_l = low_pass(time, psi)
    sel = time >= 0.5 * (t_c + time[-1])
    sigma = float(np.std((psi - psi_l)[sel])) if np.any(sel) else 0.0
    return sigma, psi_l
