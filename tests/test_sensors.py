"""Sensor models (noise, sample hold, quantisation, dropouts) in front of a controller."""

import math

import numpy as np
import pytest

from steerlab.errors import InputError
from steerlab.sensors.counter_rng import make_key, normal, uniform
from steerlab.sensors.wrapper import OFF_X, Z_PSI, Z_R, SensorParams, sensor_sample
from steerlab.sim.engine import simulate
from steerlab.sim.scenario import scenario_from_dict
from steerlab.sim.setup import build


def _measure(n, seed=1, psi=lambda k: 0.01 * k, r=lambda k: 0.0, **kw):
    p = SensorParams(seed, **kw).pack()
    z = np.zeros(OFF_X)
    x = np.zeros(7)
    out = np.empty((n, 2))
    for k in range(n):
        x[2] = psi(k)
        x[5] = r(k)
        sensor_sample(z, p, x)
        out[k] = z[Z_PSI], z[Z_R]
    return out


def test_counter_rng_is_uniform_and_normal():
    key = make_key(0.0, 42.0, 0)
    u = np.array([uniform(key, i) for i in range(10_000)])
    assert 0.0 < u.min() and u.max() <= 1.0 and u.mean() == pytest.approx(0.5, abs=0.01)
    g = np.array([normal(key, i) for i in range(10_000)])
    assert g.mean() == pytest.approx(0.0, abs=0.04) and g.std() == pytest.approx(1.0, abs=0.03)
    assert abs(np.corrcoef(g[:-1], g[1:])[0, 1]) < 0.04
    assert normal(key, 7) == normal(make_key(0.0, 42.0, 0), 7)          # a pure function of (key, i)
    assert normal(key, 7) != normal(make_key(0.0, 43.0, 0), 7)


def test_noise_std_as_configured():
    m = _measure(20_000, sigma_psi=0.01, sigma_r=0.002)
    true_psi = 0.01 * np.arange(20_000)
    e = m[:, 0] - true_psi
    assert e.std() == pytest.approx(0.01, rel=0.03) and abs(e.mean()) < 3e-4
    assert m[:, 1].std() == pytest.approx(0.002, rel=0.03)
    assert abs(np.corrcoef(e, m[:, 1])[0, 1]) < 0.03                    # independent streams


def test_quantisation():
    q = math.radians(0.5)
    m = _measure(2000, psi=lambda k: 0.00123 * k - 1.0, q_psi=q)
    true = 0.00123 * np.arange(2000) - 1.0
    assert np.allclose(np.round(m[:, 0] / q) * q, m[:, 0])
    assert np.max(np.abs(m[:, 0] - true)) <= q / 2 + 1e-12


def test_sample_hold():
    m = _measure(40, m=4)
    true = 0.01 * np.arange(40)
    assert np.array_equal(m[::4, 0], true[::4])                          # sampled every 4th call
    assert np.array_equal(m[:, 0], np.repeat(true[::4], 4))             # held in between


def test_dropouts_hold_last_value():
    n = 20_000
    m = _measure(n, p_drop=0.2)
    true = 0.01 * np.arange(n)
    fresh = m[:, 0] == true
    assert fresh[0]                                                      # first sample never dropped
    assert 1.0 - fresh.mean() == pytest.approx(0.2, abs=0.015)
    held = np.flatnonzero(~fresh)
    assert np.array_equal(m[held, 0], m[held - 1, 0])                   # last value held
    assert np.array_equal(_measure(500, p_drop=0.2), _measure(500, p_drop=0.2))
    assert not np.array_equal(_measure(500, p_drop=0.2), _measure(500, seed=2, p_drop=0.2))


SENSORS = {"heading_noise_std_deg": 0.3, "yaw_rate_noise_std_deg_s": 0.02, "sample_time": 0.5,
           "heading_quantum_deg": 0.1, "yaw_rate_quantum_deg_s": 0.01, "dropout_probability": 0.1}


def _sc(sensors, seed=3, duration=200.0):
    return scenario_from_dict({"seed": seed, "dt": 0.1, "duration": duration, "ship": {"model": "esso"},
                               "controller": {"type": "pid"},
                               "guidance": {"changes": [{"t": 10.0, "psi_deg": 10.0}]}, "sensors": sensors})


def test_sensors_compiled_readable_parity_and_effect():
    s = _sc(SENSORS)
    a = simulate(s, "compiled")
    b = simulate(s, "readable")
    np.testing.assert_array_equal(a.states, b.states)
    np.testing.assert_array_equal(a.delta_cmd, b.delta_cmd)
    clean = simulate(_sc(None), "readable")
    assert not np.array_equal(clean.delta_cmd, b.delta_cmd)
    # the noise reaches the rudder order (a PID differentiates the noisy heading), same seed same run
    late = b.time > 100.0                                                 # after the course change
    assert np.std(np.diff(b.delta_cmd[late])) > 10 * np.std(np.diff(clean.delta_cmd[late]))
    np.testing.assert_array_equal(simulate(_sc(SENSORS), "readable").delta_cmd, b.delta_cmd)
    # the batch engine: each run (its own sensor noise stream, by seed) as alone
    from steerlab.sim.batch import simulate_batch

    other = build(_sc(SENSORS, seed=4))
    batch = simulate_batch([build(s), other], record_every=10)
    np.testing.assert_array_equal(batch.delta_cmd[0], a.delta_cmd[::10])
    np.testing.assert_array_equal(batch.final_states[1], simulate(other, "compiled").states[-1])
    assert not np.array_equal(batch.delta_cmd[1], batch.delta_cmd[0])


def test_sensors_off_by_default_is_unchanged():
    plain = scenario_from_dict({"seed": 3, "dt": 0.1, "duration": 50.0, "controller": {"type": "pid"}})
    s = build(plain)
    assert s.controller.name == "pid" and plain.sensors is None


@pytest.mark.parametrize("sensors,field", [
    ({"sample_time": 0.25}, "sensors.sample_time"),
    ({"dropout_probability": 1.0}, "sensors.dropout_probability"),
    ({"heading_noise_std_deg": -1.0}, "sensors.heading_noise_std_deg"),
    ({"gyro": 1.0}, "sensors.gyro"),
])
def test_bad_sensor_input_names_the_field(sensors, field):
    with pytest.raises(InputError) as err:
        build(_sc(sensors))
    assert err.value.field == field
