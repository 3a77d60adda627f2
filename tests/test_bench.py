"""Benchmark W1 (steerlab.bench): the result dict and the agreement of its runs.

Small and quick (8 runs, 200 s); no assertion on speed - only on keys and numbers.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from steerlab.bench import (C_REFERENCE_STEPS_PER_S, run_bench, simulate_python, w1_batch_setups,
                            w1_scenario)
from steerlab.sim.batch import simulate_batch
from steerlab.sim.engine import simulate_compiled
from steerlab.sim.setup import build

RATE_KEYS = (
    "single_steps_per_s", "single_steps_per_s_incl_build", "batch_ship_steps_per_s",
    "python_reference_steps_per_s", "speedup_single_vs_python", "speedup_batch_vs_python",
    "ratio_single_vs_c", "ratio_batch_vs_c", "single_run_s", "single_run_s_incl_build", "batch_s",
    "compile_s", "batch_compile_s",
)


@pytest.fixture(scope="module")
def bench():
    messages = []
    res = run_bench(n_batch=8, duration=200.0, repeats=1, progress=messages.append)
    res["_messages"] = messages
    return res


def test_bench_dict_has_keys_with_positive_finite_values(bench):
    for key in RATE_KEYS:
        assert key in bench, key
        assert math.isfinite(bench[key]) and bench[key] > 0.0, (key, bench[key])
    assert bench["n_batch"] == 8
    assert bench["n_steps"] == 2000
    assert bench["cores"] >= 1 and bench["numba_threads"] >= 1 and bench["batch_lanes"] >= 1
    assert bench["batch_vectorisation"]["vectorised_stages"] >= 4       # the Esso's RK4 stages, all
    assert bench["batch_vectorisation"]["per_run_library_calls"] == []
    assert bench["c_reference_steps_per_s"] == C_REFERENCE_STEPS_PER_S == 13.8e6
    assert "not measured" in bench["c_reference_note"]
    assert isinstance(bench["numba_version"], str) and bench["numba_version"]
    assert bench["ratio_single_vs_c"] == pytest.approx(bench["single_steps_per_s"] / 13.8e6)
    assert bench["speedup_batch_vs_python"] == pytest.approx(
        bench["batch_ship_steps_per_s"] / bench["python_reference_steps_per_s"])
    assert bench["_messages"] and bench["_messages"][-1] == "done"


def test_bench_batch_and_single_agree_on_the_unscaled_run(bench):
    assert bench["batch_vs_single_acc_max_abs_diff"] == 0.0
    assert bench["batch_vs_single_final_state_max_abs_diff"] == 0.0
    # and directly, through the public API
    setup = build(w1_scenario(200.0))
    single = simulate_compiled(setup)
    setups = w1_batch_setups(setup, 8)
    np.testing.assert_array_equal(setups[0].pc, setup.pc)
    assert not np.array_equal(setups[1].pc, setup.pc)
    batch = simulate_batch(setups)
    np.testing.assert_array_equal(batch.acc[0], single.meta["online_metrics"])
    np.testing.assert_array_equal(batch.final_states[0], single.states[-1])
    # the other runs really have other gains, so other outcomes
    assert not np.array_equal(batch.final_states[1], single.states[-1])
    # the 20 deg course change at t = 100 s is under way by t = 200 s
    assert math.degrees(single.states[-1, 2]) > 5.0


def test_python_reference_is_the_same_model(bench):
    assert bench["python_reference_max_abs_diff"] <= 1e-12
    setup = build(w1_scenario(30.0))
    py = simulate_python(setup)
    np.testing.assert_array_equal(py.states, simulate_compiled(setup).states)
