"""``steerlab cache warm``'s plant steps, trial loops and scenario files (issue 14): each warms
exactly what the real use then runs (no new driver, no new compiled signature afterwards),
and bad input is one line, exit 2, before anything compiles."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from steerlab.cli import main

REPO = Path(__file__).resolve().parent.parent
LOS_ROUTE = REPO / "examples" / "scenarios" / "los-route.toml"


def _compiled_signatures() -> dict:
    """Every compiled (or loaded) signature of every entry point of the drivers in this process."""
    out = {}
    for name, mod in list(sys.modules.items()):
        if name.startswith("steerlab_driver_") and hasattr(mod, "ENTRY_POINTS"):
            for entry in mod.ENTRY_POINTS:
                disp = getattr(mod, entry, None)
                out[(name, entry)] = frozenset(getattr(disp, "signatures", ()))
    return {k: v for k, v in out.items() if v}


def _assert_warmed(warm, use):
    warm()
    before = _compiled_signatures()
    use()
    after = _compiled_signatures()
    assert after == before, sorted(set(after.items()) - set(before.items()))


def test_plant_warm_covers_the_readable_loop_and_identifications_replay():
    from steerlab.identification.response import simulate_response
    from steerlab.sim.engine import simulate
    from steerlab.sim.setup import build
    from steerlab.warm import warm_plant, warm_scenario
    from steerlab.ships.registry import get_ship

    def use():
        res = simulate(build(warm_scenario("nomoto2", "pid")), "readable")
        assert np.isfinite(res.states).all()
        spec = get_ship("nomoto2")
        psi, r = simulate_response(spec.rhs, spec.n_states, build(warm_scenario("nomoto2", "pid")).ps,
                                   np.full(50, 0.1), 0.5, speed=5.0)
        assert r[-1] > 0.0                                  # starboard rudder, starboard turn

    _assert_warmed(lambda: warm_plant("nomoto2"), use)


def test_trial_warm_covers_a_zigzag_trial():
    from steerlab.warm import warm_trial
    from steerlab.trials.api import run_trial
    from steerlab.trials.runner import TrialConditions

    def use():
        _, metrics = run_trial("zigzag", TrialConditions("norrbin"), rudder_deg=10.0, heading_deg=10.0)
        assert len(metrics["overshoot_angles_deg"]) >= 2

    _assert_warmed(lambda: warm_trial("norrbin"), use)


def test_scenario_warm_covers_its_single_run_and_batch():
    import steerlab as sl
    from steerlab.sim.batch import simulate_batch
    from steerlab.sim.scenario import load_scenario
    from steerlab.sim.setup import build
    from steerlab.warm import warm_scenario_file

    def use():
        setup = build(load_scenario(LOS_ROUTE))
        single = sl.simulate(setup)
        batch = simulate_batch([setup, setup])
        np.testing.assert_array_equal(batch.final_states[1], single.states[-1])

    _assert_warmed(lambda: warm_scenario_file(LOS_ROUTE, batch=True), use)


_PYTHON_SIDE = """
import json
from steerlab.components.linear import linear_model
from steerlab.control.registry import get_controller
from steerlab.ships.registry import SHIPS, get_ship
from steerlab.sim.engine import simulate
from steerlab.sim.setup import build
from steerlab.warm import warm_pair, warm_plant, warm_scenario

