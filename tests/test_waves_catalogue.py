"""Spectrum waves on every catalogue ship (issue 30, item 5).

Every ship of ``steerlab ships`` takes a JONSWAP sea: the waves reach the ship (a non-zero,
finite wave channel, a heading that moves) and nothing is refused. A ship without beam and block
coefficient (the thesis catalogue) gets the coupling of a typical hull of its length, with one
warning that names the setting and the value; a ship without even a length is refused in one
line that gives the typical value.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import steerlab as sl
from steerlab.environment.channels import W_RUDDER, W_YAW_MOMENT, W_YAW_RATE
from steerlab.environment.typical_hull import (BLOCK_COEFFICIENT, FIELD, L_OVER_B, has_hull_data, hull_gain,
                                               typical_gain)
from steerlab.environment.wave_superposition import daidola_gain
from steerlab.errors import InputError
from steerlab.ships.registry import _discover, get_ship
from steerlab.sim.sanity import scenario_warnings
from steerlab.sim.scenario import scenario_from_dict
from steerlab.sim.setup import build
from steerlab.units import KNOT

SHIPS = sorted(_discover())
WAVE = {"model": "spectrum", "spectrum": "jonswap", "sea_state": 4, "wave_angle_deg": 45.0}


def _speed_kn(ship) -> float:
    lo, hi = ship.speed_range
    if lo <= 16.0 * KNOT <= hi:
        return 16.0
    return 0.5 * (lo + hi) / KNOT if math.isfinite(hi) else 16.0


def _scenario(ship_id: str, **wave):
    ship = get_ship(ship_id)
    return scenario_from_dict({
        "seed": 3, "dt": 0.1, "duration": 30.0, "ship": {"model": ship_id, "speed_kn": _speed_kn(ship)},
        "controller": {"type": "pid", "Kp": 1.0, "Ki": 0.0, "Kd": 10.0},
        "environment": {"wave": {**WAVE, **wave}}})


def test_the_catalogue_has_ships_without_hull_data():
    """The point of the typical hull: the thesis entries give a length only."""
    bare = [s for s in SHIPS if not has_hull_data(get_ship(s).dims)]
    assert len(bare) >= 10 and all(math.isfinite(get_ship(s).dims[1]) for s in bare)


@pytest.mark.parametrize("ship_id", SHIPS)
def test_every_catalogue_ship_takes_spectrum_waves(ship_id):
    sc = _scenario(ship_id)
    setup = build(sc)
    waves = setup.w[:, [W_RUDDER, W_YAW_RATE, W_YAW_MOMENT]]
    assert np.all(np.isfinite(waves)) and np.max(np.abs(waves)) > 0.0
    r = sl.simulate(setup, "readable")                                           # no closed-loop compile per ship
    assert np.all(np.isfinite(r.states)) and np.ptp(r.col("r")) > 0.0         # the waves move the ship
    said = [w for w in scenario_warnings(sc) if w.startswith(FIELD)]
    ship = get_ship(ship_id)
    if has_hull_data(ship.dims):
        assert said == []
    else:
        (line,) = said
        L = ship.dims[1]
        assert "\n" not in line and f"{typical_gain(L):.3g} 1/s^2" in line and "set yaw_accel_per_slope" in line
    # a given coupling wins and silences the warning
    assert [w for w in scenario_warnings(_scenario(ship_id, yaw_accel_per_slope=0.5)) if w.startswith(FIELD)] == []


def test_typical_hull_is_daidola_graham_for_the_stated_proportions():
    for L in (45.0, 60.0, 100.0, 170.0):
        assert typical_gain(L) == daidola_gain(L, L / L_OVER_B, BLOCK_COEFFICIENT)
        assert typical_gain(L) == pytest.approx(80.0 / L, rel=2e-3)           # 80/L (module doc)
    # the thesis frigate gets the typical 100 m hull; its own dims would be used if it had them
    assert hull_gain("frigate-norrbin", get_ship("frigate-norrbin").dims) == (100.0, typical_gain(100.0), True)
    esso = get_ship("esso")
    assert hull_gain("esso", esso.dims) == (esso.dims[1], daidola_gain(esso.dims[1], esso.dims[2], esso.dims[0]),
                                            False)


def test_a_ship_without_a_length_is_refused_in_one_line_with_a_typical_value():
    with pytest.raises(InputError) as ei:
        hull_gain("my-ship", (math.nan, math.nan, math.nan))
    msg = str(ei.value)
    assert ei.value.field == FIELD and "\n" not in msg
    assert "80/L" in msg and "[0, 100]" in msg
