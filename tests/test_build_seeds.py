"""build_seeds: designed once, realised per seed, and equal to building each seed alone."""

from __future__ import annotations

import numpy as np
import pytest

from steerlab.sim.scenario import scenario_from_dict
from steerlab.sim.setup import build, build_seeds

BASE = {"dt": 0.1, "duration": 120.0, "ship": {"model": "esso"}, "controller": {"type": "pid"},
        "guidance": {"changes": [{"t": 10.0, "psi_deg": 15.0}]}}
VARIANTS = {
    "eq39 waves + current": {"environment": {"waves": True, "current_speed": 0.4, "current_dir_deg": 30.0}},
    "spectrum, gusts, varying current, wind rudder": {"environment": {
        "wind_speed": 8.0, "wind_dir_deg": 40.0, "current_speed": 0.3,
        "wave": {"model": "spectrum", "sea_state": 4, "n_components": 16},
        "gusts": {"speed_std": 1.0, "dir_std_deg": 5.0},
        "current_variation": {"kind": "random_walk", "speed_amplitude": 0.1, "dir_amplitude_deg": 5.0,
                              "time_scale": 50.0},
        "wind_rudder": {"amplitude_deg": 1.0}}},
    "sensors + adrc": {"controller": {"type": "adrc"}, "environment": {"waves": True},
                       "sensors": {"heading_noise_std_deg": 0.2, "dropout_probability": 0.05}},
    "los guidance on nomoto1": {"ship": {"model": "nomoto1"}, "environment": {"waves": True},
                                "guidance": {"type": "los", "start": [0.0, 50.0],
                                             "route": [[0.0, 0.0], [5000.0, 0.0]]}},
}


@pytest.mark.parametrize("name", sorted(VARIANTS))
def test_each_seed_equals_its_own_build(name):
    sc = scenario_from_dict({**BASE, **VARIANTS[name], "seed": 7})
    seeds = [7, 8, 123456789012]
    many = build_seeds(sc, seeds)
    for seed, got in zip(seeds, many):
        want = build(sc.replace(seed=seed))
        assert got.seed == want.seed == seed
        for field in ("ps", "pg", "pc", "gd", "x0", "z0", "w"):
            np.testing.assert_array_equal(getattr(got, field), getattr(want, field), err_msg=field)
        assert (got.dt, got.nc, got.n_steps, got.name) == (want.dt, want.nc, want.n_steps, want.name)
        assert got.ship is want.ship and got.controller.update is want.controller.update
        assert got.guide is want.guide
        np.testing.assert_array_equal(got.gz0, want.gz0)
    assert not np.array_equal(many[0].w, many[1].w)                  # the seas really differ
    many[0].pc[0] += 1.0                                             # no array is shared between seeds
    assert many[1].pc[0] != many[0].pc[0]
