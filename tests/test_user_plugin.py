"""examples/user_plugin: a ship and a controller in the user's own module, outside the package,
through simulate, simulate_batch, montecarlo and tune (registered by register_*), and through
the CLI (registered by module path, STEERLAB_PLUGINS)."""

from __future__ import annotations

import importlib
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

EXAMPLE = Path(__file__).resolve().parent.parent / "examples" / "user_plugin"


@pytest.fixture(scope="module")
def example():
    sys.path.insert(0, str(EXAMPLE))
    try:
        yield importlib.import_module("run_example")
    finally:
        sys.path.remove(str(EXAMPLE))


def test_example_runs_in_every_engine_and_command(example):
    out = example.main(duration=120.0, runs=2, generations=1)
    assert abs(out["final_heading_deg"] - 20.0) < 2.0                 # the course change happened
    assert len(out["batch_final_heading_deg"]) == 9
    assert np.isfinite(out["montecarlo_itae_mean"]) and out["montecarlo_itae_mean"] > 0
    assert 0.5 <= out["tuned"]["kp"] <= 4.0 and 5.0 <= out["tuned"]["td"] <= 80.0


def test_example_passes_the_kernel_checks(example):
    from steerlab.testing import check_controller, check_ship

    example.register()
    assert check_ship(example.my_ship.SHIP, options={"a": 30.0}, vectorisation=False)["parity_max_abs_diff"] <= 1e-12
    assert check_controller(example.my_controller.CONTROLLER, vectorisation=False)["n_state"] == 1


def test_register_module_by_path_is_idempotent_for_the_same_module(example):
    from steerlab.plugins import register_module

    example.register()
    specs = register_module(str(EXAMPLE / "my_ship.py"))        # the same module object: no clash
    assert [s.name for s in specs] == ["my_norrbin"]


def test_cli_with_plugins_by_module_path(tmp_path):
    env = dict(os.environ)
    env["STEERLAB_PLUGINS"] = os.pathsep.join([str(EXAMPLE / "my_ship.py"), str(EXAMPLE / "my_controller.py")])
    sc = tmp_path / "s.toml"
    sc.write_text((EXAMPLE / "scenario.toml").read_text().replace("duration = 600.0", "duration = 60.0"))
    r = subprocess.run([sys.executable, "-m", "steerlab", "montecarlo", str(sc), "--runs", "2", "--out",
                        str(tmp_path / "mc"), "--quiet"], env=env, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    mc = json.loads((tmp_path / "mc" / "montecarlo.json").read_text())
    assert mc["metrics"]["itae_deg_s2"]["n"] == 2
    env["STEERLAB_PLUGINS"] = str(tmp_path / "missing.py")
    r = subprocess.run([sys.executable, "-m", "steerlab", "run", str(sc), "--out", str(tmp_path / "x")],
                       env=env, capture_output=True, text=True, timeout=600)
    assert r.returncode == 2 and "STEERLAB_PLUGINS" in r.stderr and len(r.stderr.strip().splitlines()) == 1


def test_a_plugin_file_never_replaces_another_module(tmp_path):
    """A plug-in file is keyed by its resolved path, never its stem: one named like a module
    already imported (``json.py``) is a module of its own and ``json`` stays (tests/test_layering.py:
    no replaced modules); two files of the same name are two modules (tests/test_plugin_identity.py)."""
    import json
    import sys

    from steerlab.plugins import load_module

    f = tmp_path / "json.py"
    f.write_text("X = 1\n", encoding="utf-8")
    mine = load_module(str(f))
    assert mine.X == 1 and mine is not json
    assert sys.modules["json"] is json and hasattr(json, "dumps")
    other = tmp_path / "sub"
    other.mkdir()
    (tmp_path / "my_plug.py").write_text("X = 1\n", encoding="utf-8")
    (other / "my_plug.py").write_text("X = 2\n", encoding="utf-8")
    first = load_module(str(tmp_path / "my_plug.py"))
    second = load_module(str(other / "my_plug.py"))
    assert first.X == 1 and second.X == 2 and first is not second
    assert load_module(str(tmp_path / "my_plug.py")) is first and first.X == 1   # not replaced
    for m in (mine, first, second):
        sys.modules.pop(m.__name__, None)
