"""Steering gear (eq 15): gear_rate / gear_clamp units and the limits over closed-loop runs."""

import math

import numpy as np
import pytest

from steerlab.errors import InputError
from steerlab.sim.engine import simulate
from steerlab.steering_gear import SteeringGear, gear_clamp, gear_rate
from steerlab.units import rad

G = SteeringGear().pack()
RMAX = rad(2.33)
DMAX = rad(35.0)


def test_defaults_eq15():
    g = SteeringGear()
    assert g.delta_max == pytest.approx(rad(35.0))
    assert g.rate_max == pytest.approx(rad(2.33))
    assert g.T_sg == 1.0 and g.dead_zone == 0.0


def test_gear_rate_linear_region():
    # small error: rate = err / T_sg
    assert gear_rate(0.0, 0.01, G) == pytest.approx(0.01)
    assert gear_rate(0.02, 0.01, G) == pytest.approx(-0.01)
    g = SteeringGear(T_sg=2.0).pack()
    assert gear_rate(0.0, 0.01, g) == pytest.approx(0.005)


def test_gear_rate_rate_limited():
    assert gear_rate(0.0, rad(20.0), G) == RMAX
    assert gear_rate(0.0, -rad(20.0), G) == -RMAX


def test_gear_rate_order_limited_to_delta_max():
    # order beyond the limit is clamped first: at the limit the rudder stops
    assert gear_rate(DMAX, rad(80.0), G) == 0.0
    assert gear_rate(-DMAX, -rad(80.0), G) == 0.0
    # approaching the limit from just below: err is to DMAX, not to the order
    assert gear_rate(DMAX - 0.001, rad(80.0), G) == pytest.approx(0.001)


def test_gear_rate_dead_zone():
    g = SteeringGear(dead_zone=rad(0.5)).pack()
    assert gear_rate(0.0, rad(0.4), g) == 0.0
    assert gear_rate(0.0, -rad(0.5), g) == 0.0
    assert gear_rate(rad(3.0), rad(3.3), g) == 0.0
    assert gear_rate(0.0, rad(0.6), g) == pytest.approx(rad(0.6))
    assert gear_rate(0.0, rad(10.0), g) == RMAX


def test_gear_clamp():
    assert gear_clamp(rad(40.0), G) == DMAX
    assert gear_clamp(-rad(40.0), G) == -DMAX
    assert gear_clamp(0.1, G) == 0.1


@pytest.mark.parametrize("kw, field", [
    (dict(delta_max=0.0), "gear.delta_max"),
    (dict(delta_max=rad(95.0)), "gear.delta_max"),
    (dict(rate_max=-1.0), "gear.rate_max"),
    (dict(T_sg=0.0), "gear.T_sg"),
    (dict(dead_zone=rad(40.0)), "gear.dead_zone"),
    (dict(T_sg=math.nan), "gear.T_sg"),
])
def test_gear_validation(kw, field):
    with pytest.raises(InputError) as ei:
        SteeringGear(**kw).pack()
    assert ei.value.field == field


AGGRESSIVE = {"type": "pid", "Kp": 50.0, "Ki": 0.1, "Kd": 200.0}


@pytest.mark.parametrize("gear", [{}, {"delta_max_deg": 10.0, "rate_max_deg_s": 5.0}])
def test_limits_hold_in_closed_loop(scenario, gear):
    sc = scenario(duration=700.0, controller=AGGRESSIVE, gear=gear, environment={"waves": True},
                  guidance={"changes": [{"t": 10.0, "psi_deg": 30.0}, {"t": 300.0, "psi_deg": -30.0}]})
    res = simulate(sc)
    dmax = rad(gear.get("delta_max_deg", 35.0))
    rmax = rad(gear.get("rate_max_deg_s", 2.33))
    d = res.delta
    assert np.max(np.abs(d)) <= dmax
    rate = np.abs(np.diff(d)) / res.dt
    assert np.max(rate) <= rmax * (1 + 1e-9)
    # and the test is not vacuous: both limits are reached
    assert np.max(np.abs(d)) == pytest.approx(dmax, rel=1e-9)
    assert np.max(rate) == pytest.approx(rmax, rel=1e-6)
    assert np.max(np.abs(res.delta_cmd)) == pytest.approx(dmax, rel=1e-12)   # u_max = gear limit


def test_dead_zone_in_closed_loop_keeps_rudder_still_for_small_orders(scenario):
    # PID order for a 0.1 deg course change: Kp*e = 3.81*0.1 = 0.38 deg < 1 deg dead zone
    sc = scenario(duration=30.0, gear={"dead_zone_deg": 1.0},
                  guidance={"changes": [{"t": 1.0, "psi_deg": 0.1}]})
    res = simulate(sc)
    assert np.max(np.abs(res.delta_cmd)) > 0.0
    assert np.all(res.delta == 0.0)
