"""The nominal first-order Nomoto ship: its closed form, options and errors."""

import math

import numpy as np
import pytest

from steerlab.environment.channels import N_CHANNELS, W_RUDDER
from steerlab.errors import InputError
from steerlab.ships.nomoto1 import nomoto1_rhs
from steerlab.sim.engine import simulate
from steerlab.sim.scenario import scenario_from_dict
from steerlab.sim.setup import build
from steerlab.units import rad


def test_rhs_is_the_nomoto_equation():
    x = np.array([0.0, 0.0, 0.3, 5.0, 0.0, 0.01])
    w = np.zeros(N_CHANNELS)
    w[W_RUDDER] = 0.02
    dx = np.empty(6)
    nomoto1_rhs(0.0, x, 0.05, w, np.array([0.2, 40.0]), dx)
    assert dx[5] == pytest.approx((0.2 * 0.07 - 0.01) / 40.0)
    assert dx[0] == pytest.approx(5.0 * math.cos(0.3)) and dx[1] == pytest.approx(5.0 * math.sin(0.3))
    assert dx[2] == 0.01 and dx[3] == 0.0 and dx[4] == 0.0


def test_open_loop_step_matches_closed_form():
    # constant rudder through a fast gear: r(t) -> K delta (1 - exp(-t/T)) after the gear transient
    K, T = 0.1, 30.0
    s = scenario_from_dict({
        "dt": 0.05, "duration": 200.0,
        "ship": {"model": "nomoto1", "options": {"K": K, "T": T}},
        "gear": {"rate_max_deg_s": 100.0, "T_sg": 0.01},
        "environment": {"constant_rudder_deg": 5.0},
        "controller": {"type": "pid", "Kp": 0.0, "Ki": 0.0, "Kd": 0.0},
    })
    res = simulate(build(s))
    r_end = res.states[-1, 5]
    assert r_end == pytest.approx(K * rad(5.0) * (1 - math.exp(-200.0 / T)), rel=1e-6)


def test_options_reach_the_controller_design_and_are_validated():
    s = build(scenario_from_dict({"ship": {"model": "nomoto1", "options": {"K": 0.2, "T": 40.0}},
                                  "controller": {"type": "adrc", "c0": "exact"}}))
    assert s.pc[0] == pytest.approx(0.2 / 40.0)
    with pytest.raises(InputError, match=r"ship\.options\.K"):
        build(scenario_from_dict({"ship": {"model": "nomoto1", "options": {"K": -1.0}}}))
    with pytest.raises(InputError, match=r"ship\.options\.bogus"):
        build(scenario_from_dict({"ship": {"model": "nomoto1", "options": {"bogus": 1.0}}}))
    with pytest.raises(InputError, match=r"ship\.options"):
        build(scenario_from_dict({"ship": {"model": "esso", "options": {"K": 1.0}}}))
