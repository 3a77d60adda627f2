"""De Keizer / van Amerongen multivariable model: speed loss in turns, thrust dynamics, parity."""

import math

import numpy as np
import pytest

from steerlab.environment.channels import N_CHANNELS, W_RUDDER
from steerlab.errors import InputError
from steerlab.ships.de_keizer import DeKeizerOptions, de_keizer_rhs, pack
from steerlab.ships.registry import get_ship
from steerlab.sim.engine import simulate_compiled, simulate_readable
from steerlab.sim.scenario import scenario_from_dict
from steerlab.sim.setup import build
from steerlab.units import knots_to_ms

V = knots_to_ms(12.0)


def _scenario(**over):
    d = {"dt": 0.5, "duration": 600.0, "ship": {"model": "de-keizer", "speed_kn": 12.0},
         "controller": {"type": "pid", "Kp": 2.0, "Ki": 0.0, "Kd": 30.0},
         "guidance": {"changes": [{"t": 10.0, "psi_deg": 60.0}, {"t": 200.0, "psi_deg": 0.0}]}}
    d.update(over)
    return scenario_from_dict(d)


def test_rhs_steady_straight_and_the_yaw_equation():
    p = pack(V)
    dx = np.zeros(8)
    de_keizer_rhs(0.0, np.array([0, 0, 0.2, V, 0, 0, 0, 0.0]), 0.0, np.zeros(N_CHANNELS), p, dx)
    np.testing.assert_allclose(dx[2:], 0.0, atol=1e-15)
    # steady turn: H(r*) = K* delta with H = r* + r*^3 (defaults); r'' = 0 there
    o = DeKeizerOptions()
    delta = 0.2
    rs = np.roots([1.0, 0.0, 1.0, -o.K * delta]).real.max()
    r = rs * V / o.L
    w = np.zeros(N_CHANNELS)
    w[W_RUDDER] = 0.1
    de_keizer_rhs(0.0, np.array([0, 0, 0, V, 0, r, 0, 0.0]), delta - 0.1, w, p, dx)
    assert dx[6] == pytest.approx(0.0, abs=1e-12)
    assert dx[3] < 0            # the turn starts to slow the ship: K_u* r*^2 > 0


def test_speed_drops_in_the_turn_and_recovers_after():
    res = simulate_compiled(build(_scenario()))
    t, u, psi = res.time, res.states[:, 3], res.psi
    assert math.degrees(psi[t.searchsorted(150.0)]) == pytest.approx(60.0, abs=2.0)
    u_turn = u[(t > 10) & (t < 150)].min()
    assert u_turn < 0.97 * V                       # speed loss while turning
    assert u[-1] == pytest.approx(V, rel=2e-3)     # recovered on the straight course
    assert np.all(u <= V + 1e-12)
    # and the loss is the turn's: a run without course changes keeps its speed exactly
    calm = simulate_compiled(build(_scenario(guidance={"changes": []}, duration=50.0)))
    np.testing.assert_allclose(calm.states[:, 3], V, rtol=1e-15)


def test_readable_and_compiled_agree():
    s = build(_scenario(duration=250.0, ship={"model": "de-keizer", "speed_kn": 12.0,
                                               "options": {"rpm_schedule": [[0, 100], [100, 60]]}}))
    a, b = simulate_readable(s), simulate_compiled(s)
    np.testing.assert_allclose(a.states, b.states, rtol=1e-12, atol=1e-12)
    assert b.states[-1, 3] < 0.9 * V               # rpm cut slows the ship


def test_thrust_dynamics_reach_the_new_stationary_speed():
    o = DeKeizerOptions()
    p = pack(V, 50.0, o)                           # half the nominal rpm
    x = np.array([0, 0, 0, V, 0, 0, 0, 0.0])
    dx = np.zeros(8)
    h = 1.0                                        # time constant tau_a* L / U0 = 650 s
    for k in range(12000):                         # forward Euler is enough for this check
        de_keizer_rhs(k * h, x, 0.0, np.zeros(N_CHANNELS), p, dx)
        x += h * dx
    assert x[3] == pytest.approx(V / 2, rel=1e-3) and x[7] + V == pytest.approx(V / 2, rel=1e-3)


def test_nomoto_reading_and_bad_options():
    ship = get_ship("de-keizer")
    K, T = ship.nomoto(V)
    o = DeKeizerOptions()
    assert K == pytest.approx(o.K * V / o.L) and T == pytest.approx((o.tau1 + o.tau2) * o.L / V)
    with pytest.raises(InputError, match=r"ship\.options\.a"):
        build(_scenario(ship={"model": "de-keizer", "options": {"a": [0, 0.5, 0, 1]}}))
    with pytest.raises(InputError, match=r"ship\.options\.tau_u"):
        build(_scenario(ship={"model": "de-keizer", "options": {"tau_u": -1.0}}))
    with pytest.raises(InputError, match=r"ship\.options\.rpm_schedule"):
        build(_scenario(ship={"model": "de-keizer", "options": {"rpm_schedule": [[5, 100], [1, 50]]}}))
