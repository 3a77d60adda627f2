"""Conformance of every ship in the registry (modules and the data-file catalogue).

Each ship, at its nominal operating point: straight with the equilibrium rudder stays
straight; a PID course change respects the gear limits and gives identical numbers in the
compiled and readable engines; +-rudder mirror where the model is symmetric; a 20/20 zig-zag
stays finite and actually zig-zags. Open-loop runs use the engine's own RK4 plant step
(``plant_step``); closed-loop ones the engines. Compiled loops are cached per ship kernel,
so ships sharing a kernel (all Nomoto/Norrbin/Bech entries) compile once.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from steerlab.environment.channels import N_CHANNELS
from steerlab.ships.registry import SHIPS
from steerlab.ships.ship_traits import is_symmetric, straight_rudder
from steerlab.sim.engine import simulate
from steerlab.sim.kernels import plant_step
from steerlab.sim.scenario import scenario_from_dict
from steerlab.steering_gear import SteeringGear
from steerlab.units import knots_to_ms, ms_to_knots, rad

NAMES = sorted(SHIPS)
GEAR = SteeringGear(rad(35.0), rad(2.33), 1.0, 0.0)


def operating_speed(spec) -> float:
    """Nominal speed [m/s]: the catalogue's middle row, else the middle of the validity range."""
    cat = getattr(spec, "catalogue", None)
    if cat and "speed_range_kn" in cat:
        from steerlab.ships.catalogue import get_entry

        return get_entry(spec.name).nominal
    lo, hi = spec.speed_range
    return 0.5 * (lo + hi) if math.isfinite(hi) else knots_to_ms(10.0)


def straight_sway(spec, speed) -> float:
    """Sway speed [m/s] of the straight-course equilibrium: 0 unless the spec says (a propeller side force)."""
    f = getattr(spec, "equilibrium_sway", None)
    return 0.0 if f is None else float(f(speed, spec.options(None)))


def open_loop(spec, speed, rudder, duration, dt=0.5, delta0=0.0, v0=0.0):
    """Open-loop run with ``rudder(t, x) -> order [rad]``; returns (t, X) with the rudder last."""
    ps = spec.pack(speed, None, spec.options(None))
    pg = GEAR.pack()
    step = plant_step(spec.rhs)
    x = np.zeros(spec.n_states + 1)
    x[3] = speed
    x[4] = v0
    x[-1] = delta0
    w = np.zeros(N_CHANNELS)
    work = np.empty((5, x.size))
    n = int(round(duration / dt))
    X = np.empty((n + 1, x.size))
    X[0] = x
    for k in range(n):
        t = k * dt
        step(t, x, rudder(t, x), w, ps, pg, dt, work)
        X[k + 1] = x
    return np.arange(n + 1) * dt, X


@pytest.mark.parametrize("name", NAMES)
def test_straight_with_equilibrium_rudder_stays_straight(name):
    spec = SHIPS[name]
    v = operating_speed(spec)
    d0 = straight_rudder(spec, v)
    assert abs(d0) < GEAR.delta_max
    _, X = open_loop(spec, v, lambda t, x: d0, 300.0, delta0=d0, v0=straight_sway(spec, v))
    assert np.all(np.isfinite(X))
    assert np.max(np.abs(X[:, 2])) < 1e-9          # heading [rad]
    assert np.max(np.abs(X[:, 5])) < 1e-11         # yaw rate [rad/s]
    assert X[-1, 0] == pytest.approx(300.0 * X[0, 3], rel=1e-3)   # moved ahead at its speed


@pytest.mark.parametrize("name", NAMES)
def test_symmetric_response_to_plus_minus_rudder(name):
    spec = SHIPS[name]
    v = operating_speed(spec)
    if not is_symmetric(spec, v):
        pytest.skip(f"{name} is asymmetric by design (H(0) or an r^2 term)")
    _, Xp = open_loop(spec, v, lambda t, x: rad(10.0), 200.0)
    _, Xm = open_loop(spec, v, lambda t, x: -rad(10.0), 200.0)
    assert np.max(np.abs(Xp[:, 5])) > 1e-4        # it turned
    for i in (2, 5, Xp.shape[1] - 1):              # psi, r, rudder mirror
        np.testing.assert_allclose(Xm[:, i], -Xp[:, i], rtol=1e-9, atol=1e-14)
    np.testing.assert_allclose(Xm[:, 0], Xp[:, 0], rtol=1e-9, atol=1e-9)


@pytest.mark.parametrize("name", NAMES)
def test_zigzag_20_20_is_finite_and_switches(name):
    spec = SHIPS[name]
    v = operating_speed(spec)
    d0 = straight_rudder(spec, v)
    state = {"sign": 1.0, "switches": 0}

    def rudder(t, x):
        psi = x[2]
        if state["sign"] > 0 and psi >= rad(20.0):
            state["sign"], state["switches"] = -1.0, state["switches"] + 1
        elif state["sign"] < 0 and psi <= -rad(20.0):
            state["sign"], state["switches"] = 1.0, state["switches"] + 1
        return d0 + state["sign"] * rad(20.0)

    _, X = open_loop(spec, v, rudder, 1500.0, delta0=d0)
    assert np.all(np.isfinite(X))
    assert state["switches"] >= 2
    assert np.max(np.abs(X[:, -1])) <= GEAR.delta_max * (1 + 1e-12)


@pytest.mark.parametrize("name", NAMES)
def test_pid_course_change_gear_limits_and_engine_parity(name):
    spec = SHIPS[name]
    v = operating_speed(spec)
    s = scenario_from_dict({
        "dt": 0.2, "duration": 200.0,
        "ship": {"model": name, "speed_kn": ms_to_knots(v)},
        "gear": {"delta_max_deg": 30.0, "rate_max_deg_s": 3.0, "T_sg": 0.5},
        "controller": {"type": "pid", "Kp": 4.0, "Ki": 0.0, "Kd": 20.0},
        "guidance": {"changes": [{"t": 5.0, "psi_deg": 40.0}]},
    })
    fast = simulate(s, "compiled")
    slow = simulate(s, "readable")
    np.testing.assert_array_equal(fast.states, slow.states)
    np.testing.assert_array_equal(fast.delta_cmd, slow.delta_cmd)
    delta = fast.delta
    assert np.all(np.isfinite(fast.states))
    assert np.max(np.abs(delta)) <= rad(30.0) * (1 + 1e-12)
    assert np.max(np.abs(np.diff(delta))) / 0.2 <= rad(3.0) * (1 + 1e-9)
    assert np.max(np.abs(delta)) > rad(29.0)       # the gear limit was actually reached
