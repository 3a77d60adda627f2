"""A built setup or a scenario sent to another process (``pickle``: a ``spawn`` multiprocessing
child, a Dask worker, joblib) unpickles there, runs to the same numbers, and compiles nothing:
the ship and controller specs pickle by their registry name (or by the recipe that made them
from a registered one: the sensors' wrapper, a ship's kernel picked for its options), so the
child's kernels are its own module-level ones, which the compiled drivers name and load from
the disk cache (steerlab.plugins.PicklesByName).

Before, a ``"<name>+wf"`` controller or a catalogue ship made by a factory (closures) could not
be pickled at all, and a controller behind the sensors was compiled again in every child.
"""

from __future__ import annotations

import pickle
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parent.parent

#: scenarios of .ci/warm (compiled there once per CI run): a wrapped controller, the sensors, a
#: factory-made catalogue ship (a subclass of ShipSpec), a ship whose kernel is picked for its
#: options, a ship whose spec holds closures, and a plain pair
SCENARIOS = ("esso-pid-wf.toml", "esso-pid-sensors.toml", "norrbin-adrc-sensors-third-order.toml",
             "kosoko-berthing.toml", "dekeizer-pid-wf.toml", "esso-pid-los.toml")

CHILD = """
import pickle, sys
from numba.core import event
import steerlab as sl
with open(sys.argv[1], "rb") as f:
    items = pickle.load(f)
out = []
with event.install_recorder("numba:compile") as rec:
    for setup, scenario in items:
        a, b = sl.simulate(setup), sl.simulate(scenario)
        out.append((type(scenario.controller).__name__, a.columns(), b.columns()))
compiled = sorted({getattr(getattr(e.data.get("dispatcher"), "py_func", None), "__qualname__", "?")
                   for _, e in rec.buffer})
with open(sys.argv[2], "wb") as f:
    pickle.dump({"runs": out, "compiled": compiled}, f)
"""


def test_setups_and_scenarios_run_in_a_fresh_process_with_the_same_numbers_and_no_compile(tmp_path):
    import steerlab as sl
    from steerlab.sim.setup import build

    items, expected = [], []
    for name in SCENARIOS:
        scenario = sl.load_scenario(REPO / ".ci" / "warm" / name)
        setup = build(scenario)
        expected.append((type(scenario.controller).__name__, sl.simulate(setup).columns()))  # compiled here (or loaded)
        items.append((setup, scenario))
    (tmp_path / "in.pkl").write_bytes(pickle.dumps(items))
    proc = subprocess.run([sys.executable, "-c", CHILD, str(tmp_path / "in.pkl"), str(tmp_path / "out.pkl")],
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-3000:]
    got = pickle.loads((tmp_path / "out.pkl").read_bytes())
    assert got["compiled"] == []                       # every loop came from the driver cache
    for name, (config_class, want), (got_class, from_setup, from_scenario) in zip(SCENARIOS, expected, got["runs"]):
        assert got_class == config_class, name
        for column, values in want.items():
            np.testing.assert_array_equal(from_setup[column], values, err_msg=f"{name}: {column}")
            np.testing.assert_array_equal(from_scenario[column], values, err_msg=f"{name}: {column}")


def test_every_registered_ship_and_controller_pickles_as_its_name():
    from steerlab.control.registry import CONTROLLERS
    from steerlab.ships.registry import SHIPS

    for registry in (SHIPS, CONTROLLERS):
        for name in registry:
            spec = registry[name]
            if not registry.found_everywhere(spec):
                # registered while this process runs, by a test of another module that ran in
                # this worker before (test_user_plugin registers its example): by value, by design
                # (test_a_spec_registered_while_the_process_runs_pickles_field_by_field)
                assert name.startswith("my_"), name       # never one of steerlab's own
                continue
            assert pickle.loads(pickle.dumps(spec)) is spec, name
            assert len(pickle.dumps(spec)) < 300, name      # the name, not the kernels' code


def test_a_modified_copy_of_a_spec_pickles_field_by_field():
    """A spec that is not the registry's own (``dataclasses.replace``) keeps its own fields."""
    from dataclasses import replace

    from steerlab.control.registry import get_controller

    spec = replace(get_controller("pid"), description="my PID")
    back = pickle.loads(pickle.dumps(spec))
    assert back is not spec and back.description == "my PID" and back.name == "pid"


def test_a_spec_registered_while_the_process_runs_pickles_field_by_field(tmp_path):
    """A fresh process does not know a spec registered at run time (or knows another spec under
    a name replaced at run time): such a spec, and its ``+wf`` variant (by its recipe), carry
    their own fields and run in the other process."""
    from steerlab.control.registry import CONTROLLERS, ControllerSpec, get_controller

    pid = get_controller("pid")
    spec = ControllerSpec(name="only-here", description="a plug-in of this process", update=pid.update,
                          n_state=pid.n_state, config=pid.config, build=pid.build)
    CONTROLLERS.register(spec)
    try:
        wf = get_controller("only-here+wf")
        blob = pickle.dumps([spec, wf])
        assert len(blob) > 1000                           # the fields, kernels included
        assert pickle.loads(pickle.dumps(get_controller("pid+wf"))) is get_controller("pid+wf")
    finally:
        CONTROLLERS.unregister("only-here")
    script = ("import pickle, sys; spec, wf = pickle.loads(open(sys.argv[1], 'rb').read()); "
              "print(spec.name, spec.description, wf.name, wf.update.py_func.__globals__['_inner'].py_func.__name__)")
    (tmp_path / "spec.pkl").write_bytes(blob)
    proc = subprocess.run([sys.executable, "-c", script, str(tmp_path / "spec.pkl")], capture_output=True,
                          text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert proc.stdout.split() == ["only-here", "a", "plug-in", "of", "this", "process", "only-here+wf",
                                   "pid_update"]


@pytest.mark.parametrize("name", ["pid+wf", "adrc+wf"])
def test_a_wave_filtered_config_pickles_as_its_controllers_config(name):
    from steerlab.control.registry import get_controller

    cls = get_controller(name).config
    cfg = cls.model_validate({"type": name, "wave_filter": {"T_lf": 25.0}})
    back = pickle.loads(pickle.dumps(cfg))
    assert type(back) is cls and back == cfg


def test_the_documented_spawn_pool_example_runs_with_the_numbers_of_this_process(tmp_path):
    """docs/compile-cache.md's example, as a script: setups mapped over a real ``spawn`` pool."""
    import re

    import steerlab as sl
    from steerlab.sim.setup import build

    doc = (REPO / "docs" / "compile-cache.md").read_text(encoding="utf-8")
    section = doc.split("### Setups and scenarios sent to other processes", 1)[1]
    code = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    script = tmp_path / "spawn_example.py"         # (a spawn child imports the main module's file)
    script.write_text(code, encoding="utf-8")
    proc = subprocess.run([sys.executable, str(script)], cwd=REPO, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-3000:]
    got = [float(v) for v in re.findall(r"np\.float64\(([^)]+)\)|([-+\d.e]+)", proc.stdout) for v in v if v]
    scenario = sl.load_scenario(REPO / "examples" / "scenarios" / "esso-pid.toml")
    want = [float(sl.simulate(build(scenario.replace(seed=s))).states[-1, 2]) for s in range(8)]
    assert got == want
