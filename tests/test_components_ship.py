"""Ship objects (steerlab.components.ship): engine parity, named states, bad input."""

import math

import numpy as np
import pytest

from steerlab.components.controller import controller
from steerlab.components.ship import ship
from steerlab.errors import InputError
from steerlab.sim.engine import simulate
from steerlab.units import rad


def test_ship_and_controller_objects_reproduce_the_engine_run(scenario):
    """Ship.step with the engine's orders and disturbance rows, and the controller object in
    the loop, give the engine's states bit for bit (same RK4 + gear kernel, same law)."""
    sc = scenario(duration=120.0, controller={"type": "pid"}, environment={"waves": True},
                  guidance={"changes": [{"t": 10.0, "psi_deg": 20.0}]}, seed=4)
    res = simulate(sc)
    s = ship("esso", 16.0)
    c = controller("pid", ship="esso", speed_kn=16.0).reset()
    X = np.empty_like(res.states)
    for k in range(len(res.time)):
        X[k] = s.state
        assert s.t == res.time[k]                         # t = k dt, as in the engine
        u = c.step(s.t, s.heading, s.yaw_rate, res.psi_ref[k], res.r_ref[k], rudder=s.rudder, speed=s["u"])
        assert u == res.delta_cmd[k]
        if k < len(res.time) - 1:
            s.step(u, 0.1, res.disturbance[k])
    assert np.array_equal(X, res.states)
    assert s.t == pytest.approx(120.0)
    assert math.degrees(s.heading) > 10.0            # the run turned (not a trivial comparison)


def test_named_states_and_disturbance_dict():
    s = ship("nomoto1", 10.0, ship_options={"K": 0.1, "T": 20.0})
    assert s.state_names[-1] == "delta" and s["u"] == pytest.approx(s.speed)
    for _ in range(2000):                # 200 s = 10 T
        s.step(0.0, 0.1, disturbance={"d_rudder": rad(1.0)})
    # a constant equivalent rudder of 1 deg: r -> K * 1 deg (T r' + r = K (delta + d))
    assert s.yaw_rate == pytest.approx(0.1 * rad(1.0), rel=1e-3)
    assert s.as_dict()["r"] == s.yaw_rate
    with pytest.raises(KeyError):
        s["q"]


@pytest.mark.parametrize("call,field", [
    (lambda s: s.step(math.nan, 0.1), "rudder_order"),
    (lambda s: s.step(0.1, 0.0), "dt"),
    (lambda s: s.step(0.1, 0.1, disturbance={"gust": 1.0}), "disturbance.gust"),
    (lambda s: s.reset(heading=math.inf), "heading"),
])
def test_bad_input(call, field):
    s = ship("esso", 16.0)
    with pytest.raises(InputError) as ei:
        call(s)
    assert ei.value.field == field


def test_unknown_ship_and_speed():
    with pytest.raises(InputError) as ei:
        ship("titanic", 10.0)
    assert ei.value.field == "ship.model"
    with pytest.raises(InputError) as ei:
        ship("esso", -1.0)
    assert ei.value.field == "speed_kn"


@pytest.mark.parametrize("kwargs, field, range_text", [
    ({"gear": {"rate_max_deg_s": -1.0}}, "gear.rate_max_deg_s", "(allowed: gt 0.0)"),
    ({"gear": {"T_sg": math.nan}}, "gear.T_sg", "(allowed: ge 0.001, le 100.0)"),
    ({"rpm": -80.0}, "rpm", "(allowed: gt 0.0)"),
    ({"rpm": 1e6}, "rpm", "(allowed: le 1000.0)"),
], ids=["gear-rate", "gear-nan", "rpm-negative", "rpm-huge"])
def test_bad_gear_or_rpm_is_one_line_naming_the_field_and_its_range(kwargs, field, range_text):
    """A bad gear value was pydantic's multi-line error with a web address; an rpm of -80 was
    accepted, and 1e6 ran the surge speed to 81 km/s in one step. Now the scenario's checks,
    one line each (also through ``controller(..., gear=...)``)."""
    with pytest.raises(InputError) as ei:
        ship("esso", 16.0, **kwargs)
    assert ei.value.field == field and ei.value.message.endswith(range_text)
    if "gear" in kwargs:
        with pytest.raises(InputError) as ei:
            controller("pid", ship="esso", speed_kn=16.0, **kwargs)
        assert ei.value.field == field


def test_functional_step_equals_the_stateful_one():
    s = ship("esso", 16.0).reset(heading=0.1, yaw_rate=0.001)
    x0 = s.state.copy()
    x1 = s.step_state(x0, rad(5.0), 0.1)
    assert np.array_equal(s.state, x0)                      # untouched
    assert np.array_equal(x1, s.step(rad(5.0), 0.1))
