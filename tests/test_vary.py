"""sl.vary: scenarios varied by dotted name, validated by the scenario's model."""

from __future__ import annotations

import pytest

import steerlab as sl
from steerlab.errors import InputError
from steerlab.sim.scenario import scenario_from_dict

BASE = scenario_from_dict({"duration": 60.0, "ship": {"model": "nomoto1", "options": {"K": 0.1, "T": 50.0}},
                           "controller": {"type": "pid", "Kp": 2.0}})


def test_grid_and_zip():
    runs = sl.vary(BASE, {"controller.Kp": [1.0, 2.0, 3.0], "ship.speed_kn": [10.0, 12.0]})
    assert [(s.controller.Kp, s.ship.speed_kn) for s in runs] == [
        (1.0, 10.0), (1.0, 12.0), (2.0, 10.0), (2.0, 12.0), (3.0, 10.0), (3.0, 12.0)]
    assert all(s.controller.Kd == BASE.controller.Kd and s.duration == 60.0 for s in runs)   # the rest kept
    z = sl.vary(BASE, {"controller.Kp": [1.0, 3.0], "ship.options.T": [40.0, 60.0], "seed": [7, 8]}, mode="zip")
    assert [(s.controller.Kp, s.ship.options["T"], s.seed) for s in z] == [(1.0, 40.0, 7), (3.0, 60.0, 8)]
    assert z[0].ship.options["K"] == 0.1
    s = sl.vary(BASE, {"sensors.heading_noise_std_deg": [0.5]})[0]             # an absent optional table
    assert s.sensors.heading_noise_std_deg == 0.5


def test_varied_scenarios_build_with_the_value():
    from steerlab.control.pid import C_KP
    from steerlab.sim.setup import build

    runs = sl.vary(BASE, {"controller.Kp": [0.5, 4.0]})
    assert [build(s).pc[C_KP] for s in runs] == [0.5, 4.0]


@pytest.mark.parametrize("changes, field, words", [
    ({"controller.Kx": [1.0]}, "controller.Kx", ["unknown field 'Kx'", "Kp", "Ki", "Kd"]),
    ({"shipp.speed_kn": [1.0]}, "shipp.speed_kn", ["unknown field 'shipp'", "controller", "guidance"]),
    ({"ship.options.Q": [1.0]}, "ship.options.Q", ["unknown field 'Q'", "K", "T"]),
    ({"ship.speed_kn.x": [1.0]}, "ship.speed_kn.x", ["is a value"]),
    ({"controller.Kp": []}, "controller.Kp", ["at least one value"]),
    ({"controller.Kp": [-1.0]}, "controller.Kp", ["greater than or equal to 0"]),
])
def test_bad_names_and_values_name_the_field(changes, field, words):
    with pytest.raises(InputError) as err:
        sl.vary(BASE, changes)
    assert err.value.field == field
    for w in words:
        assert w in str(err.value)


def test_zip_needs_equal_lengths_and_mode_is_checked():
    with pytest.raises(InputError) as err:
        sl.vary(BASE, {"controller.Kp": [1.0, 2.0], "seed": [1]}, mode="zip")
    assert err.value.field == "vary" and "equal length" in str(err.value)
    with pytest.raises(InputError) as err:
        sl.vary(BASE, {"seed": [1]}, mode="cartesian")
    assert err.value.field == "mode"
