r"""Zig-zag (Kempf) trial: overshoot angles, time to second execute, period; IMO limits.

The program is :mod:`steerlab.trials.zigzag_logic` (rudder ``delta`` reversed each time the
heading change reaches ``+-psi_s``). Definitions (IMO MSC/Circ.1053, 4.2.2), with
``e = psi - psi_0`` measured in the direction of the first rudder:

* execute points: the rudder orders (``t_0``, then each reversal ``t_1, t_2, ...``);
* k-th overshoot angle: how far the heading goes beyond ``+-psi_s`` after the k-th reversal,
  i.e. ``max e - psi_s`` between ``t_1`` and ``t_2``, ``-min e - psi_s`` between ``t_2``
  and ``t_3``, and so on;
* time to second execute (initial turning time): ``t_1 - t_0``; the distance sailed by then
  is the initial-turning distance (IMO 5.3.2 for the 10/10 zig-zag: <= 2.5 L);
* time to check yaw: from a reversal to the heading extremum that follows it;
* period: ``t_3 - t_1`` (the first full rudder cycle; ``periods_s`` lists every
  ``t_{k+2} - t_k`` recorded).

IMO limits: :mod:`steerlab.trials.imo_criteria` (eq 32 of the berthing paper for 10/10).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from steerlab.trials.imo_criteria import mark_model_scale, zigzag_criteria
from steerlab.trials.program import TrialProgramConfig
from steerlab.trials.runner import (TrialConditions, conditions_dict, heading_change, rudder_limit_check,
                                    run_until, speed_of, time_scale)
from steerlab.errors import require_finite_range
from steerlab.units import deg, rad

N_REVERSALS = 4   # t_1 .. t_4: three overshoots and two half periods


@dataclass
class ZigzagTrial:
    result: object
    metrics: dict
    t0: float
    sign: float
    heading_deg: float


def reversal_times(time, delta_cmd, t0: float) -> np.ndarray:
    """Times [s] at which the rudder order changes sign after ``t0`` (the execute points)."""
    after = time >= t0
    c = np.sign(delta_cmd[after])
    idx = np.flatnonzero((c[1:] * c[:-1]) < 0.0) + 1
    return time[after][idx]


def zigzag_metrics(res, t0: float, sign: float, rudder_deg: float, heading_deg: float, L: float,
                   U0: float) -> dict:
    """Metrics of a recorded zig-zag (see the module docstring)."""
    t = res.time
    e = sign * heading_change(res, res.psi[0])
    psi_s = rad(heading_deg)
    tr = reversal_times(t, res.delta_cmd, t0)
    m = {"rudder_deg": rudder_deg, "heading_deg": heading_deg,
         "first_rudder": "starboard" if sign > 0 else "port",
         "execute_times_s": [t0] + [float(x) for x in tr]}
    over, check = [], []
    for k in range(len(tr) - 1):
        win = (t >= tr[k]) & (t <= tr[k + 1])
        ek = e[win] if k % 2 == 0 else -e[win]
        i = int(np.argmax(ek))
        over.append(float(deg(ek[i] - psi_s)))
        check.append(float(t[win][i] - tr[k]))
    m["overshoot_angles_deg"] = over
    m["time_to_check_yaw_s"] = check
    m["first_overshoot_deg"] = over[0] if len(over) > 0 else math.nan
    m["second_overshoot_deg"] = over[1] if len(over) > 1 else math.nan
    m["time_to_second_execute_s"] = float(tr[0] - t0) if len(tr) else math.nan
    periods = [float(tr[k + 2] - tr[k]) for k in range(len(tr) - 2)]
    m["periods_s"] = periods
    m["period_s"] = periods[0] if periods else math.nan
    if len(tr):
        seg = (t >= t0) & (t <= tr[0])
        dist = float(np.trapezoid(speed_of(res)[seg], t[seg]))
    else:
        dist = math.nan
    m["initial_turning_distance_m"] = dist
    m["initial_turning_distance_L"] = dist / L
    m["time_to_second_execute_nd"] = m["time_to_second_execute_s"] * U0 / L   # t U / L
    m["period_nd"] = m["period_s"] * U0 / L
    m["complete"] = len(tr) >= N_REVERSALS
    return m


def run_zigzag(cond: TrialConditions, rudder_deg: float = 10.0, heading_deg: float = 10.0,
               port_first: bool = False) -> ZigzagTrial:
    """``rudder_deg``/``heading_deg`` zig-zag, first rudder to starboard (``port_first``: to port)."""
    cond = cond.resolved()
    rudder_limit_check(cond, rudder_deg)
    require_finite_range("heading", heading_deg, 0.0, 90.0, lo_open=True)
    ts = time_scale(cond)
    sign = -1.0 if port_first else 1.0
    t0 = round(max(ts["L_over_U"], 10 * cond.dt), 1)
    duration = t0 + 30.0 * ts["L_over_U"] + 4.0 * ts["slow"]

    def program(_):
        return TrialProgramConfig(kind="zigzag", t0=t0, rudder_deg=sign * rudder_deg, heading_deg=heading_deg)

    def done(res):
        return len(reversal_times(res.time, res.delta_cmd, t0)) >= N_REVERSALS

    res, _ = run_until(program, cond, duration, done, label="zig-zag")
    L_over_V = ts["L_over_U"]
    m = zigzag_metrics(res, t0, sign, rudder_deg, heading_deg, ts["L"], cond.speed)
    m["L_over_V_s"] = L_over_V
    m["imo"] = mark_model_scale(zigzag_criteria(rudder_deg, heading_deg, m["overshoot_angles_deg"], L_over_V,
                                                m["initial_turning_distance_L"]), cond)
    m["conditions"] = conditions_dict(cond)
    return ZigzagTrial(res, m, t0, sign, heading_deg)
