"""Monte-Carlo, robustness maps, dask executor and the sweep CLI commands (nomoto1 + pid only)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from steerlab.errors import InputError
from steerlab.metrics import compute_metrics
from steerlab.sim.engine import simulate
from steerlab.sim.scenario import scenario_from_dict
from steerlab.sweeps.montecarlo import run_montecarlo
from steerlab.sim.batch import PackedBatch
from steerlab.sweeps.robustness import parse_vary, run_robustness

SEA = {
    "name": "sea", "seed": 5, "dt": 0.1, "duration": 300.0,
    "ship": {"model": "nomoto1", "speed_kn": 10.0, "options": {"K": 0.1, "T": 50.0}},
    "gear": {"delta_max_deg": 35.0, "rate_max_deg_s": 5.0, "T_sg": 0.5},
    "controller": {"type": "pid", "Kp": 2.0, "Ki": 0.001, "Kd": 30.0},
    "guidance": {"psi0_deg": 0.0, "changes": [{"t": 20.0, "psi_deg": 10.0}]},
    "environment": {"waves": True, "wave_power": 1e-2},
}


def test_montecarlo_ci_shrinks_with_n():
    sc = scenario_from_dict(SEA)
    small = run_montecarlo(sc, 8, record_every=20)
    large = run_montecarlo(sc, 64, record_every=20)
    for k in ("ise_deg2_s", "rudder_travel_deg", "speed_loss_J"):
        w_small = small.stats[k]["ci95_high"] - small.stats[k]["ci95_low"]
        w_large = large.stats[k]["ci95_high"] - large.stats[k]["ci95_low"]
        assert 0 < w_large < 0.6 * w_small, k
        s = large.stats[k]
        assert s["ci95_low"] < s["mean"] < s["ci95_high"] and s["p5"] <= s["p50"] <= s["p95"]
    # the first 8 seeds of the large set are the small set, bit for bit
    assert np.array_equal(large.per_run["ise_deg2_s"][:8], small.per_run["ise_deg2_s"])
    assert list(large.seeds[:3]) == [5, 6, 7]
    # every realisation differs (the sea is random), the bands bracket the median
    assert len(np.unique(small.per_run["ise_deg2_s"])) == 8
    assert np.all(large.error_bands_deg[5] <= large.error_bands_deg[50])
    assert np.all(large.error_bands_deg[50] <= large.error_bands_deg[95])


def test_confidence_interval_is_scipys_student_t_interval_bit_for_bit():
    """The interval's t quantile comes from scipy.special (the command stays clear of
    scipy.stats' import time) and equals scipy.stats.t.ppf's, for every sample size."""
    from scipy import stats

    from steerlab.sweeps.montecarlo import confidence_interval

    rng = np.random.default_rng(3)
    for n in (2, 3, 5, 8, 30, 101, 1000, 5000):
        v = rng.normal(2.0, 0.7, n)
        for level in (0.9, 0.95, 0.99):
            m, lo, hi = confidence_interval(v, level)
            half = stats.t.ppf(0.5 + level / 2.0, n - 1) * np.std(v, ddof=1) / np.sqrt(n)
            assert (m, lo, hi) == (np.mean(v), np.mean(v) - half, np.mean(v) + half)
    assert np.isnan(confidence_interval([1.0, np.nan])[1])          # one finite value: no interval


def test_montecarlo_in_chunks_gives_the_same_numbers(monkeypatch):
    """Chunks of 3 seeds (the last one short) against one chunk: every per-run metric, every
    statistic and every percentile band equal, and the progress runs to the end."""
    from steerlab.sweeps import montecarlo

    sc = scenario_from_dict({**SEA, "duration": 60.0})
    whole = run_montecarlo(sc, 8, record_every=10)
    monkeypatch.setattr(montecarlo, "CHUNK_RUNS", 3)
    said = []
    parts = run_montecarlo(sc, 8, record_every=10, progress=said.append)
    assert np.array_equal(parts.seeds, whole.seeds) and np.array_equal(parts.time, whole.time)
    for k, v in whole.per_run.items():
        np.testing.assert_array_equal(parts.per_run[k], v, err_msg=k)
    assert parts.stats == whole.stats
    for p in whole.error_bands_deg:
        np.testing.assert_array_equal(parts.error_bands_deg[p], whole.error_bands_deg[p])
        np.testing.assert_array_equal(parts.rudder_bands_deg[p], whole.rudder_bands_deg[p])
    assert any("chunks of <= 3 runs" in m for m in said) and said[-1].endswith("8/8 runs")


def test_montecarlo_run_equals_single_run():
    sc = scenario_from_dict(SEA)
    mc = run_montecarlo(sc, 2, record_every=1)
    single = compute_metrics(simulate(sc.replace(seed=6)))
    for k in ("itae_deg_s2", "rudder_travel_deg", "overshoot_deg", "settling_time_1deg_s", "max_abs_rudder_deg"):
        assert mc.per_run[k][1] == single[k], k


def test_robustness_1x1_grid_equals_single_run():
    sc = scenario_from_dict(SEA)
    res = run_robustness(sc, [parse_vary("T=50:50:1", sc), parse_vary("K=0.1:0.1:0.05", sc)], "itae")
    single = compute_metrics(simulate(sc))
    assert len(res.points) == 1
    assert res.metric_values[0] == single["itae_deg_s2"]
    assert res.table["travel"][0] == single["rudder_travel_deg"]
    assert res.nominal["metric"] == single["itae_deg_s2"]


def test_robustness_map_varies_the_plant_only():
    sc = scenario_from_dict(SEA)
    res = run_robustness(sc, [parse_vary("T=30:70:20", sc)], "itae + 0*travel")
    assert list(res.table["T"]) == [30.0, 50.0, 70.0]
    assert res.metric_values[1] == res.nominal["metric"]
    assert len(set(res.metric_values)) == 3
    # a slower ship (larger T) with the same autopilot tracks worse here
    assert res.metric_values[0] < res.metric_values[1] < res.metric_values[2]


def test_robustness_grid_stores_a_sea_once_unless_it_varies(monkeypatch):
    from steerlab.sweeps import robustness

    seen = []
    real = robustness.PackedBatch.from_setups

    def spy(setups):
        seen.append(len({id(s.w) for s in setups}))
        return real(setups)

    monkeypatch.setattr(robustness.PackedBatch, "from_setups", staticmethod(spy))
    sc = scenario_from_dict({**SEA, "duration": 30.0})
    a = run_robustness(sc, [parse_vary("T=30:70:20", sc)], "itae")
    b = run_robustness(sc, [parse_vary("environment.wave_power=0.0001:0.0003:0.0001", sc)], "itae")
    assert seen == [1, 4]             # 3 plants + nominal in one sea; 3 other seas + the nominal (1e-2)
    assert len(set(a.metric_values)) == 3 and len(set(b.metric_values)) == 3


@pytest.mark.parametrize("text, fragment", [
    ("T", "NAME=lo:hi:step"), ("T=1:2", "lo:hi:step"), ("T=2:1:1", "lo <= hi"),
    ("T=1:2:0", "step > 0"), ("Q=1:2:1", "unknown quantity 'Q'"), ("ship.nope=1:2:1", "unknown scenario path"),
])
def test_bad_vary_is_input_error(text, fragment):
    with pytest.raises(InputError) as e:
        parse_vary(text, scenario_from_dict(SEA))
    assert e.value.field == "--vary" and fragment in e.value.message


def test_out_of_range_grid_point_names_it():
    sc = scenario_from_dict(SEA)
    with pytest.raises(InputError) as e:
        run_robustness(sc, [parse_vary("K=-0.1:0.1:0.1", sc)])
    assert e.value.field.startswith("--vary K=-0.1")


def test_dask_and_local_give_identical_numbers():
    distributed = pytest.importorskip("distributed")
    from steerlab.sweeps.conditions import condition_set
    from steerlab.sweeps.executors import DaskExecutor, LocalExecutor
    from steerlab.tuning.cost import parse_cost
    from steerlab.tuning.evaluator import PopulationEvaluator
    from steerlab.tuning.params import build_param_map

    sc = scenario_from_dict({**SEA, "duration": 100.0})
    conds = condition_set(sc, n_seeds=3)
    pm = build_param_map(conds, ["kp", "kd"], np.array([[0.5, 4.0], [5.0, 60.0]]))
    X = np.random.default_rng(0).uniform(pm.bounds[:, 0], pm.bounds[:, 1], size=(5, 2))
    costs = [parse_cost("itae + travel")]
    local = PopulationEvaluator(conds, pm, costs, executor=LocalExecutor()).per_condition_costs(X)
    batch = PackedBatch.from_setups([c.setup for c in conds])
    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False,
                                  protocol="tcp", host="127.0.0.1", dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        ex = DaskExecutor(client, chunk_size=4)
        remote = PopulationEvaluator(conds, pm, costs, executor=ex).per_condition_costs(X)
        a = batch.run(record_every=50)
        seen = []
        b = ex.run(batch, record_every=50, progress=lambda done, n: seen.append((done, n)))
    assert np.array_equal(local, remote)
    assert seen[-1] == (batch.n, batch.n) and [d for d, _ in seen] == sorted(d for d, _ in seen)
    assert np.array_equal(a.acc, b.acc) and np.array_equal(a.states, b.states)


def test_packed_take_keeps_only_used_seas():
    from steerlab.sweeps.conditions import condition_set

    conds = condition_set(scenario_from_dict({**SEA, "duration": 10.0}), n_seeds=4)
    b = PackedBatch.from_setups([c.setup for c in conds]).tile(2)
    part = b.take([1, 5, 3])
    assert part.W.shape[0] == 2 and np.array_equal(part.W[part.w_index], b.W[b.w_index[[1, 5, 3]]])


# ------------------------------------------------------------------ CLI (in process: no recompiling)


def _write(tmp_path, d=SEA):
    lines = [f'name = "{d["name"]}"', f'seed = {d["seed"]}', f'dt = {d["dt"]}', f'duration = {d["duration"]}',
             "[ship]", 'model = "nomoto1"', "speed_kn = 10.0", "options = { K = 0.1, T = 50.0 }",
             "[gear]", "rate_max_deg_s = 5.0", "T_sg = 0.5",
             "[controller]", 'type = "pid"',
             "[guidance]", "changes = [{ t = 20.0, psi_deg = 10.0 }]",
             "[environment]", "waves = true", "wave_power = 0.01"]
    p = tmp_path / "s.toml"
    p.write_text("\n".join(lines) + "\n")
    return p


def test_cli_tune_montecarlo_robustness(tmp_path, capsys):
    from steerlab.cli import main

    s = _write(tmp_path)
    out = tmp_path / "tune"
    assert main(["tune", str(s), "--params", "kp,kd", "--bounds", "0.5:4,5:60", "--cost", "J + overshoot",
                 "--seeds", "2", "--generations", "2", "--pop-size", "6", "--out", str(out), "--quiet"]) == 0
    r = json.loads((out / "result.json").read_text())
    assert set(r["best"]["parameters"]) == {"kp", "kd"} and r["method"] == "de"
    assert (out / "convergence.png").exists() and (out / "history.csv").exists()
    assert r["n_simulations"] == 6 * 3 * 2  # (initial population + 2 generations) x 6 x 2 seeds
    capsys.readouterr()
    assert main(["montecarlo", str(s), "--runs", "3", "--out", str(tmp_path / "mc")]) == 0
    assert "[####################] 3/3 runs" in capsys.readouterr().err     # progress, at the end
    assert (tmp_path / "mc" / "percentile_bands.png").exists()
    mc = json.loads((tmp_path / "mc" / "montecarlo.json").read_text())
    assert mc["metrics"]["itae_deg_s2"]["n"] == 3
    assert main(["robustness", str(s), "--vary", "T=40:60:10", "--vary", "K=0.1:0.2:0.1",
                 "--out", str(tmp_path / "rb"), "--quiet"]) == 0
    assert (tmp_path / "rb" / "heatmap.png").exists()
    assert len(json.loads((tmp_path / "rb" / "robustness.json").read_text())["rows"]) == 6


@pytest.mark.parametrize("argv, field", [
    (["tune", "{s}", "--params", "kp,zz", "--bounds", "0:1,0:1"], "--params"),
    (["tune", "{s}", "--params", "kp", "--bounds", "1:0"], "--bounds"),
    (["tune", "{s}", "--params", "kp", "--bounds", "0:1", "--cost", "itae +* 2"], "--cost"),
    (["tune", "{s}", "--params", "kp", "--bounds", "0:1", "--speeds-kn", "10,x"], "--speeds-kn"),
    (["montecarlo", "{s}", "--runs", "1"], "--runs"),
    (["robustness", "{s}", "--vary", "T=1:2"], "--vary"),
    (["robustness", "{s}", "--vary", "T=40:50:10", "--metric", "overshoot"], "--metric"),
])
def test_cli_bad_input_exit_2_and_nothing_written(tmp_path, capsys, argv, field):
    from steerlab.cli import main

    s = _write(tmp_path)
    out = tmp_path / "out"
    argv = [a.replace("{s}", str(s)) for a in argv] + ["--out", str(out), "--quiet"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"error: {field}" in err
    assert not out.exists()


def test_condition_set_is_the_product_of_variants_speeds_seas_and_seeds(tmp_path):
    from steerlab.sweeps.conditions import condition_set, load_variants

    f = tmp_path / "loading.toml"
    f.write_text('[[condition]]\nlabel = "ballast"\nship = { options = { K = 0.12, T = 40.0 } }\n'
                 '[[condition]]\nlabel = "full"\nship = { options = { K = 0.08, T = 70.0 } }\n')
    conds = condition_set(scenario_from_dict({**SEA, "duration": 10.0}), n_seeds=2, speeds_kn=(8.0, 12.0),
                          wave_powers=(0.0, 1e-3), variants=load_variants(f))
    assert len(conds) == 2 * 2 * 2 * 2
    c = conds[-1]
    assert c.label == "full, 12 kn, waves 0.001, seed 6"
    assert c.scenario.ship.options == {"K": 0.08, "T": 70.0} and c.scenario.ship.speed_kn == 12.0
    assert c.setup.ps[1] == 70.0 and c.scenario.environment.waves
    assert not conds[0].scenario.environment.waves
    bad = tmp_path / "bad.toml"
    bad.write_text('[[condition]]\nship = { options = { K = -1.0 } }\n')
    with pytest.raises(InputError) as e:
        condition_set(scenario_from_dict(SEA), variants=load_variants(bad))
    assert e.value.field == "ship.options.K"
    bad.write_text("x = 1\n")
    with pytest.raises(InputError) as e:
        load_variants(bad)
    assert e.value.field == "--conditions"
