r"""Step metrics that mean something in waves: judged on the low-passed heading error.

In a seaway the heading error after a course change never settles in the usual sense: the
wave-frequency yaw (periods of encounter of 5-20 s) keeps ``|e|`` crossing any band of the
order of its amplitude until the end of the record, so "the last time ``|e|`` was outside
+-1 deg" measures the sea, not the autopilot (the default run of 0.2, sea state 6: 1385 s of
1500 s). An autopilot cannot and should not take that yaw out (van Amerongen 1982, 4.5.2:
the wave filter is there so that the rudder does *not* follow it); what it can do is bring the
*mean* heading to the new course. So, in waves, steerlab judges the step metrics on the
heading low-passed by a centred moving average (``t_c`` the onset of the last set-point
change; the heading is continuous through the change, the set heading need not be)::

    psi_L(t) = mean of psi over [t - T_avg/2, t + T_avg/2]   (cut to the record at its ends)
    sigma_w  = std of (psi - psi_L) over the second half of [t_c, t_end]
               (course keeping after the change: the wave-frequency yaw)
    in waves  <=>  sigma_w >= WAVE_YAW_STD_MIN (0.05 deg)

with ``T_avg = 60 s`` (:data:`T_AVG`): three periods of encounter of the longest sea-state-9
peak period met head on (20 s), so a centred mean over it takes out the wave yaw (a sinusoid of
period ``T_e`` is cut to ``|sin(pi T_avg/T_e)| / (pi T_avg/T_e)``: <= 5 % for ``T_e <= 20 s``).
In waves the overshoot, rise time and both settling times of
:func:`steerlab.metrics.step_metrics` are those of ``psi_L``; ``wave_yaw_std_deg`` =
``sigma_w`` [deg] and ``step_lowpass_s`` = ``T_avg`` say so in the metrics (``0`` = judged on
the raw heading, as in calm water). A run whose low-passed error still does not settle (a
slow limit cycle, following seas whose encounter period exceeds ``T_avg``) reports "not
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

T_AVG = 60.0
"""Length [s] of the centred moving average that takes out the wave-frequency yaw."""

WAVE_YAW_STD_MIN = math.radians(0.05)
"""Wave-frequency yaw std [rad] from which the step metrics are judged on the low-passed error."""


def centred_mean(time, x, window: float = T_AVG) -> np.ndarray:
    """Centred moving average of ``x`` over ``window`` seconds, cut to the record at its ends.

    Parameters
    ----------
    time : ndarray
        Sample times [s], uniformly spaced.
    x : ndarray
        Signal (any unit).
    window : float
        Window length [s]; ``n = 2 round(window / (2 dt)) + 1`` samples.

    Returns
    -------
    ndarray
        Same shape as ``x``.
    """
    x = np.asarray(x, dtype=float)
    if len(x) < 2:
        return x.copy()
    dt = float(time[1] - time[0])
    half = max(int(round(window / (2.0 * dt))), 0)
    c = np.concatenate([[0.0], np.cumsum(x)])
    i = np.arange(len(x))
    lo = np.maximum(i - half, 0)
    hi = np.minimum(i + half + 1, len(x))
    return (c[hi] - c[lo]) / (hi - lo)


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
    psi_l = centred_mean(time, psi)
    sel = time >= 0.5 * (t_c + time[-1])
    sigma = float(np.std((psi - psi_l)[sel])) if np.any(sel) else 0.0
    return sigma, psi_l