ship = next(name for name in sorted(SHIPS) if get_ship(name).linearise is None)
rhs, update = get_ship(ship).rhs, get_controller("adrc").update
warm_plant(ship)
warm_pair(ship, "adrc")
before = [sorted(map(str, rhs.signatures)), sorted(map(str, update.signatures))]
linear_model(ship)
simulate(build(warm_scenario(ship, "adrc")), "readable")
after = [sorted(map(str, rhs.signatures)), sorted(map(str, update.signatures))]
print(json.dumps({"ship": ship, "before": before, "after": after}))
"""


def test_plant_warm_covers_linearisation_and_pair_warm_the_readable_controller():
    """The kernels called from Python: ``--plants`` warms the ship's rhs as linearisation calls
    it (``sl.linearize``, the design rules: one float signature, whatever the straight-running
    rudder's type), a pair's warm-up the controller's update as the readable loop calls it. In
    a new process: one where no other test has already compiled them."""
    import json
    import subprocess

    p = subprocess.run([sys.executable, "-c", _PYTHON_SIDE], capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, p.stderr
    out = json.loads(p.stdout.strip().splitlines()[-1])
    assert all(out["before"]), out                        # the warm-ups compiled (or loaded) both
    assert out["after"] == out["before"], out             # linearisation and the readable loop: nothing new


_RUN_SIDE = """
import json, sys
from steerlab import fast_csv
from steerlab.angles import wrap_to_pi
from steerlab.cli import main
from steerlab.ships.registry import get_ship
from steerlab.warm import warm_pair

def signatures():
    kernels = [get_ship("esso").rhs, wrap_to_pi, *fast_csv._compile()]
    return [sorted(map(str, k.signatures)) for k in kernels]

warm_pair("esso", "adrc")                 # the default scenario's pair
before = signatures()
assert main(["run", "--out", sys.argv[1]]) == 0
print(json.dumps({"before": before, "after": signatures()}))
"""


def test_pair_warm_covers_what_the_default_run_calls_from_python(tmp_path):
    """After the pair's warm-up, ``steerlab run`` on the bundled default calls no kernel with a
    signature the warm-up did not: the ship's rhs called from Python (the wave's channel probe),
    the metrics' heading wrap and the CSV formatter. In a new process (see above)."""
    import json
    import subprocess

    p = subprocess.run([sys.executable, "-c", _RUN_SIDE, str(tmp_path / "out")], capture_output=True, text=True,
                       timeout=600)
    assert p.returncode == 0, p.stderr
    out = json.loads(p.stdout.strip().splitlines()[-1])
    assert all(out["before"]), out
    assert out["after"] == out["before"], out


def test_lanes_warm_covers_the_batch_at_that_group_size():
    """``--lanes``: the batch loop at another number of runs per vector group (another driver
    per group size) is warmed too, and the batch at that size then loads or compiles nothing
    more in this process (2 runs per group: a size .ci/warm-cache warms, so CI loads it)."""
    from steerlab.sim.batch import simulate_batch
    from steerlab.sim.setup import build
    from steerlab.warm import warm_pair, warm_scenario

    def use():
        setup = build(warm_scenario("nomoto1", "pid"))
        a = simulate_batch([setup] * 5, lanes=2)
        b = simulate_batch([setup] * 5)
        np.testing.assert_array_equal(a.final_states, b.final_states)

    _assert_warmed(lambda: warm_pair("nomoto1", "pid", batch=True, lanes=(16, 2)), use)


@pytest.mark.parametrize("argv, field", [
    (["--scenario", "no-such-file.toml"], "scenario"),
    (["--ships", "no-such-ship", "--plants"], "ship"),
    (["--ships", "nomoto1", "--batch", "--lanes", "0"], "--lanes"),
    (["--ships", "nomoto1", "--batch", "--lanes", "16", "65"], "--lanes"),
    (["--ships", "nomoto1", "--lanes", "3"], "--lanes"),              # --lanes warms the batch: needs --batch
])
def test_bad_warm_input_is_one_line_and_exit_2(argv, field, capsys, monkeypatch, tmp_path):
    monkeypatch.setenv("STEERLAB_CACHE_DIR", str(tmp_path))
    assert main(["cache", "warm", "--quiet", *argv]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and field in err, err
    assert not any(tmp_path.rglob("*.nbi"))                 # nothing compiled before the refusal


def test_scenario_warm_with_plants_covers_the_plant_step_of_its_ships_options():
    """An rpm schedule in ``[ship.options]`` gives the ship another kernel than the catalogue's
    (``mmg_rhs`` instead of ``mmg_rhs_constant_rate``): ``--plants`` with ``--scenario`` warms
    that kernel's plant step, which the readable loop of the scenario then runs."""
    from steerlab.sim.engine import simulate
    from steerlab.sim.scenario import load_scenario
    from steerlab.sim.setup import build
    from steerlab.warm import warm_scenario_file

    path = REPO / ".ci" / "warm" / "kosoko-rpm-schedule.toml"

    def use():
        res = simulate(build(load_scenario(path)), "readable")
        assert np.isfinite(res.states).all()

    _assert_warmed(lambda: warm_scenario_file(path, plants=True), use)
