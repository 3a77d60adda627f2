"""The designed wave filter's gain scale (issue 30, "wave filter on small ships").

The noise-adaptive gain ``k_psi = xi`` of the thesis' filter is per *sample*: the heading
estimate is corrected at a rate ``k_psi / h`` [1/s], so the same noise level ``xi`` gives a
filter ten times wider at a 0.1 s step than at the 1 s step its settings were tuned at, and
the wave yaw leaks into the estimate as ``(k_psi / h) / w_e`` of itself. On the small
Zeefakkel (wave yaw of about 5 deg std at a 7.5 s encounter period in sea state 5) that leak
reached the rudder as 9-14 reversals a minute. The designed filter scales the gain by
``gain_scale`` (:func:`steerlab.control.wave_filter.design_filter`), so its bandwidth in 1/s
is the tuning's at any step.

* The thesis filter, ``gains = "paper"``, an explicit setting and ASA (whose filter model is
  identified on line) keep ``gain_scale = 1``: no experiment number moves.
* Open loop, a known ship in a pure wave yaw: the designed filter at 0.1 s leaks about what it
  leaks at 1 s, and several times less than the unscaled gain at 0.1 s.
* Closed loop: the conformance case (Zeefakkel, Nomoto 10 deg, design speed, JONSWAP sea state
  5, PID behind the designed filter) holds the change with under 6 rudder reversals a minute
  (9.1 a minute before the scale; 0.12 now).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from steerlab.control import wave_filter as WF


def test_gain_scale_designed_only_where_the_filter_is_designed():
    assert WF.WaveFilterParams().gain_scale == 1.0
    assert WF.design_filter(WF.DESIGN_H).gain_scale == 1.0            # the tuning's own step: unchanged
    assert WF.design_filter(2.0).gain_scale == 1.0                     # never a gain above the noise level
    assert WF.design_filter(0.1).gain_scale == pytest.approx(WF.designed_gain_scale(0.1))
    assert WF.design_filter(0.1).gain_scale < 1.0
    assert WF.filter_params(None, 0.1, paper=True).gain_scale == 1.0
    assert WF.filter_params(None, 0.1, paper=False, identified=True).gain_scale == 1.0
    given = WF.WaveFilterSettings(gain_scale=0.5)
    assert WF.filter_params(given, 0.1, paper=False).gain_scale == 0.5


def _leak(pf: "WF.WaveFilterParams", h: float, seconds: float = 1800.0) -> float:
    """Std [rad] over the last 600 s of the heading estimate's error on a ship the filter's model
    knows (K 0.173 1/s, T 14.7 s: the Zeefakkel at 8 kn), steered by a slow rudder (5 deg at
    0.05 rad/s), in a wave yaw of 5 deg at 0.84 rad/s (its encounter frequency in sea state 5)."""
    K, T = 0.173, 14.7
    p = pf.pack()
    zf = np.zeros(WF.N_WF)
    WF.wave_filter_init(zf, 0.0, 0.0, 0.0)
    a = math.exp(-h / T)
    psi = r = 0.0
    n = int(round(seconds / h))
    keep = n - int(round(600.0 / h))
    err = []
    for k in range(n):
        t = (k + 1) * h
        d = 0.5 * (math.radians(5.0) * (math.sin(0.05 * (t - h)) + math.sin(0.05 * t)))
        drive = K * d - r                                   # the same step as the filter's model
        psi += h * r + (h - T * (1.0 - a)) * drive
        r += (1.0 - a) * drive
        WF.wave_filter_step(zf, p, K, T, psi + math.radians(5.0) * math.sin(0.84 * t),
                            math.radians(5.0) * math.sin(0.05 * t), h)
        if k >= keep:
            err.append(zf[WF.F_PSI] - psi)
    return float(np.std(err))


def test_the_designed_gain_keeps_the_bandwidth_of_the_tuning_at_a_short_step():
    at_tuning = _leak(WF.design_filter(1.0), 1.0)
    scaled = _leak(WF.design_filter(0.1), 0.1)
    unscaled = _leak(WF.design_filter(0.1)._replace(gain_scale=1.0), 0.1)
    assert unscaled > 2.5 * scaled
    assert scaled < 2.0 * at_tuning


def test_pid_behind_the_designed_filter_quiets_the_rudder_on_the_zeefakkel_in_sea_state_5():
    from steerlab.conformance.cases import SEA5, Case
    from steerlab.conformance.matrix import run_case
    from steerlab.conformance.points import operating_points
    from steerlab.ships.registry import get_ship

    ship = "zeefakkel-nomoto-10deg"
    point = next(p for p in operating_points(get_ship(ship)) if p.label == "design")
    out = run_case(Case(ship, "pid", point, SEA5))
    assert out.verdict == "steers", out.reason
    assert out.metrics["reversals_per_min"] < 6.0
    assert abs(out.metrics["final_error_deg"]) < 1.0
