"""Shared helpers for the core test suite.

Scenarios are built from plain dicts (the TOML shape) so every test goes through the same
validation as a user file. Compiled runs reuse two (ship, controller) combinations only,
esso+pid and esso+adrc, so each compiles once per test process.
"""

from __future__ import annotations

import copy
import os
from pathlib import Path

import pytest

from steerlab.sim.scenario import scenario_from_dict

# Subprocess tests (``python -m steerlab ...``) must import this checkout's ``src`` (pytest's
# ``pythonpath`` only reaches this process), whichever checkout an editable install points to.
_SRC = str(Path(__file__).resolve().parent.parent / "src")
os.environ["PYTHONPATH"] = os.pathsep.join(p for p in (_SRC, os.environ.get("PYTHONPATH")) if p)

BASE = {
    "name": "test",
    "seed": 0,
    "dt": 0.1,
    "duration": 300.0,
    "ship": {"model": "esso", "speed_kn": 16.0},
    "controller": {"type": "pid"},
    "guidance": {"psi0_deg": 0.0, "changes": []},
    "environment": {},
}


def _merge(base: dict, over: dict) -> dict:
    out = copy.deepcopy(base)
    for k, v in over.items():
        if isinstance(v, dict) and isinstance(out.get(k), dict) and k != "controller":
            out[k] = _merge(out[k], v)
        else:
            out[k] = copy.deepcopy(v)
    return out


def make_scenario_dict(**over) -> dict:
    """The base dict with top-level / nested overrides (``controller`` is replaced whole)."""
    return _merge(BASE, over)


def make_scenario(**over):
    return scenario_from_dict(make_scenario_dict(**over))


@pytest.fixture
def scenario():
    """Factory: ``scenario(duration=..., controller={...}, guidance={...})`` -> Scenario."""
    return make_scenario
