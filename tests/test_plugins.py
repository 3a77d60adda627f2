"""The plug-in contract: one registry class, register_ship / register_controller, entry points."""

from __future__ import annotations

from dataclasses import replace
from typing import Literal

import numpy as np
import pytest
from pydantic import create_model

import steerlab as sl
from steerlab.control.pid import PIDConfig
from steerlab.control.registry import CONTROLLERS, ControllerSpec, get_controller
from steerlab.errors import InputError
from steerlab.plugins import Registry
from steerlab.ships.registry import SHIPS, ShipSpec, get_ship
from steerlab.sim.engine import simulate
from steerlab.sim.scenario import scenario_from_dict
from steerlab.sim.setup import build


def _renamed_pid(name: str) -> ControllerSpec:
    cfg = create_model(f"Cfg_{name}", __base__=PIDConfig, type=(Literal[name], ...))
    return replace(get_controller("pid"), name=name, config=cfg)


def test_item_assignment_is_refused_with_a_pointer_to_register():
    with pytest.raises(TypeError, match="register_ship"):
        SHIPS["myship"] = get_ship("esso")
    with pytest.raises(TypeError, match="register_controller"):
        CONTROLLERS["mine"] = get_controller("pid")
    assert "myship" not in SHIPS and "mine" not in CONTROLLERS


def test_register_controller_joins_scenarios_and_gets_a_wave_filter():
    spec = sl.register_controller(_renamed_pid("pid_plugin_t1"))
    assert get_controller("pid_plugin_t1") is spec and "pid_plugin_t1+wf" in CONTROLLERS
    base = {"duration": 30.0, "ship": {"model": "esso"}, "guidance": {"changes": [{"t": 1.0, "psi_deg": 5.0}]}}
    mine = simulate(build(scenario_from_dict({**base, "controller": {"type": "pid_plugin_t1", "Kp": 2.0}})))
    ref = simulate(build(scenario_from_dict({**base, "controller": {"type": "pid", "Kp": 2.0}})))
    np.testing.assert_array_equal(mine.states, ref.states)     # the same law under another name
    sc = scenario_from_dict({**base, "controller": {"type": "pid_plugin_t1+wf", "filter_K": 0.05,
                                                     "filter_T": 100.0}})
    assert build(sc).controller.name == "pid_plugin_t1+wf"
    with pytest.raises(InputError) as err:                       # a name is declared once
        sl.register_controller(_renamed_pid("pid_plugin_t1"))
    assert err.value.field == "controller.type" and "declared twice" in str(err.value)
    with pytest.raises(InputError) as err:                       # bad fields still name the field
        scenario_from_dict({**base, "controller": {"type": "pid_plugin_t1", "Kp": -1.0}})
    assert err.value.field == "controller.Kp"


def test_register_ship_by_name():
    spec = sl.register_ship(replace(get_ship("esso"), name="esso_plugin_t1"))
    assert get_ship("esso_plugin_t1") is spec
    s = build(scenario_from_dict({"duration": 10.0, "ship": {"model": "esso_plugin_t1"}, "controller": {"type": "pid"}}))
    assert s.ship is spec
    with pytest.raises(TypeError):
        sl.register_ship("esso")                                  # not a spec
    with pytest.raises(InputError):
        sl.register_ship(replace(get_ship("esso"), name="esso_plugin_t1"))


class _EntryPoint:
    def __init__(self, name, value, obj):
        self.name, self.value, self._obj = name, value, obj

    def load(self):
        if isinstance(self._obj, Exception):
            raise self._obj
        return self._obj


def _fresh_ship_registry():
    def collect(module):
        specs = getattr(module, "SHIP_SPECS", ())
        return list(specs() if callable(specs) else specs)
    return Registry("ship", "steerlab.ships", collect, ShipSpec, "ship.model", "steerlab.ships",
                    skip={"registry"}, recursive=True)


def test_entry_points_are_read(monkeypatch):
    import importlib.metadata

    extra = replace(get_ship("esso"), name="esso_from_entry_point")
    seen = []

    def entry_points(group):
        seen.append(group)
        return [_EntryPoint("x", "pkg.mod:SPEC", [extra])] if group == "steerlab.ships" else []

    monkeypatch.setattr(importlib.metadata, "entry_points", entry_points)
    reg = _fresh_ship_registry()
    assert reg["esso_from_entry_point"] is extra and "esso" in reg and seen == ["steerlab.ships"]
    broken = _fresh_ship_registry()
    monkeypatch.setattr(importlib.metadata, "entry_points",
                        lambda group: [_EntryPoint("bad", "pkg.bad:X", ImportError("no module pkg"))])
    with pytest.raises(InputError) as err:
        broken["esso"]
    assert err.value.field == "steerlab.ships" and "'bad'" in str(err.value)


def test_unknown_names_list_the_known_ones():
    with pytest.raises(InputError) as err:
        get_ship("no_such_ship")
    assert err.value.field == "ship.model" and "esso" in str(err.value)
    with pytest.raises(InputError) as err:
        get_controller("no_such_controller")
    assert err.value.field == "controller.type" and "pid" in str(err.value)
