r"""Performance indices of a heading-control run.

Integral indices come from the on-line accumulator (:mod:`steerlab.metrics_online`), so a
batch run and a recorded run give identical numbers. Definitions (e = wrap_to_pi(psi_ref -
psi), delta the actual rudder angle; rectangle rule on the simulation grid):

* IAE = int |e| dt,  ISE = int e^2 dt,  ITAE = int t |e| dt           (reported in degrees)
* speed-loss criterion ``J = (0.0076 / T) int (e^2 + lambda delta^2) dt`` (e, delta in deg;
  Witkowska & Smierzchalski eq (30), lambda = 0.1 there; Koyama/Norrbin)
* rudder travel ``sum |d delta|``, rudder reversals (direction changes), mean |delta|
* step metrics about the last set-point change: overshoot, 10-90 % rise time, settling time
  into +-2 % of the change and into +-1 deg, all measured from the change (the conventions of
  python-control's ``step_info``, tested on ``examples/scenarios/calm_default.toml``). A run without a set-point change
  has no step metrics (``None``, printed "n/a"); to time the rejection of a disturbance use
  :func:`settling_time` with ``t0`` = its onset.
* in waves (the wave-frequency yaw after the change has a std of 0.05 deg or more) the step
  metrics of ``steerlab run``, Monte-Carlo and the tuning costs are judged on the heading
  low-passed by a 90 s zero-phase Savitzky-Golay smoother (:func:`step_metrics_in_waves`,
  :mod:`steerlab.metrics_waves`); ``wave_yaw_std_deg`` and ``step_lowpass_s`` (90 in waves,
  0 otherwise) say which. :func:`step_metrics` itself, which the paper experiments call,
  always judges the raw heading.
"""

from __future__ import annotations

import math

import numpy as np

from steerlab.angles import wrap_to_pi, wrap_to_pi_array
from steerlab.guidance.route_metrics import ROUTE_METRIC_UNITS, route_metrics
from steerlab.metrics_online import (M_ABS_DELTA, M_D2_DEG, M_DURATION, M_E2_DEG, M_IAE, M_ISE, M_ITAE,
                                     M_MAX_ABS_E, M_REVERSALS, M_TRAVEL, online_metrics_from_result)

R2D = 180.0 / math.pi

METRIC_UNITS = {
    "iae_deg_s": "deg s", "ise_deg2_s": "deg^2 s", "itae_deg_s2": "deg s^2",
    "speed_loss_J": "-", "lambda": "-", "max_abs_error_deg": "deg", "final_error_deg": "deg",
    "overshoot_deg": "deg", "overshoot_pct": "%", "rise_time_s": "s",
    "settling_time_2pct_s": "s", "settling_time_1deg_s": "s", "wave_yaw_std_deg": "deg", "step_lowpass_s": "s",
    "rudder_travel_deg": "deg", "rudder_reversals": "-", "mean_abs_rudder_deg": "deg",
    "max_abs_rudder_deg": "deg", "min_speed_kn": "kn",
    **ROUTE_METRIC_UNITS,
}


def speed_loss_J(acc, lam: float = 0.1) -> float:
    """``J = (0.0076/T) int (e^2 + lambda delta^2) dt`` from an accumulator (degrees)."""
    T = acc[M_DURATION]
    return 0.0076 / T * (acc[M_E2_DEG] + lam * acc[M_D2_DEG]) if T > 0 else math.nan


def integral_metrics(acc, lam: float = 0.1) -> dict:
    """The integral indices of one accumulator row, in degrees."""
    T = acc[M_DURATION]
    return {
        "iae_deg_s": acc[M_IAE] * R2D,
        "ise_deg2_s": acc[M_ISE] * R2D**2,
        "itae_deg_s2": acc[M_ITAE] * R2D,
        "speed_loss_J": speed_loss_J(acc, lam),
        "lambda": lam,
        "max_abs_error_deg": acc[M_MAX_ABS_E] * R2D,
        "rudder_travel_deg": acc[M_TRAVEL] * R2D,
        "rudder_reversals": int(acc[M_REVERSALS]),
        "mean_abs_rudder_deg": acc[M_ABS_DELTA] / T * R2D if T > 0 else math.nan,
    }


def last_setpoint_change(time, psi_ref):
    """``(t_change, psi_before, step)`` of the last set-point change, or ``None``.

    With a rate-limited reference the change starts where psi_ref starts to move.
    """
    d = np.abs(wrap_to_pi_array(np.diff(psi_ref)))
    moving = np.nonzero(d > 1e-12)[0]
    if len(moving) == 0:
        return None
    # start of the last contiguous stretch of movement
    k_end = moving[-1]
    k = k_end
    while k - 1 >= 0 and d[k - 1] > 1e-12:
        k -= 1
    before = psi_ref[k]
    after = psi_ref[k_end + 1]
    return float(time[k + 1]), float(before), float(wrap_to_pi(after - before))


def _last_outside(time, outside, t0):
    """Settling time: from ``t0`` to the end of the last sample outside the band."""
    idx = np.nonzero(outside)[0]
    if len(idx) == 0:
        return 0.0
    if idx[-1] == len(time) - 1:
        return None  # still outside at the end: did not settle
    return float(time[idx[-1] + 1] - t0)


