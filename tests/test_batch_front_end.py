"""One batch front end (steerlab.sim.batch): simulate_batch, Monte-Carlo, robustness, the tuner
and the experiments all pack a PackedBatch and get one BatchResult; every guidance kind goes
through it; .metrics is a pandas DataFrame with one row per run.

Compiled runs reuse nomoto1 + pid with LOS guidance (tests/test_guidance.py compiles it too).
"""

from __future__ import annotations

import pickle

import numpy as np
import pytest

from steerlab.guidance.reference_vector import REF_PSI
from steerlab.metrics import integral_metrics
from steerlab.ships.state import IPSI
from steerlab.sim.batch import BatchResult, PackedBatch, simulate_batch
from steerlab.sim.engine import simulate
from steerlab.sim.scenario import scenario_from_dict
from steerlab.sim.setup import build

LOS = {"dt": 0.5, "duration": 120.0, "ship": {"model": "nomoto1", "speed_kn": 10.0},
       "controller": {"type": "pid", "Kp": 3.0, "Ki": 0.0, "Kd": 67.0},
       "environment": {"waves": True, "wave_power": 1e-4},
       "guidance": {"type": "los", "start": [0.0, 100.0], "route": [[0.0, 0.0], [20000.0, 0.0]],
                    "lookahead_L": 5.0}}


@pytest.fixture(scope="module")
def los_setups():
    sc = scenario_from_dict(LOS)
    return [build(sc.replace(seed=s)) for s in (1, 2, 3)]


def test_the_former_packed_names_are_deprecated_aliases_of_the_one_batch():
    from steerlab.sweeps import packed

    with pytest.warns(DeprecationWarning, match="steerlab.sim.batch.PackedBatch"):
        assert packed.PackedBatch is PackedBatch
    with pytest.warns(DeprecationWarning, match="steerlab.sim.batch.BatchResult"):
        assert packed.BatchOutput is BatchResult
    with pytest.raises(AttributeError):
        packed.nothing_here    # noqa: B018


def test_guided_batch_metrics_frame_has_one_row_per_run_and_the_single_runs_numbers(los_setups):
    b = simulate_batch(los_setups, record_every=20)
    df = b.metrics
    assert list(df.index) == [0, 1, 2] and df.index.name == "run"
    for i, s in enumerate(los_setups):
        single = simulate(s)
        assert np.array_equal(b.final_states[i], single.states[-1])        # the same numbers, batched
        assert df["psi_final"].iloc[i] == single.states[-1, IPSI]
        assert df["itae_deg_s2"].iloc[i] == integral_metrics(b.acc[i])["itae_deg_s2"]
        assert np.array_equal(b.ref[i, :, REF_PSI], single.psi_ref[::20])
    assert df.equals(b.to_pandas(0.1)) and not df["speed_loss_J"].equals(b.to_pandas(1.0)["speed_loss_J"])
    assert b.n == 3 and not b.diverged.any()


def test_a_packed_batch_sent_to_another_process_finds_its_kernels_by_name(los_setups):
    """Chunks for dask workers are pickled without the kernels; the copy runs the same numbers."""
    pb = PackedBatch.from_setups(los_setups, "conditions")
    copy = pickle.loads(pickle.dumps(pb.take([2, 0])))
    assert copy.rhs is None and copy.update is None and pb.rhs is not None
    a, b = pb.run(), copy.run()
    assert np.array_equal(b.acc, a.acc[[2, 0]]) and np.array_equal(b.final_states, a.final_states[[2, 0]])
    joined = BatchResult.concatenate([a, b])
    assert joined.n == 5 and joined.state_names == a.state_names == los_setups[0].state_names


def test_montecarlo_and_robustness_of_a_los_scenario_go_through_the_one_batch(los_setups):
    from steerlab.sweeps.montecarlo import run_montecarlo
    from steerlab.sweeps.robustness import parse_vary, run_robustness

    sc = scenario_from_dict({**LOS, "seed": 1})
    mc = run_montecarlo(sc, 3, record_every=20)
    direct = simulate_batch(los_setups)
    assert mc.per_run["itae_deg_s2"].tolist() == [integral_metrics(a)["itae_deg_s2"] for a in direct.acc]
    rb = run_robustness(sc, [parse_vary("ship.speed_kn=9:11:2", sc)], metric="itae")
    nominal = integral_metrics(direct.acc[0])["itae_deg_s2"]
    assert rb.nominal["metric"] == nominal and rb.metric_values.shape == (2,)


def test_montecarlo_of_a_berthing_scenario_goes_through_the_one_batch():
    """Berthing guidance orders the propeller rate into the batch's own copy of PS: the sweep
    gives each seed's single-run numbers."""
    from steerlab.experiments.berthing2019 import PID_PAPER, scenario_dict
    from steerlab.sim.setup import build_seeds
    from steerlab.sweeps.montecarlo import run_montecarlo

    sc = scenario_from_dict(scenario_dict(PID_PAPER, wind=True, duration=25.0))
    mc = run_montecarlo(sc, 2, record_every=10)
    singles = [simulate(s) for s in build_seeds(sc, [sc.seed, sc.seed + 1])]
    assert mc.per_run["iae_deg_s"].tolist() == [integral_metrics(r.meta["online_metrics"])["iae_deg_s"]
                                                for r in singles]
    assert 300.0 in set(np.round(singles[0].meta["guidance_log"]["rpm_cmd"] * 60.0, 9))
