r"""Pull-out trial: rudder back to midships after a steady turn; residual rate of turn.

IMO MSC/Circ.1053 (explanatory notes to MSC.137(76)), 3.4.3: after a steady turn with
``delta`` (typically 20 deg) the rudder is returned to midships and the rate of turn is
recorded until it is steady. "If the ship is stable, the rate of turn will decay to zero for
turns to both port and starboard. If the ship is unstable, the rate of turn will reduce to
some residual rate of turn." The residual rates to starboard and port bracket the spiral
loop: their difference is the loop height (:mod:`steerlab.trials.spiral`).

Program: :mod:`steerlab.trials.rudder_schedule` with ``[t_0: delta, t_r: 0]``; ``t_r`` is
chosen from the ship's time scale and the run is lengthened until the turn before ``t_r``
and the rate at the end are steady. Verdict: course-stable when both residual rates are
below ``RESIDUAL_FRACTION`` of the steady rate before release.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from steerlab.trials.program import TrialProgramConfig
from steerlab.trials.runner import TrialConditions, conditions_dict, rudder_limit_check, run_until, time_scale
from steerlab.units import deg

RESIDUAL_FRACTION = 0.02
STEADY_REL = 0.01


@dataclass
class PulloutTrial:
    results: dict            # "starboard" / "port" -> Result
    metrics: dict
    t0: float
    t_release: dict


def _window_mean(res, a, b):
    i0, i1 = np.searchsorted(res.time, [a, b])
    r = res.r[i0:i1]
    return float(np.mean(r)), float(r[-1] - r[0])


def run_pullout(cond: TrialConditions, rudder_deg: float = 20.0) -> PulloutTrial:
    """Pull-out after a steady ``rudder_deg`` turn to starboard and to port."""
    cond = cond.resolved()
    rudder_limit_check(cond, rudder_deg)
    ts = time_scale(cond)
    t0 = round(max(ts["L_over_U"], 10 * cond.dt), 1)
    span = max(6.0 * ts["slow"], 30.0 * ts["L_over_U"])
    results, t_rel, sides = {}, {}, {}
    for side, sign in (("starboard", 1.0), ("port", -1.0)):
        holder = {}

        def program(duration, sign=sign, holder=holder):
            holder["t_r"] = t0 + 0.5 * (duration - t0)
            return TrialProgramConfig(kind="schedule", times=(t0, holder["t_r"]),
                                      values=(sign * rudder_deg, 0.0))

        def done(res, holder=holder):
            tr_, end = holder["t_r"], res.time[-1]
            w = 0.2 * (end - tr_)
            r_turn, d_turn = _window_mean(res, tr_ - w, tr_)
            r_end, d_end = _window_mean(res, end - w, end)
            return abs(d_turn) <= STEADY_REL * abs(r_turn) and abs(d_end) <= STEADY_REL * max(abs(r_end), 0.05 * abs(r_turn))

        res, converged = run_until(program, cond, t0 + 2.0 * span, done, max_doublings=3,
                                     label="pull-out")
        tr_, end = holder["t_r"], res.time[-1]
        w = 0.2 * (end - tr_)
        r_turn, _ = _window_mean(res, tr_ - w, tr_)
        r_res, _ = _window_mean(res, end - w, end)
        results[side], t_rel[side] = res, tr_
        sides[side] = {"steady_rate_before_deg_s": float(deg(r_turn)), "residual_rate_deg_s": float(deg(r_res)),
                       "residual_fraction": abs(r_res) / abs(r_turn) if r_turn != 0.0 else math.nan,
                       "release_time_s": tr_, "steady": bool(converged)}
    stable = all(s["residual_fraction"] <= RESIDUAL_FRACTION for s in sides.values())
    m = {"rudder_deg": rudder_deg, "starboard": sides["starboard"], "port": sides["port"],
         "course_stable": bool(stable), "verdict": "course-stable" if stable else "course-unstable",
         "loop_height_deg_s": 0.0 if stable else
         sides["starboard"]["residual_rate_deg_s"] - sides["port"]["residual_rate_deg_s"],
         "conditions": conditions_dict(cond)}
    return PulloutTrial(results, m, t0, t_rel)
