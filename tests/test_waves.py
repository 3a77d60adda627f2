"""Wave noise of eq (39), held white noise and the disturbance array."""

import math

import numpy as np
import pytest
from scipy.linalg import expm

from steerlab.environment.channels import N_CHANNELS, W_RUDDER
from steerlab.environment.disturbance import Disturbance, build_disturbance
from steerlab.environment.waves import (band_pass_eq39, coloured_noise, held_white_noise,
                                        stationary_std_eq39)
from steerlab.errors import InputError
from steerlab.units import rad


def _reference_eq39(u, dt):
    """Exact ZOH response of 10.8 s / (s^2 + 0.672 s + 2.6729) from rest (controllable form).

    Output k uses the state at t_k, i.e. the inputs held over steps 0..k-1 only.
    """
    A = np.array([[0.0, 1.0], [-2.6729, -0.672]])
    B = np.array([0.0, 1.0])
    C = np.array([0.0, 10.8])
    M = np.zeros((3, 3))
    M[:2, :2] = A * dt
    M[:2, 2] = B * dt
    Md = expm(M)
    Ad, Bd = Md[:2, :2], Md[:2, 2]
    x = np.zeros(2)
    y = np.empty(len(u))
    for k in range(len(u)):
        y[k] = C @ x
        x = Ad @ x + Bd * u[k]
    return y


def test_stationary_std_formula():
    # var = P b^2 / (2 a1)
    assert stationary_std_eq39() == pytest.approx(math.sqrt(1e-4 * 10.8**2 / (2 * 0.672)))
    assert stationary_std_eq39() == pytest.approx(0.0932, abs=1e-4)
    assert stationary_std_eq39(4e-4) == pytest.approx(2 * stationary_std_eq39())


