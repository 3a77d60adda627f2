"""Route-following and berthing indices of a recorded run with LOS / berthing guidance.

Computed from the guidance's own log (``Result.meta["guidance_log"]``: cross-track error,
leg, propeller order, sampled at the controller rate and held in between) and the states:

* ``mean_abs_xte_m``, ``max_abs_xte_m``: mean (rectangle rule over the run) and maximum of
  |cross-track error| [m], from t = 0 (so they include an initial offset)
* ``time_on_route_s``: time with |XTE| <= the tolerance (``[guidance] xte_tolerance_m``,
  default the acceptance radius R) [s]; ``time_on_route_pct`` of the run
* ``route_completed_s``: first time the last waypoint was reached (None: never)
* berthing only: ``rpm_zero_time_s`` (first time the propeller order is 0, Table 5 of the
  berthing paper), ``stop_time_s`` (first time after it that the speed is below the paper's
  limit, 1 kn full scale, Froude-scaled to the model: ``1 kn / sqrt(scale)``; None: never),
  ``berth_distance_m`` (D, the distance from the berth centre at the stop time, else at the
  end of the run), ``closest_approach_m``, ``berth_distance_end_m`` (at the end of the run: a ship below
  the limit still coasts), ``final_speed_kn`` (at that time, model scale),
  ``berthed`` (stopped, and D <= the success radius)
"""

from __future__ import annotations

import math

import numpy as np

ROUTE_METRIC_UNITS = {
    "mean_abs_xte_m": "m", "max_abs_xte_m": "m", "time_on_route_s": "s", "time_on_route_pct": "%",
    "route_completed_s": "s", "berth_distance_m": "m", "final_speed_kn": "kn",
    "rpm_zero_time_s": "s", "stop_time_s": "s", "closest_approach_m": "m", "berth_distance_end_m": "m",
    "berthed": "-",
}

KNOT = 1852.0 / 3600.0


def _first_time(time, mask):
    idx = np.flatnonzero(mask)
    return float(time[idx[0]]) if idx.size else None


def route_metrics(res) -> dict:
    """The indices above, or ``{}`` for a run without a route."""
    log = res.meta.get("guidance_log")
    plan = res.meta.get("guidance")
    if log is None or plan is None or plan.route is None:
        return {}
    t = res.time
    xte = np.abs(log["xte"])
    dt = res.dt if len(t) > 1 else 0.0
    T = dt * (len(t) - 1)
    w = xte[:-1] if len(t) > 1 else xte
    on = (w <= plan.xte_tolerance)
    out = {
        "mean_abs_xte_m": float(np.sum(w) * dt / T) if T > 0 else float(xte[0]),
        "max_abs_xte_m": float(np.max(xte)),
        "time_on_route_s": float(np.sum(on) * dt),
        "time_on_route_pct": float(100.0 * np.sum(on) * dt / T) if T > 0 else math.nan,
        "route_completed_s": _first_time(t, log["leg"] >= len(plan.route) - 1),
    }
    if plan.berth is not None:
        x = res.col("x_n")
        y = res.col("y_e")
        speed = np.hypot(res.col("u"), res.col("v"))
        dist = np.hypot(x - plan.berth[0], y - plan.berth[1])
        t0 = _first_time(t, log["rpm_cmd"] == 0.0)
        t_stop = None if t0 is None else _first_time(t, (t >= t0) & (speed <= plan.berth_speed_max))
        k = len(t) - 1 if t_stop is None else int(np.searchsorted(t, t_stop))
        D = float(dist[k])
        out["rpm_zero_time_s"] = t0
        out["stop_time_s"] = t_stop
        out["berth_distance_m"] = D
        out["closest_approach_m"] = float(np.min(dist))
        out["berth_distance_end_m"] = float(dist[-1])
        out["final_speed_kn"] = float(speed[k] / KNOT)
        out["berthed"] = bool(t_stop is not None and D <= plan.success_radius)
    return out
