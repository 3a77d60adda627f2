"""The batch engine's vectorised groups (steerlab.sim.lanes): any group size, the same numbers.

Each run of a batch must be bit-identical to the same run alone, whatever the number of
runs per group (``lanes``), with partial last groups, per-run seas and currents, decimated
logs, state-dependent guidance, and ships whose kernels do not vectorise.
"""

from __future__ import annotations

import numba
import numpy as np
import pytest


from steerlab.bench import W1, w1_batch_setups
from steerlab.errors import InputError
from steerlab.sim.batch import simulate_batch
from steerlab.sim.engine import simulate_compiled
from steerlab.sim.lanes import LANES
from steerlab.sim.scenario import scenario_from_dict
from steerlab.sim.setup import build

SEA = {"waves": True, "current_speed": 0.6, "current_dir_deg": 120.0, "constant_rudder_deg": 2.0}


def _w1(duration=120.0, seed=0, env=None, **over):
    return build(scenario_from_dict({**W1, "duration": duration, "seed": seed,
                                     "environment": env or {"waves": False}, **over}))


@pytest.fixture(scope="module")
def sea_runs():
    """19 runs (one full group of 16 and a partial one of 3) in 3 different seas, varied gains."""
    base = [_w1(seed=s, env=SEA) for s in (1, 2, 3)]
    runs = []
    for k, s in enumerate(w1_batch_setups(base[0], 19)):
        runs.append(s if k % 3 == 0 else type(s)(**{**s.__dict__, "w": base[k % 3].w}))
    return runs


def test_default_group_fills_a_vector():
    assert LANES % 4 == 0


#: the tests that compile the sea runs' batch group of 3 lanes: one worker (the second loads it)
SEA_RUNS_3 = "sea-runs-lanes-3"


@pytest.mark.xdist_group(SEA_RUNS_3)
@pytest.mark.parametrize("lanes", [3, LANES])
def test_every_run_equals_its_single_run(sea_runs, lanes):
    batch = simulate_batch(sea_runs, record_every=7, lanes=lanes)
    for i in (0, 1, 2, 15, 16, 18):
        single = simulate_compiled(sea_runs[i])
        np.testing.assert_array_equal(batch.final_states[i], single.states[-1])
        np.testing.assert_array_equal(batch.acc[i], single.meta["online_metrics"])
        np.testing.assert_array_equal(batch.states[i], single.states[::7])
        np.testing.assert_array_equal(batch.delta_cmd[i], single.delta_cmd[::7])


def test_the_seas_and_currents_really_differ(sea_runs):
    batch = simulate_batch(sea_runs)
    # same gains as run 0 would need the same sea: runs 0 and 3 share sea 1, but not gains
    assert len({tuple(b) for b in np.round(batch.final_states[:, :2], 6)}) == len(sea_runs)
    # the current sets the ship to the south-east: compare with the same run in calm water
    calm = simulate_compiled(_w1())
    assert batch.final_states[0][1] - calm.states[-1][1] > 0.6 * 0.5 * 120.0


def test_guided_batch_any_group_size_equals_single():
    sc = {"dt": 0.5, "duration": 200.0, "ship": {"model": "nomoto1", "speed_kn": 10.0},
          "controller": {"type": "pid", "Kp": 3.0, "Ki": 0.0, "Kd": 67.0},
          "guidance": {"type": "los", "start": [0.0, 100.0], "route": [[0.0, 0.0], [20000.0, 0.0]],
                       "lookahead_L": 5.0}}
    runs = []
    for y0 in (100.0, -60.0, 30.0, 250.0, -5.0):
        runs.append(build(scenario_from_dict({**sc, "guidance": {**sc["guidance"], "start": [0.0, y0]}})))
    ref = simulate_batch(runs, record_every=4, lanes=16)
    for lanes in (2,):
        other = simulate_batch(runs, record_every=4, lanes=lanes)
        np.testing.assert_array_equal(other.final_states, ref.final_states)
        np.testing.assert_array_equal(other.ref, ref.ref)
    for i, s in enumerate(runs):
        single = simulate_compiled(s)
        np.testing.assert_array_equal(ref.final_states[i], single.states[-1])
        np.testing.assert_array_equal(ref.acc[i], single.meta["online_metrics"])


def test_ship_with_branches_and_its_own_current_handling():
    """MMG's kernel with an rpm schedule reads the schedule at an index computed from the data
    (not vectorised; without a schedule the set-up picks the kernel that is): still the same numbers."""
    runs = [build(scenario_from_dict({"dt": 0.2, "duration": 60.0, "seed": s,
                                      "ship": {"model": "kosoko",
                                               "options": {"rpm_schedule": [[0, 600], [30, 600], [30, 500]]}},
                                      "controller": {"type": "pid", "Kp": 2.0, "Ki": 0.0, "Kd": 20.0},
                                      "guidance": {"psi0_deg": 0.0, "changes": [{"t": 5.0, "psi_deg": 10.0}]},
                                      "environment": {"current_speed": 0.3 * s, "current_dir_deg": 45.0}}))
            for s in range(3)]
    batch = simulate_batch(runs, lanes=16)
    for i, s in enumerate(runs):
        np.testing.assert_array_equal(batch.final_states[i], simulate_compiled(s).states[-1])
    # and the report says so (docs/ships.md: what a vectorisable kernel avoids)
    from steerlab.sim.lanes import vectorisation_report

    report = vectorisation_report(runs[0].ship.rhs, runs[0].controller.update, runs[0].x0.size, lanes=16)
    assert report["vectorised_stages"] == 0


