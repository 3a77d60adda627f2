"""The wave filter's yaw-bias state (steerlab.control.wave_filter, ``bias_gain``).

* Off in the thesis' filter and with ``gains = "paper"`` (every experiment keeps its numbers);
  on in the filter designed for a sample time.
* The error dynamics of the alpha-beta-gamma corrector are stable for every gain the
  noise-adaptive rule can give (0 < k_psi <= 1).
* What it is for: a ship whose low-frequency behaviour the filter's Nomoto model gets wrong (here
  a constant yaw acceleration the model does not know). With the bias state the heading and
  yaw-rate estimates converge to the truth and the noise level ``xi`` stays at its floor; without
  it the estimate keeps an offset and ``xi`` rises (the filter starts to pass the waves).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from steerlab.control import wave_filter as WF


def test_bias_state_is_off_in_the_thesis_filter_and_on_in_the_designed_one():
    assert WF.WaveFilterParams().bias_gain == 0.0
    assert WF.filter_params(None, 0.1, paper=True).bias_gain == 0.0
    assert WF.filter_params(None, 0.1, paper=False).bias_gain == 1.0
    assert WF.design_filter(1.0).bias_gain == 1.0


@pytest.mark.parametrize("k_psi", [0.002, 0.004, 0.02, 0.1, 0.5, 0.9, 1.0])
def test_alpha_beta_gamma_error_dynamics_are_stable(k_psi):
    """Spectral radius < 1 of the corrector on the pure chain psi'' = b (the filter with tau -> inf)."""
    h = 0.1
    k_r = k_psi * k_psi / (2.0 - k_psi)
    gamma = k_r * k_r / (2.0 * k_psi)
    F = np.array([[1.0, h, h * h / 2.0], [0.0, 1.0, h], [0.0, 0.0, 1.0]])
    gains = np.array([k_psi, k_r / h, gamma / h ** 2])
    M = (np.eye(3) - np.outer(gains, [1.0, 0.0, 0.0])) @ F
    assert np.max(np.abs(np.linalg.eigvals(M))) < 1.0


def _run(bias_gain: float, n: int = 40000, h: float = 0.1):
    """Filter a ship ``tau r' + r = K delta + tau b`` (rudder 0, unknown bias b) in a wave yaw of
    1 deg at 0.8 rad/s with the model ``K, tau`` and no bias; returns the filter state, the true
    low-frequency heading and yaw rate, b, and the heading estimate's error over the last 600 s
    (wrapped, rad)."""
    K, tau, b = 0.1, 50.0, 2e-5
    pf = WF.WaveFilterParams(T_lf=60.0, T_pow=60.0, P0=1e-10, xi_min=0.002, bias_gain=bias_gain).pack()
    zf = np.zeros(WF.N_WF)
    WF.wave_filter_init(zf, 0.0, 0.0, 0.0)
    psi = r = 0.0
    a = math.exp(-h / tau)
    err = []
    for k in range(n):
        psi += h * r + (h - tau * (1.0 - a)) * (tau * b - r)      # exact step of the true ship
        r += (1.0 - a) * (tau * b - r)
        WF.wave_filter_step(zf, pf, K, tau, psi + math.radians(1.0) * math.sin(0.8 * (k + 1) * h), 0.0, h)
        if k >= n - 6000:
            err.append(math.remainder(zf[WF.F_PSI] - psi, 2.0 * math.pi))
    return zf, psi, r, b, np.array(err)


def test_the_bias_state_removes_the_offset_a_wrong_model_leaves():
    zf, psi, r, b, err = _run(1.0)
    off, _, _, _, err_off = _run(0.0)
    assert zf[WF.F_BIAS] == pytest.approx(b, rel=0.1)
    assert zf[WF.F_R] == pytest.approx(r, rel=0.05)
    assert np.max(np.abs(err)) < math.radians(0.1)      # the waves (1 deg) out, the heading kept
    assert zf[WF.F_XI] < 0.004                          # near the floor: little model error left to see
    assert off[WF.F_XI] > 4.0 * zf[WF.F_XI]             # the thesis filter reads the model error as calm
    assert np.std(err_off) > 2.0 * np.std(err)          # ... and lets more of the waves through
