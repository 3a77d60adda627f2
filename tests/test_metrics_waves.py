"""Step metrics in waves (steerlab.metrics_waves, metrics.step_metrics_in_waves).

A known response (a critically damped second-order turn onto the new course) plus a wave yaw
of known period and amplitude: the raw settling time measures the waves, the low-passed one
recovers the clean response's. Calm runs keep their raw step metrics bit for bit.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import steerlab as sl
from steerlab.metrics import compute_metrics, step_metrics, step_metrics_in_waves
from steerlab.metrics_waves import T_AVG, WAVE_YAW_STD_MIN, low_pass, savgol_weights, wave_yaw

DT = 0.1
T_C = 100.0
STEP = math.radians(20.0)


def _response(wave_deg: float = 0.0, period: float = 9.5, duration: float = 1500.0):
    """``(time, psi, psi_ref)``: a 20 deg change at 100 s, critically damped with w_n = 0.04
    rad/s, plus a wave yaw ``wave_deg sin(2 pi t / period)``."""
    t = np.arange(0.0, duration + DT / 2, DT)
    ref = np.where(t >= T_C, STEP, 0.0)
    tau = np.clip(t - T_C, 0.0, None)
    wn = 0.04
    clean = STEP * (1.0 - (1.0 + wn * tau) * np.exp(-wn * tau))
    return t, clean + math.radians(wave_deg) * np.sin(2.0 * math.pi * t / period), ref


def test_low_pass_takes_out_wave_periods_up_to_20_s_and_follows_a_cubic():
    t = np.arange(0.0, 600.0, DT)
    inner = (t > T_AVG) & (t < t[-1] - T_AVG)
    for lo, hi, bound in ((4.0, 10.0, 0.050), (10.0, 20.0, 0.103)):          # module doc
        for period in np.arange(lo, hi + 0.01, 0.25):
            x = np.sin(2.0 * math.pi * t / period + 0.3)
            assert np.max(np.abs(low_pass(t, x)[inner])) <= bound + 1e-3, period
    cubic = 1e-3 * t + 2e-6 * (t - 300.0) ** 2 - 3e-9 * (t - 300.0) ** 3
    np.testing.assert_allclose(low_pass(t, cubic)[inner], cubic[inner], atol=1e-9)
    parabola = 1e-3 * t + 2e-6 * (t - 300.0) ** 2                        # the ends: one parabola each
    np.testing.assert_allclose(low_pass(t, parabola), parabola, atol=1e-9)
    w = savgol_weights(450)
    assert w.sum() == pytest.approx(1.0) and np.allclose(w, w[::-1])


def test_in_waves_settling_is_the_clean_response_s_and_the_raw_one_is_the_sea_s():
    t, psi_clean, ref = _response()
    clean = step_metrics(t, psi_clean, ref)
    t, psi, ref = _response(wave_deg=0.8)
    raw = step_metrics(t, psi, ref)
    waves = step_metrics_in_waves(t, psi, ref)
    # the wave (0.8 deg amplitude) keeps |e| outside the 2 % band (0.4 deg) to the end
    assert raw["settling_time_2pct_s"] is None
    assert waves["step_lowpass_s"] == T_AVG
    assert waves["wave_yaw_std_deg"] == pytest.approx(0.8 / math.sqrt(2.0), rel=0.05)
    for key in ("settling_time_2pct_s", "settling_time_1deg_s"):
        assert waves[key] == pytest.approx(clean[key], abs=1.0), key
    assert waves["rise_time_s"] == pytest.approx(clean["rise_time_s"], abs=3.0)
    assert waves["overshoot_deg"] == pytest.approx(clean["overshoot_deg"], abs=0.05)


def test_below_the_threshold_the_raw_metrics_are_kept_bit_for_bit():
    t, psi, ref = _response(wave_deg=0.03)          # std 0.021 deg < 0.05 deg
    waves = step_metrics_in_waves(t, psi, ref)
    assert waves["step_lowpass_s"] == 0.0 and waves["wave_yaw_std_deg"] < math.degrees(WAVE_YAW_STD_MIN)
    assert {k: waves[k] for k in step_metrics(t, psi, ref)} == step_metrics(t, psi, ref)


def test_no_setpoint_change_gives_no_step_metrics():
    t = np.arange(0.0, 100.0, DT)
    out = step_metrics_in_waves(t, 0.01 * np.sin(t), np.zeros_like(t))
    assert all(v is None for v in out.values())


def test_wave_yaw_is_measured_away_from_the_turn():
    """The turn's curvature is not wave yaw: a clean response has sigma_w ~ 0."""
    t, psi, _ = _response()
    sigma, psi_l = wave_yaw(t, psi, T_C)
    assert sigma < 1e-3 * WAVE_YAW_STD_MIN and psi_l.shape == psi.shape


def test_calm_default_keeps_its_raw_step_metrics():
    """The default up to 0.1.0 (eq 39 noise, sigma_w ~ 0.005 deg): compute_metrics' step metrics
    are step_metrics' (the ones cross-checked with python-control in test_metrics)."""
    sc = sl.load_scenario(Path(__file__).resolve().parent.parent / "examples" / "scenarios" / "calm_default.toml")
    r = sl.simulate(sc.replace(duration=1500.0))
    m = compute_metrics(r)
    assert m["step_lowpass_s"] == 0.0 and m["wave_yaw_std_deg"] < 0.01
    raw = step_metrics(r.time, r.psi, r.psi_ref)
    assert {k: m[k] for k in raw} == raw