def test_bad_group_size_is_refused(sea_runs):
    with pytest.raises(InputError, match="lanes"):
        simulate_batch(sea_runs[:2], lanes=0)


@pytest.mark.skipif(not numba.config.LOOP_VECTORIZE, reason="numba's loop vectoriser is switched off")
@pytest.mark.parametrize("ship", ["esso", "nomoto1"])
def test_the_four_rk4_stages_are_vectorised_across_runs(ship):
    """Structural guard for the batch speed: the compiled group holds the sin polynomial of
    the kinematics as vector arithmetic (``<N x double>``) once per RK4 stage. A branch, a
    raising division or a library call added to the ship (Esso; Nomoto 1, which divides by
    T), gear or kinematics kernels would make this fail."""
    from steerlab.sim.lanes import vectorisation_report

    setup = _w1(duration=1.0, ship={"model": ship, "speed_kn": 16.0})
    with pytest.raises(RuntimeError, match="not been compiled"):
        vectorisation_report(setup.ship.rhs, setup.controller.update, setup.x0.size, lanes=5)
    simulate_batch(w1_batch_setups(setup, 2))
    report = vectorisation_report(setup.ship.rhs, setup.controller.update, setup.x0.size)
    assert report["vectorised_stages"] >= 4 and report["per_run_library_calls"] == []


@pytest.mark.xdist_group(SEA_RUNS_3)
def test_a_forked_child_runs_batches_too(sea_runs):
    """The thread pool is per process: a child forked after a batch must not wait on the
    parent's (threadless) pool."""
    import multiprocessing as mp

    if "fork" not in mp.get_all_start_methods():
        pytest.skip("no fork on this platform")
    # lanes=3: the group size the other sea-run tests compile (2 groups of 5 runs: still a pool's work)
    want = simulate_batch(sea_runs[:5], lanes=3).final_states
    ctx = mp.get_context("fork")
    with ctx.Pool(1) as pool:
        got = pool.apply_async(_child_batch, (sea_runs[:5],)).get(timeout=120)
    np.testing.assert_array_equal(got, want)


def _child_batch(runs):
    return simulate_batch(runs, lanes=3).final_states


def test_progress_reports_runs_done_in_order_and_ends_complete(sea_runs, monkeypatch):
    from steerlab.sim import lanes

    monkeypatch.setattr(lanes, "PROGRESS_PERIOD", 0.0)       # report after every group
    calls = []
    batch = simulate_batch(sea_runs, lanes=3, progress=lambda done, n: calls.append((done, n)))
    assert {n for _, n in calls} == {19}
    done = [d for d, _ in calls]
    assert done == sorted(done) and done[-1] == 19 and len(done) >= 3
    # whole groups (6 of 3 runs and one of 1), in the order they finish
    assert set(np.diff([0] + done)) <= {1, 3, 4}
    np.testing.assert_array_equal(batch.final_states, simulate_batch(sea_runs, lanes=3).final_states)


def test_progress_bar_text():
    from steerlab.progress import bar, runs_progress

    assert bar(0, 10) == "[" + "." * 20 + "]"
    assert bar(5, 10) == "[" + "#" * 10 + "." * 10 + "]"
    assert bar(12, 10, width=4) == "[####]"
    said = []
    report = runs_progress(said.append, period=60.0)
    report(250, 1000)
    report(500, 1000)                      # within the period: not printed
    report(1000, 1000)                     # the end: always printed
    assert said == ["[#####...............] 250/1000 runs", "[####################] 1000/1000 runs"]


def test_bench_ships_script_reports_a_vectorised_esso(capsys):
    """benchmarks/bench_ships.py, run as its own main on a tiny workload."""
    import importlib.util
    import json
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "benchmarks" / "bench_ships.py"
    spec = importlib.util.spec_from_file_location("bench_ships", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    assert mod.main(["--ships", "esso", "--runs", "4", "--duration", "5", "--repeats", "1", "--json"]) == 0
    (row,) = json.loads(capsys.readouterr().out)
    assert row["ship"] == "esso" and row["kernel"] == "esso_rhs"
    assert row["batch_ship_steps_per_s"] > 0 and row["single_steps_per_s"] > 0
    assert row["vectorised_stages"] >= 4 and row["per_run_library_calls"] == []
    assert mod.main(["--ships", "no-such-ship"]) == 2
    assert "unknown ship" in capsys.readouterr().err
