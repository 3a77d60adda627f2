r"""Turning-circle trial: advance, transfer, tactical and steady diameter, steady speed and rate.

Procedure (van Amerongen 1982 Sec. 2.5.1; IMO MSC.137(76) / MSC/Circ.1053): the ship sails
straight at the approach speed; at the execute time ``t_0`` the rudder is ordered to
``delta`` and held until the ship has turned at least 540 deg with a steady rate of turn.

Definitions (IMO MSC/Circ.1053, 4.2.1), measured for the ship's reference point from the
execute position, with ``chi = |psi - psi_0|`` the heading change:

* advance: distance along the original course when ``chi = 90 deg``;
* transfer: distance perpendicular to it (towards the turn) when ``chi = 90 deg``;
* tactical diameter: distance perpendicular to the original course when ``chi = 180 deg``;
* steady turning diameter: ``D = 2 V / |r|`` with the steady speed ``V = sqrt(u^2 + v^2)`` and
  rate ``r``, averaged over the last full turn (also checked against a least-squares circle
  through the track of that turn: ``steady_diameter_fit_m``).

For a first-order Nomoto ship at constant speed ``U`` the steady values are ``r = K delta``
and ``D = 2 U / (K delta)`` (the tests check these closed forms).
IMO criteria (MSC.137(76) 5.3.1, for the maximum rudder angle): advance <= 4.5 L,
tactical diameter <= 5 L.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from steerlab.trials.imo_criteria import mark_model_scale, turning_criteria
from steerlab.trials.program import TrialProgramConfig
from steerlab.trials.runner import (TrialConditions, conditions_dict, heading_change, rudder_limit_check,
                                    run_until, speed_of, time_scale)
from steerlab.units import deg, ms_to_knots, rad

TURN_TARGET_DEG = 540.0
STEADY_TOL = 0.01   # relative spread of r over the last turn that counts as steady


@dataclass
class TurningTrial:
    result: object
    metrics: dict
    t0: float
    sign: float


def _interp_at(chi, target, t, *cols):
    """Values of ``cols`` where ``chi`` (monotone at first) first reaches ``target`` (linear)."""
    idx = np.flatnonzero(chi >= target)
    if len(idx) == 0:
        return None
    k = idx[0]
    if k == 0:
        return tuple(c[0] for c in (t,) + cols)
    f = (target - chi[k - 1]) / (chi[k] - chi[k - 1])
    return tuple(c[k - 1] + f * (c[k] - c[k - 1]) for c in (t,) + cols)


def fit_circle(x, y):
    """Least-squares circle through points (Kasa fit): ``(x_c, y_c, R)``."""
    A = np.column_stack([x, y, np.ones_like(x)])
    b = x * x + y * y
    c, *_ = np.linalg.lstsq(A, b, rcond=None)
    xc, yc = 0.5 * c[0], 0.5 * c[1]
    return xc, yc, math.sqrt(max(c[2] + xc * xc + yc * yc, 0.0))


def last_turn_window(chi, span=2.0 * math.pi):
    """Boolean mask of the samples of the last ``span`` [rad] of heading change."""
    return chi >= chi[-1] - span


def turning_metrics(res, t0: float, sign: float, L: float, U0: float, rudder_deg: float) -> dict:
    """Metrics of a recorded turning circle (see the module docstring). SI inside, units in keys."""
    t = res.time
    psi0 = res.psi[0]
    x0, y0 = np.interp(t0, t, res.col("x_n")), np.interp(t0, t, res.col("y_e"))
    dx, dy = res.col("x_n") - x0, res.col("y_e") - y0
    along = dx * math.cos(psi0) + dy * math.sin(psi0)
    across = sign * (-dx * math.sin(psi0) + dy * math.cos(psi0))
    chi = sign * heading_change(res, psi0)
    after = t >= t0
    ta, ca, aa, cx = (t[after], chi[after], along[after], across[after])
    m = {"rudder_deg": rudder_deg, "direction": "starboard" if sign > 0 else "port"}
    at90 = _interp_at(ca, 0.5 * math.pi, ta, aa, cx)
    at180 = _interp_at(ca, math.pi, ta, aa, cx)
    m["advance_m"] = at90[1] if at90 else math.nan
    m["transfer_m"] = at90[2] if at90 else math.nan
    m["tactical_diameter_m"] = at180[2] if at180 else math.nan
    m["time_to_90deg_s"] = at90[0] - t0 if at90 else math.nan
    m["time_to_180deg_s"] = at180[0] - t0 if at180 else math.nan
    win = after & last_turn_window(chi)
    r = res.r[win]
    V = speed_of(res)[win]
    r_ss = float(np.mean(r))
    V_ss = float(np.mean(V))
    m["steady_rate_of_turn_deg_s"] = float(deg(abs(r_ss)))
    m["steady_speed_m_s"] = V_ss
    m["steady_speed_kn"] = ms_to_knots(V_ss)
    m["steady_surge_m_s"] = float(np.mean(res.col("u")[win]))
    m["speed_ratio"] = V_ss / U0
    m["steady_drift_angle_deg"] = float(deg(np.mean(np.arctan2(-sign * res.col("v")[win], res.col("u")[win]))))
    m["steady_diameter_m"] = 2.0 * V_ss / abs(r_ss) if r_ss != 0.0 else math.inf
    _, _, R = fit_circle(res.col("x_n")[win], res.col("y_e")[win])
    m["steady_diameter_fit_m"] = 2.0 * R
    m["nondimensional_rate"] = abs(r_ss) * L / V_ss          # r' = r L / V
    m["heading_change_deg"] = float(deg(chi[-1]))
    spread = (np.max(r) - np.min(r)) / abs(r_ss) if r_ss != 0.0 else math.inf
    m["steady"] = bool(chi[-1] >= rad(TURN_TARGET_DEG) - 1e-9 and spread <= STEADY_TOL)
    for k in ("advance", "transfer", "tactical_diameter", "steady_diameter"):
        m[f"{k}_L"] = m[f"{k}_m"] / L
    return m


def run_turning(cond: TrialConditions, rudder_deg: float = 35.0, port: bool = False) -> TurningTrial:
    """Turning circle with ``rudder_deg`` to starboard (``port=True``: to port)."""
    cond = cond.resolved()
    rudder_limit_check(cond, rudder_deg)
    ts = time_scale(cond)
    sign = -1.0 if port else 1.0
    t0 = round(max(ts["L_over_U"], 10 * cond.dt), 1)
    r_guess = abs(ts["K"] * rad(rudder_deg)) if ts["K"] else ts["U"] / (2.5 * ts["L"])
    r_guess = min(max(r_guess, 0.05 * ts["U"] / ts["L"]), 2.0 * ts["U"] / ts["L"])
    duration = t0 + rad(TURN_TARGET_DEG) / r_guess + 3.0 * ts["slow"]

    def program(_):
        return TrialProgramConfig(kind="schedule", times=(t0,), values=(sign * rudder_deg,))

    def done(res):
        chi = sign * heading_change(res, res.psi[0])
        if chi[-1] < rad(TURN_TARGET_DEG):
            return False
        r = res.r[last_turn_window(chi)]
        return (np.max(r) - np.min(r)) <= STEADY_TOL * abs(np.mean(r))

    res, _ = run_until(program, cond, duration, done, label="turning-circle")
    m = turning_metrics(res, t0, sign, ts["L"], cond.speed, rudder_deg)
    m["imo"] = mark_model_scale(turning_criteria(m["advance_m"], m["tactical_diameter_m"], ts["L"], rudder_deg,
                                                 cond), cond)
    m["conditions"] = conditions_dict(cond)
    return TurningTrial(res, m, t0, sign)
