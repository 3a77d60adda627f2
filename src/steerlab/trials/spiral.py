r"""Spiral (Dieudonné) and reversed spiral (Bech) trials: the spiral curve, course stability, loop.

Van Amerongen (1982) Sec. 2.3.2 and 2.5.1-2.5.2 (after Bech 1968):

* **Direct spiral**: the rudder is stepped ``+a, +a - s, ..., -a, ..., +a`` deg, each angle
  held until the rate of turn is steady; the steady rates form the spiral curve ``r(delta)``
  (Fig. 2.5). "To measure the hysteresis loop in both directions, the trial has to be repeated
  for rudder angles going in the opposite direction": the two branches differ inside the loop
  of a course-unstable ship.
* **Reversed spiral**: "the mean rudder angle needed to maintain a certain mean rate of
  turn" is measured (Fig. 2.6); here a PI yaw-rate hold (:mod:`steerlab.trials.rate_hold`)
  steps through set rates from ``-r_max`` to ``+r_max`` (denser near zero) and the mean
  rudder angle of each steady step gives ``delta = H(r)``, single-valued even inside the loop.

Course stability (Sec. 2.3.2): a ship is course-unstable when the reversed-spiral slope at
``r = 0`` is negative (``dH/dr < 0``; thesis: "course instability results in a negative value
of c1"). The slope is taken from the two measured points that bracket ``r = 0``.
Loop width (rudder): the largest drop of ``H`` while ``r`` increases,
``max_{r_i < r_j} (H(r_i) - H(r_j))`` [deg], i.e. the rudder range in which the direct spiral
has two turning branches (zero for a stable ship). Loop height (rate): the span between the
outer zero crossings of ``H``, i.e. the two residual rates of turn with the rudder amidships
that the pull-out also measures. The direct spiral gives only bounds on the width (its
resolution is the rudder step ``s``).

The cubic ``delta = c0 + c1 r + c2 r^2 + c3 r^3`` (thesis eq 2.26, steerlab sign, rudder in
deg, r in deg/s) is fitted by least squares to the reversed points and reported.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from steerlab.errors import require_finite_range
from steerlab.trials.program import TrialProgramConfig
from steerlab.trials.runner import TrialConditions, conditions_dict, rudder_limit_check, run_until, time_scale
from steerlab.units import deg, rad

SETTLE_FRACTION = 0.25   # last part of each step that must be steady and is averaged
STEADY_REL = 0.01        # relative change of r over that part that counts as steady


@dataclass
class SpiralTrial:
    direct: object          # Result of the direct spiral
    reversed: object        # Result of the reversed spiral
    metrics: dict
    step_times: np.ndarray
    rate_times: np.ndarray


def direct_schedule(max_rudder_deg: float, step_deg: float) -> np.ndarray:
    """Rudder angles [deg] ``+a ... -a ... +a`` with step ``s`` (``a`` a multiple of ``s`` or not)."""
    n = int(math.floor(max_rudder_deg / step_deg + 1e-9))
    down = max_rudder_deg - step_deg * np.arange(0, 2 * n + 1)
    if down[-1] > -max_rudder_deg + 1e-9:
        down = np.append(down, -max_rudder_deg)
    return np.concatenate([down, down[-2::-1]])


def rate_targets(r_max: float, n: int = 21) -> np.ndarray:
    """Set rates [rad/s] from ``-r_max`` to ``+r_max``, spaced quadratically (dense near zero)."""
    s = np.linspace(-1.0, 1.0, n)
    return r_max * np.sign(s) * s * s


def step_means(res, times, hold: float):
    """Per step: mean rudder angle, mean r over its last part, and whether r was steady there."""
    t = res.time
    r_all, d_all = res.r, res.delta
    r_scale = 1e-3 * float(np.max(np.abs(r_all))) + 1e-12
    out = []
    for i, t_i in enumerate(times):
        t_end = times[i + 1] if i + 1 < len(times) else t_i + hold
        a = t_end - SETTLE_FRACTION * (t_end - t_i)
        i0, i1 = np.searchsorted(t, [a, t_end])
        r = r_all[i0:i1]
        d = d_all[i0:i1]
        scale = max(abs(float(np.mean(r))), r_scale)
        steady = bool(abs(r[-1] - r[0]) <= STEADY_REL * scale)
        out.append((float(np.mean(d)), float(np.mean(r)), steady))
    return out


def loop_from_reversed(r, delta):
    """Loop of the reversed spiral from the measured points ``(r, delta)`` (any units).

    Returns ``(width, r_lo, r_hi)``: the largest drop of ``delta`` while ``r`` increases,
    ``max_{r_i < r_j} (delta_i - delta_j)``, and the rates where it starts and ends (the
    unstable branch); ``(0, nan, nan)`` for a monotone (course-stable) curve.
    """
    order = np.argsort(r)
    r, d = np.asarray(r)[order], np.asarray(delta)[order]
    best, lo, hi = 0.0, math.nan, math.nan
    run_max, i_max = -math.inf, 0
    for j in range(len(d)):
        if d[j] > run_max:
            run_max, i_max = d[j], j
        if run_max - d[j] > best:
            best, lo, hi = run_max - d[j], r[i_max], r[j]
    return float(best), float(lo), float(hi)


def zero_rudder_rates(r, delta):
    """Rates where the measured ``delta(r)`` crosses zero (linear interpolation), ascending.

    On a course-unstable ship the outer two are the residual rates of turn with the rudder
    amidships (the turning branches of the loop); their span is the loop height.
    """
    order = np.argsort(r)
    r, d = np.asarray(r)[order], np.asarray(delta)[order]
    out = []
    for k in range(len(d) - 1):
        if d[k] == 0.0:
            out.append(float(r[k]))
        elif d[k] * d[k + 1] < 0.0:
            out.append(float(r[k] - d[k] * (r[k + 1] - r[k]) / (d[k + 1] - d[k])))
    if d[-1] == 0.0:
        out.append(float(r[-1]))
    return out


def slope_at_zero(r, delta) -> float:
    """``dH/dr`` at ``r = 0`` from the two measured points bracketing it (or the nearest two)."""
    order = np.argsort(r)
    r, d = np.asarray(r)[order], np.asarray(delta)[order]
    k = int(np.searchsorted(r, 0.0))
    k = min(max(k, 1), len(r) - 1)
    if r[k - 1] == 0.0 and k >= 2 and r[k] > 0.0:
        return float((d[k] - d[k - 2]) / (r[k] - r[k - 2]))
    return float((d[k] - d[k - 1]) / (r[k] - r[k - 1]))


def direct_loop_bounds(points, step_deg: float) -> list[float]:
    """Bounds [deg] on the loop width from the direct spiral (its resolution is the rudder step).

    The rudder angles at which the down and up branches turn opposite ways span ``w0``; each
    jump lies less than one step outside them, so the width is in ``[w0, w0 + 2 step]``. When
    no angle differs, a loop narrower than two steps can still hide between the angles:
    ``[0, 2 step]``.
    """
    down, up = {}, {}
    for p in points:
        if p["branch"] == "down":
            down[round(p["rudder_deg"], 9)] = p["rate_deg_s"]
        elif p["branch"] == "up":
            up[round(p["rudder_deg"], 9)] = p["rate_deg_s"]
    differ = [dd for dd in down if dd in up and down[dd] * up[dd] < 0.0]
    if not differ:
        return [0.0, 2.0 * step_deg]
    w0 = float(max(differ) - min(differ))
    return [w0, w0 + 2.0 * step_deg]


def run_spiral(cond: TrialConditions, max_rudder_deg: float = 10.0, step_deg: float = 2.0,
               n_rates: int = 21, hold_s: float | None = None) -> SpiralTrial:
    """Direct and reversed spiral (see the module docstring); both on the same ship and gear."""
    cond = cond.resolved()
    rudder_limit_check(cond, max_rudder_deg, "max_rudder")
    require_finite_range("step", step_deg, 0.0, max_rudder_deg, lo_open=True)
    if not (5 <= n_rates <= 101):
        from steerlab.errors import InputError
        raise InputError("n_rates", f"must be in [5, 101], got {n_rates}")
    ts = time_scale(cond)
    hold = hold_s if hold_s is not None else max(8.0 * ts["slow"], 20.0 * ts["L_over_U"])
    require_finite_range("hold", hold, 0.0, 1e5, lo_open=True)
    rudders = direct_schedule(max_rudder_deg, step_deg)
    t0 = round(max(ts["L_over_U"], 10 * cond.dt), 1)
    holder = {}

    def direct_prog(duration):
        h = (duration - t0) / len(rudders)
        holder["times"] = t0 + h * np.arange(len(rudders))
        holder["hold"] = h
        return TrialProgramConfig(kind="schedule", times=tuple(holder["times"]), values=tuple(rudders))

    def steady(res, key):
        return all(s for _, _, s in step_means(res, holder[key], holder["hold" if key == "times" else "rhold"])[1:])

    res_d, _ = run_until(direct_prog, cond, t0 + hold * len(rudders), lambda r: steady(r, "times"),
                         max_doublings=2, label="spiral")
    sd = step_means(res_d, holder["times"], holder["hold"])
    n_down = int(np.argmin(rudders)) + 1
    points = []
    for i, ((dm, rm, ok), dc) in enumerate(zip(sd, rudders)):
        branch = "start" if i == 0 else ("down" if i < n_down else "up")
        points.append({"branch": branch, "rudder_deg": float(dc), "mean_rudder_deg": float(deg(dm)),
                       "rate_deg_s": float(deg(rm)), "steady": ok})

    r_max = 0.9 * max(abs(p["rate_deg_s"]) for p in points)
    targets = rate_targets(rad(r_max), n_rates)
    rhold = holder["hold"]

    def reversed_prog(duration):
        h = (duration - t0) / len(targets)
        holder["rtimes"] = t0 + h * np.arange(len(targets))
        holder["rhold"] = h
        return TrialProgramConfig(kind="rate_hold", times=tuple(holder["rtimes"]), values=tuple(deg(targets)))

    res_r, _ = run_until(reversed_prog, cond, t0 + rhold * len(targets), lambda r: steady(r, "rtimes"),
                         max_doublings=2, label="reversed-spiral")
    sr = step_means(res_r, holder["rtimes"], holder["rhold"])
    rpoints = [{"set_rate_deg_s": float(deg(tg)), "rate_deg_s": float(deg(rm)), "rudder_deg": float(deg(dm)),
                "steady": ok} for (dm, rm, ok), tg in zip(sr, targets)]
    rr = np.array([p["rate_deg_s"] for p in rpoints])
    dd = np.array([p["rudder_deg"] for p in rpoints])
    width, r_lo, r_hi = loop_from_reversed(rr, dd)
    zeros = zero_rudder_rates(rr, dd)
    slope = slope_at_zero(rr, dd)
    coef = np.polynomial.polynomial.polyfit(rr, dd, 3)
    unstable = slope < 0.0
    height = (zeros[-1] - zeros[0]) if (unstable and len(zeros) >= 3) else 0.0
    m = {
        "max_rudder_deg": max_rudder_deg, "step_deg": step_deg,
        "hold_direct_s": holder["hold"], "hold_reversed_s": holder["rhold"],
        "direct": points, "reversed": rpoints,
        "slope_at_zero_deg_per_deg_s": slope,
        "course_stable": bool(not unstable),
        "verdict": "course-unstable" if unstable else "course-stable",
        "loop_width_deg": width if unstable else 0.0,
        "loop_height_deg_s": height,
        "residual_rates_deg_s": [zeros[0], zeros[-1]] if (unstable and len(zeros) >= 3) else [],
        "unstable_rate_range_deg_s": [r_lo, r_hi] if (unstable and width > 0.0) else [],
        "loop_width_direct_bounds_deg": direct_loop_bounds(points, step_deg),
        "cubic_deg": {"c0": coef[0], "c1": coef[1], "c2": coef[2], "c3": coef[3],
                      "form": "delta[deg] = c0 + c1 r + c2 r^2 + c3 r^3, r in deg/s"},
        "all_steady": bool(all(p["steady"] for p in points[1:]) and all(p["steady"] for p in rpoints)),
    }
    m["conditions"] = conditions_dict(cond)
    return SpiralTrial(res_d, res_r, m, holder["times"], holder["rtimes"])
