"""A user's script, type-checked: the public API used as the docs show it.

``mypy`` checks this file with the package (``[tool.mypy]`` in pyproject.toml,
``tests/test_typing.py``): each ``assert_type`` states the type a user's editor and type
checker see, so a public function whose annotation drifts from what it returns fails the
check. ``tests/test_typing.py`` also runs it (``python tests/typing_usage.py``), so every
line works as written (short runs; the runtime ``isinstance`` checks back the annotations).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import assert_type

import numpy as np

import steerlab as sl
from steerlab.components.controller import Controller
from steerlab.components.controller_vector import ControllerVector
from steerlab.components.ship import Ship
from steerlab.control.registry import ControllerSpec, get_controller
from steerlab.errors import InputError
from steerlab.records import Field, Layout
from steerlab.ships.registry import ShipSpec, get_ship
from steerlab.sim.batch import BatchResult
from steerlab.sim.result import Result
from steerlab.sim.scenario import Scenario
from steerlab.sim.setup import SimSetup, build

ROOT = Path(__file__).resolve().parent.parent


def main() -> None:
    # ------------------------------------------------------------ scenarios and runs
    scenario = sl.default_scenario().replace(duration=60.0)
    assert_type(scenario, Scenario)
    pid_file = sl.load_scenario(ROOT / "examples" / "scenarios" / "esso-pid.toml")
    assert_type(pid_file, Scenario)

    result = sl.simulate(scenario)
    assert_type(result, Result)
    assert isinstance(result, Result)
    heading_error: np.ndarray = result.heading_error
    assert heading_error.shape == result.time.shape
    assert_type(result.dt, float)

    variants = sl.vary(scenario, {"controller.T_settle": [100.0, 150.0], "seed": [1, 2]})
    assert_type(variants, list[Scenario])
    assert len(variants) == 4 and all(isinstance(v, Scenario) for v in variants)

    setups = [build(v) for v in variants]
    assert_type(setups, list[SimSetup])
    batch = sl.simulate_batch(setups)
    assert_type(batch, BatchResult)
    assert batch.final_states.shape[0] == 4
    assert_type(batch.diverged, np.ndarray)

    # ------------------------------------------------------------ components
    pid = sl.controller("pid", nomoto=(0.05, 100.0), Kp=2.0, Ki=0.0, Kd=60.0)
    assert_type(pid, Controller)
    order = pid.reset(heading=0.0).step(0.0, heading=0.1, yaw_rate=0.0, heading_ref=0.0)
    assert_type(order, float)
    assert math.isfinite(order)

    many = sl.controllers("pid", n=3, nomoto=(0.05, 100.0), Kp=2.0, Ki=0.0, Kd=60.0)
    assert_type(many, ControllerVector)
    orders = many.reset().step(0.0, heading=np.array([0.1, 0.0, -0.1]), yaw_rate=0.0, heading_ref=0.0)
    assert_type(orders, np.ndarray)
    assert orders.shape == (3,)

    tanker = sl.ship("esso", 16.0)
    assert_type(tanker, Ship)
    state = tanker.reset(heading=0.0).step(order, 0.1)
    assert_type(state, np.ndarray)
    assert_type(tanker.heading, float)

    # ------------------------------------------------------------ registries, records, checks
    spec = get_controller("pid")
    assert_type(spec, ControllerSpec)
    esso = get_ship("esso")
    assert_type(esso, ShipSpec)
    assert_type(esso.nomoto(8.0), tuple[float, float])

    layout = Layout("demo", "D_", [Field("GAIN", "gain", "-", "a gain", lo=0.0)])
    record = layout.pack(gain=2.0)
    assert_type(record, np.ndarray)
    assert_type(layout.unpack(record), dict[str, float])

    try:
        sl.load_scenario(ROOT / "no-such-file.toml")
    except InputError as err:
        assert_type(err.field, str)
    assert_type(sl.wrap_to_pi(4.0), float)


if __name__ == "__main__":
    main()
    print("typing_usage: ok")
