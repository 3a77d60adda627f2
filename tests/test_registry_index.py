"""The registries' name -> module index (steerlab.registry_index): a process that validates one
scenario imports only its controller's and its ship's modules; a missing, stale or corrupt index
is rebuilt; plug-ins still join (and still clash); messages are those of the full discovery."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLE = Path(__file__).resolve().parent.parent / "examples" / "user_plugin"

PROBE = """
import json, sys
from steerlab.errors import InputError
from steerlab.sim.scenario import scenario_from_dict
from steerlab.ships.registry import get_ship
for arg in sys.argv[1:]:
    out = {}
    try:
        sc = scenario_from_dict(json.loads(arg))
        out["controller"] = type(sc.controller).__name__
        out["ship"] = get_ship(sc.ship.model).name
    except InputError as err:
        out["error"] = str(err)
    out["modules"] = sorted(m for m in sys.modules if m.startswith(("steerlab.control.", "steerlab.ships.")))
    print(json.dumps(out))
"""


def _probes(scenarios: list, cache: Path, **env) -> list:
    """What one new process says of each scenario in turn: its controller's and ship's names,
    or its error; and the controller and ship modules imported so far."""
    e = {k: v for k, v in os.environ.items() if k not in ("STEERLAB_PLUGINS", "STEERLAB_REGISTRY_INDEX")}
    e.update(STEERLAB_CACHE_DIR=str(cache), **env)
    r = subprocess.run([sys.executable, "-c", PROBE, *map(json.dumps, scenarios)], env=e, capture_output=True,
                       text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    return [json.loads(line) for line in r.stdout.strip().splitlines()[-len(scenarios):]]


def _probe(scenario: dict, cache: Path, **env) -> dict:
    """What a new process says of ``scenario`` (:func:`_probes`)."""
    return _probes([scenario], cache, **env)[0]


def _index_file(cache: Path, package: str) -> Path:
    (path,) = cache.glob(f"drivers/*/registry-{package}.json")
    return path


PID_ON_ESSO = {"ship": {"model": "esso"}, "controller": {"type": "pid", "Kp": 2.0}}


@pytest.fixture(scope="module")
def indexed(tmp_path_factory) -> Path:
    """A cache where a process validated PID_ON_ESSO, writing the index (tests that start from
    an index take a copy: one such process for the module instead of one per test)."""
    from conftest import once_per_session

    def make(cache: Path) -> dict:
        _probe(PID_ON_ESSO, cache)
        return {"cache": str(cache)}

    return Path(once_per_session(tmp_path_factory, "registry-index-indexed", make)["cache"])


def _copy(cache: Path, to: Path) -> Path:
    shutil.copytree(cache, to)
    return to


def test_with_the_index_only_the_chosen_modules_are_imported(tmp_path):
    first = _probe(PID_ON_ESSO, tmp_path)                        # no index yet: full discovery, writes it
    assert "steerlab.control.adrc" in first["modules"] and "steerlab.control.sliding_mode" in first["modules"]
    index = json.loads(_index_file(tmp_path, "steerlab.control").read_text())["names"]
    assert index["pid"] == ["steerlab.control.pid", None]
    assert index["adrc+wf"] == ["steerlab.control.adrc", "adrc"]
    assert json.loads(_index_file(tmp_path, "steerlab.ships").read_text())["names"]["esso"][0].startswith("steerlab.ships.")
    second = _probe(PID_ON_ESSO, tmp_path)
    assert second["controller"] == first["controller"] == "PIDConfig" and second["ship"] == "esso"
    others = {"steerlab.control.adrc", "steerlab.control.sliding_mode", "steerlab.control.backstepping_a",
              "steerlab.ships.mmg_kvlcc2"}
    assert not others & set(second["modules"]), second["modules"]
    assert len(second["modules"]) < len(first["modules"])
    wf = _probe({**PID_ON_ESSO, "controller": {"type": "pid+wf"}}, tmp_path)   # a derived name
    assert wf["controller"].endswith("WaveFiltered") and "steerlab.control.adrc" not in wf["modules"]


@pytest.mark.parametrize("damage", ["wrong module", "not json", "unknown name"])
def test_a_stale_or_corrupt_index_is_rebuilt(indexed, tmp_path, damage):
    cache = _copy(indexed, tmp_path / "cache")
    path = _index_file(cache, "steerlab.control")
    good = json.loads(path.read_text())
    bad = json.loads(path.read_text())
    if damage == "wrong module":
        bad["names"]["pid"] = ["steerlab.control.adrc", None]         # adrc declares no "pid"
    elif damage == "unknown name":
        del bad["names"]["pid"]
    path.write_text("{not json" if damage == "not json" else json.dumps(bad))
    out = _probe(PID_ON_ESSO, cache)
    assert out["controller"] == "PIDConfig"                          # found by the full discovery
    assert json.loads(path.read_text()) == good                      # and the index rewritten


def test_messages_for_unknown_names_are_those_of_the_full_discovery(indexed, tmp_path):
    cache = _copy(indexed, tmp_path / "cache")
    bads = [{"controller": {"type": "nope"}}, {"controller": {}}, {"controller": 5},
            {"controller": {"type": "pid", "Kp": -1.0}}, {"controller": {"type": "adrc+wf", "bogus": 1}}]
    # without the index every name goes through the full discovery: one process for all of them;
    # with it, a fresh process for each (the first unknown name would discover everything)
    full = _probes(bads, cache, STEERLAB_REGISTRY_INDEX="0")
    with_index = [_probe(bad, cache) for bad in bads]
    for bad, i, f in zip(bads, with_index, full, strict=True):
        assert i["error"] == f["error"], bad
    msg = with_index[0]["error"]                                     # {"controller": {"type": "nope"}}
    assert msg.startswith("controller.type: unknown type 'nope'; known: adrc, ") and "pid" in msg
    msg = _probe({"ship": {"model": "nope"}, "controller": {"type": "pid"}}, cache)["error"]
    assert msg.startswith("ship.model: unknown ship 'nope'; known ships (`steerlab ships` prints them): b481, ")
    assert ", esso, " in msg


def test_plugins_are_found_and_still_clash_with_the_index_present(indexed, tmp_path):
    cache = _copy(indexed, tmp_path / "cache")
    plugins = os.pathsep.join([str(EXAMPLE / "my_ship.py"), str(EXAMPLE / "my_controller.py")])
    out = _probe({"ship": {"model": "my_norrbin"}, "controller": {"type": "my_pd"}}, cache,
                 STEERLAB_PLUGINS=plugins)
    assert out.get("ship") == "my_norrbin" and "error" not in out, out
    clash = tmp_path / "clash.py"
    clash.write_text("from dataclasses import replace\nfrom steerlab.control import pid\n"
                     "CONTROLLER = replace(pid.CONTROLLER)\n")          # a second 'pid'
    out = _probe(PID_ON_ESSO, cache, STEERLAB_PLUGINS=str(clash))
    assert out.get("error", "").startswith("controller.type: controller 'pid' declared twice (steerlab.control.pid "
                                           "and STEERLAB_PLUGINS "), out


def test_a_spec_found_by_index_is_the_one_the_full_discovery_returns():
    from steerlab.control.registry import CONTROLLERS
    from steerlab.plugins import Registry

    fresh = Registry("controller", "steerlab.control", CONTROLLERS.collect, CONTROLLERS.spec_type,
                     "controller.type", "steerlab.controllers", skip=CONTROLLERS.skip, derive=CONTROLLERS.derive)
    wf = fresh.get_spec("adrc+wf")                  # the index (written by earlier processes) or full
    plain = fresh.get_spec("adrc")
    assert fresh["adrc+wf"] is wf and fresh["adrc"] is plain    # after the full discovery: same objects
    assert wf.config is fresh["adrc+wf"].config