def test_held_white_noise_holds_samples():
    rng = np.random.default_rng(5)
    n, dt, ts = 1003, 0.1, 0.5
    w = held_white_noise(n, dt, rng, ts, 1e-4)
    assert w.shape == (n + 1,)
    hold = 5
    blocks = w[: (len(w) // hold) * hold].reshape(-1, hold)
    assert np.all(blocks == blocks[:, :1])                   # constant within a hold
    assert np.all(np.diff(blocks[:, 0]) != 0.0)             # new sample each hold
    assert np.all(w[-((n + 1) % hold):] == w[(len(w) // hold) * hold])  # tail is one held sample


def test_held_white_noise_variance():
    rng = np.random.default_rng(1)
    w = held_white_noise(200_000, 0.1, rng, 0.5, 1e-4)
    samples = w[::5]
    assert samples.std() == pytest.approx(math.sqrt(1e-4 / 0.5), rel=0.02)
    assert abs(samples.mean()) < 0.02 * math.sqrt(1e-4 / 0.5)


@pytest.mark.parametrize("ts", [0.35, 0.05, 0.0, -0.5])
def test_sample_time_not_multiple_of_dt(ts):
    with pytest.raises(InputError) as ei:
        held_white_noise(100, 0.1, np.random.default_rng(0), ts)
    assert ei.value.field == "waves.sample_time"
    assert "waves.sample_time" in str(ei.value)


def test_sample_time_accepts_float_multiples():
    # 0.3 / 0.1 is not exactly 3 in floating point; still a multiple
    w = held_white_noise(30, 0.1, np.random.default_rng(0), 0.3)
    assert np.all(w[:3] == w[0]) and w[3] != w[0]


def test_coloured_noise_long_run_statistics():
    dt = 0.1
    y = coloured_noise(200_000, dt, np.random.default_rng(7))   # 20000 s
    s = stationary_std_eq39()
    assert abs(y.mean()) < 0.02 * s
    assert y[1000:].std() == pytest.approx(s, rel=0.15)


def test_band_pass_discretisation_dc_and_peak():
    b, a = band_pass_eq39(0.1)
    # zero at s = 0 -> z = 1: no DC gain
    assert abs(np.polyval(b, 1.0)) < 1e-12
    # frequency response near the peak (1.635 rad/s) equals the continuous one (ZOH, small dt)
    w = 1.635
    z = np.exp(1j * w * 0.1)
    nb = len(a) - len(b)
    Hd = np.polyval(b, z) / np.polyval(a, z) * (z ** -nb if nb else 1.0)
    Hc = 10.8j * w / ((1j * w) ** 2 + 0.672j * w + 2.6729)
    assert abs(Hd) == pytest.approx(abs(Hc), rel=0.02)


def test_coloured_noise_is_causal_zoh_from_rest():
    dt = 0.1
    rng = np.random.default_rng(3)
    y = coloured_noise(2000, dt, rng)
    white = held_white_noise(2000, dt, np.random.default_rng(3))
    assert y[0] == 0.0
    np.testing.assert_allclose(y, _reference_eq39(white, dt), rtol=1e-9, atol=1e-12)


def test_coloured_noise_matches_exact_zoh_up_to_alignment():
    # whatever the alignment, the filter itself is the exact ZOH discretisation of eq (39)
    dt = 0.1
    white = held_white_noise(2000, dt, np.random.default_rng(3))
    y = coloured_noise(2000, dt, np.random.default_rng(3))
    ref = _reference_eq39(white, dt)
    if y[0] == 0.0:
        np.testing.assert_allclose(y, ref, rtol=1e-9, atol=1e-12)
    else:
        np.testing.assert_allclose(y[:-1], ref[1:], rtol=1e-9, atol=1e-12)


def test_build_disturbance_constant_and_start():
    dist = Disturbance(constant_rudder=rad(10.0), constant_start=5.0)
    w = build_disturbance(dist, 100, 0.1, seed=0)
    assert w.shape == (101, N_CHANNELS)
    t = np.arange(101) * 0.1
    assert np.all(w[t < 5.0 - 1e-9, W_RUDDER] == 0.0)
    assert np.all(w[t >= 5.0 + 1e-9, W_RUDDER] == rad(10.0))


def test_build_disturbance_seeded():
    dist = Disturbance(waves=True)
    a = build_disturbance(dist, 2000, 0.1, seed=11)
    b = build_disturbance(dist, 2000, 0.1, seed=11)
    c = build_disturbance(dist, 2000, 0.1, seed=12)
    assert np.array_equal(a, b)
    assert not np.allclose(a, c)
    assert np.std(a[500:, W_RUDDER]) > 0.03
    # waves add on top of the constant part
    d = build_disturbance(Disturbance(constant_rudder=0.1, waves=True), 2000, 0.1, seed=11)
    np.testing.assert_allclose(d[:, W_RUDDER] - a[:, W_RUDDER], 0.1, rtol=0, atol=1e-15)
    assert np.array_equal(np.delete(d, W_RUDDER, axis=1), np.delete(a, W_RUDDER, axis=1))


@pytest.mark.parametrize("kw, field", [
    (dict(constant_rudder=2.0), "environment.constant_rudder [rad]"),
    (dict(constant_start=-1.0), "environment.constant_start"),
    (dict(wave_sample_time=0.0), "environment.wave_sample_time"),
    (dict(wave_power=-1e-4), "environment.wave_power"),
])
def test_disturbance_validation(kw, field):
    with pytest.raises(InputError) as ei:
        Disturbance(**kw).validated()
    assert ei.value.field == field


def test_generated_noise_std_matches_held_noise_theory():
    """The held (ZOH) white noise through eq (39): std from the spectrum integral, within 5 %."""
    from steerlab.environment.waves import held_noise_std_eq39

    dt = 0.1
    y = coloured_noise(400_000, dt, np.random.default_rng(11))
    assert np.std(y[1000:]) == pytest.approx(held_noise_std_eq39(), rel=0.05)
    assert held_noise_std_eq39() < stationary_std_eq39()  # the hold removes power near the peak