def settling_time(time, error, band, t0: float = 0.0):
    """Time [s] from ``t0`` until ``|error|`` stays within ``band`` (same units as ``error``).

    ``None`` if it is still outside the band at the end of the record; ``0.0`` if it never
    leaves the band after ``t0``. Use ``t0`` = the onset of a disturbance to time its rejection.
    """
    time = np.asarray(time)
    sel = time >= t0
    return _last_outside(time[sel], np.abs(np.asarray(error)[sel]) > band, t0)


def step_metrics(time, psi, psi_ref) -> dict:
    """Overshoot, rise and settling times about the last set-point change.

    Parameters
    ----------
    time : ndarray
        Sample times [s].
    psi, psi_ref : ndarray
        Heading and set heading [rad].

    Returns
    -------
    dict
        ``overshoot_deg`` [deg], ``overshoot_pct`` [%], ``rise_time_s`` (10 % to 90 % of the
        change) [s], ``settling_time_2pct_s`` (into +-2 % of the change) and
        ``settling_time_1deg_s`` (into +-1 deg) [s], all from the last change. Every value is
        ``None`` when ``psi_ref`` never changes (nothing to measure from); a settling time is
        also ``None`` when the response is still outside its band at the end.
    """
    out = {"overshoot_deg": None, "overshoot_pct": None, "rise_time_s": None,
           "settling_time_2pct_s": None, "settling_time_1deg_s": None}
    e = wrap_to_pi_array(psi_ref - psi)
    change = last_setpoint_change(time, psi_ref)
    if change is None:
        return out
    t_c, before, step = change
    sel = time >= t_c
    tt = time[sel]
    p = wrap_to_pi_array(psi[sel] - before) / step      # normalised response, 1 = new heading
    peak = float(np.max(p))
    out["overshoot_pct"] = max(0.0, (peak - 1.0) * 100.0)
    out["overshoot_deg"] = max(0.0, (peak - 1.0) * abs(step) * R2D)
    i10 = np.nonzero(p >= 0.1)[0]
    i90 = np.nonzero(p >= 0.9)[0]
    if len(i10) and len(i90):
        out["rise_time_s"] = float(tt[i90[0]] - tt[i10[0]])
    out["settling_time_2pct_s"] = _last_outside(tt, np.abs(p - 1.0) > 0.02, t_c)
    out["settling_time_1deg_s"] = _last_outside(tt, np.abs(e[sel]) > math.radians(1.0), t_c)
    return out


def step_metrics_in_waves(time, psi, psi_ref) -> dict:
    """:func:`step_metrics`, judged on the low-passed heading when the run is in waves.

    Parameters
    ----------
    time : ndarray
        Sample times [s], uniformly spaced.
    psi, psi_ref : ndarray
        Heading and set heading [rad].

    Returns
    -------
    dict
        The keys of :func:`step_metrics` plus ``wave_yaw_std_deg`` (std of the heading about
        its 90 s zero-phase low-pass in the second half of the record after the last change
        [deg]) and ``step_lowpass_s`` (the low-pass' window [s] when the step metrics were
        judged on the low-passed heading, i.e. when ``wave_yaw_std_deg >= 0.05``; else 0 and
        the step metrics are :func:`step_metrics`'s).
        Both are ``None`` without a set-point change. Definitions and the threshold's reason:
        :mod:`steerlab.metrics_waves`.
    """
    from steerlab.metrics_waves import T_AVG, WAVE_YAW_STD_MIN, wave_yaw

    time = np.asarray(time)
    change = last_setpoint_change(time, psi_ref)
    if change is None:
        return {**step_metrics(time, psi, psi_ref), "wave_yaw_std_deg": None, "step_lowpass_s": None}
    sigma, psi_l = wave_yaw(time, psi, change[0])
    in_waves = sigma >= WAVE_YAW_STD_MIN
    out = step_metrics(time, psi_l if in_waves else psi, psi_ref)
    out["wave_yaw_std_deg"] = sigma * R2D
    out["step_lowpass_s"] = T_AVG if in_waves else 0.0
    return out


def compute_metrics(res, lam: float = 0.1) -> dict:
    """All indices of a recorded :class:`~steerlab.sim.result.Result` (JSON-ready dict).

    A run that follows a route (LOS or berthing guidance) has no set-point step: its step
    metrics (overshoot, rise and settling times) and the sea's wave yaw are ``None`` ("n/a"),
    and the route's indices (:func:`steerlab.guidance.route_metrics.route_metrics`) judge it."""
    acc = res.meta.get("online_metrics")
    if acc is None:
        acc = online_metrics_from_result(res)
    m = integral_metrics(acc, lam)
    route = route_metrics(res)                # LOS / berthing runs only
    step = step_metrics_in_waves(res.time, res.psi, res.psi_ref)
    if route:
        # the set heading moves with the cross-track error and turns at every waypoint: there is
        # no set-point step to judge (an "overshoot" of several hundred per cent of the last
        # small correction), and the sea's yaw cannot be told from the turns; n/a, and the
        # route's own indices (cross-track error, time on route) judge the run
        step = dict.fromkeys(step)
    m.update(step)
    m["final_error_deg"] = float(res.heading_error[-1] * R2D)
    m["max_abs_rudder_deg"] = float(np.max(np.abs(res.delta)) * R2D)
    if "u" in res.state_names:
        speed = np.hypot(res.col("u"), res.col("v"))
        m["min_speed_kn"] = float(np.min(speed) / (1852.0 / 3600.0))
    m.update(route)
    return {k: (float(v) if isinstance(v, (np.floating,)) else v) for k, v in m.items()}
