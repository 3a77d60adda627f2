"""``steerlab run --record-every / --keep-diverged / --max-memory`` and the resource estimates of
the sweeps (steerlab.resources): refused before allocating, in one line naming the field."""

from __future__ import annotations

import json
import time

import numpy as np
import pytest

from conftest import make_scenario
from steerlab.cli import main
from steerlab.errors import DivergedError, InputError
from steerlab.metrics import compute_metrics
from steerlab.sim.engine import simulate
from steerlab.sim.setup import build

RUN = """name = "short"
seed = 3
dt = {dt}
duration = {duration}
[ship]
model = "esso"
speed_kn = 16.0
[controller]
type = "pid"
{extra}
[guidance]
psi0_deg = 0.0
changes = [{{ t = 20.0, psi_deg = 10.0 }}]
[environment]
waves = true
{env}
"""


def _write(tmp_path, dt=0.1, duration=300.0, extra="", env=""):
    p = tmp_path / "s.toml"
    p.write_text(RUN.format(dt=dt, duration=duration, extra=extra, env=env))
    return p


INTEGRAL = ("iae_deg_s", "ise_deg2_s", "itae_deg_s2", "speed_loss_J", "max_abs_error_deg", "rudder_travel_deg",
            "rudder_reversals", "mean_abs_rudder_deg")


@pytest.mark.parametrize("engine", ["compiled", "readable"])
def test_record_every_thins_the_log_and_keeps_the_integral_metrics(engine):
    setup = build(make_scenario(duration=120.0, environment={"waves": True}))
    full = simulate(setup, engine)
    thin = simulate(setup, engine, record_every=7)
    assert len(thin.time) == 1200 // 7 + 1
    np.testing.assert_array_equal(thin.states, full.states[::7])          # the same samples, bit for bit
    np.testing.assert_array_equal(thin.time, full.time[::7])
    np.testing.assert_array_equal(thin.disturbance, full.disturbance[::7])
    np.testing.assert_array_equal(thin.meta["final_state"], full.states[-1])
    mf, mt = compute_metrics(full), compute_metrics(thin)
    assert {k: mt[k] for k in INTEGRAL} == {k: mf[k] for k in INTEGRAL}   # on-line: every step
    assert mt["max_abs_rudder_deg"] <= mf["max_abs_rudder_deg"]           # from the thinned log


def test_run_record_every_writes_the_thinned_log_and_says_so(tmp_path):
    out = tmp_path / "o"
    assert main(["run", str(_write(tmp_path)), "--out", str(out), "--quiet", "--record-every", "10"]) == 0
    assert len((out / "timeseries.csv").read_text().splitlines()) == 1 + 301
    m = json.loads((out / "metrics.json").read_text())
    assert m["record_every"] == 10 and "every 1 s" in m["note"]


@pytest.mark.parametrize("value", ["0", "-3", "3001"])
def test_record_every_out_of_range(tmp_path, capsys, value):
    assert main(["run", str(_write(tmp_path)), "--out", str(tmp_path / "o"), "--record-every", value]) == 2
    assert "--record-every: must be in [1, 3000]" in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


def test_simulate_refuses_a_bad_record_every():
    with pytest.raises(InputError, match="--record-every"):
        simulate(make_scenario(duration=10.0), record_every=0)


def test_keep_diverged_writes_the_rows_before_the_spin_marked_and_exits_3(tmp_path, capsys):
    """Zero gains and a 35 deg rudder disturbance: the Esso spins (test_input_edges)."""
    p = _write(tmp_path, duration=1500.0, extra="Kp = 0.0\nKi = 0.0\nKd = 0.0",
               env="constant_rudder_deg = 35.0")
    out = tmp_path / "o"
    assert main(["run", str(p), "--out", str(out), "--quiet", "--keep-diverged"]) == 3
    assert "the ship spun" in capsys.readouterr().err
    m = json.loads((out / "metrics.json").read_text())
    assert m["diverged"] is True and m["metrics"] is None
    t_spin = m["divergence"]["time_s"]
    rows = np.loadtxt(out / "timeseries.csv", delimiter=",", skiprows=1)
    assert 0 < t_spin < 1500.0 and rows[-1, 0] == pytest.approx(t_spin) and len(rows) == m["divergence"]["rows"]
    assert np.isfinite(rows).all() and not (out / "report.html").exists()
    assert main(["run", str(p), "--out", str(tmp_path / "o2"), "--quiet"]) == 3       # without: nothing
    assert not (tmp_path / "o2").exists()


def test_finite_head_stops_before_the_first_non_finite_row():
    from steerlab.commands._run_options import finite_head

    res = simulate(make_scenario(duration=20.0))
    res.states[57:, 4] = np.nan
    head = finite_head(res, DivergedError(5.7, "v = nan", ""))
    assert len(head.time) == 57 and np.isfinite(head.states).all() and head.time[-1] == pytest.approx(5.6)


def test_a_nan_between_logged_steps_is_still_caught(tmp_path):
    from steerlab.commands._run_options import check_accumulator

    setup = build(make_scenario(duration=20.0))
    res = simulate(setup, record_every=7)
    check_accumulator(res, setup)
    res.meta["final_state"][2] = np.inf
    with pytest.raises(DivergedError, match="final state"):
        check_accumulator(res, setup)


# ---------------------------------------------------------------- resource estimates


def test_the_largest_accepted_duration_is_refused_by_the_estimate_not_by_numpy(tmp_path, capsys):
    """duration 1e6 s at dt 0.02 s: 50 M steps, the most the design accepts; with a 4 GB limit
    it is one line naming duration with the estimate, at once (nothing allocated)."""
    t0 = time.perf_counter()
    code = main(["run", str(_write(tmp_path, dt=0.02, duration=1e6)), "--out", str(tmp_path / "o"),
                 "--max-memory", "4"])
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert code == 2 and err.startswith("steerlab: error: duration: a run of 50000000 steps")
    assert "needs about 17" in err and "limit of 4 GB" in err
    assert time.perf_counter() - t0 < 120.0 and not (tmp_path / "o").exists()   # a hang guard


def test_environment_limit_and_bad_limits(tmp_path, capsys, monkeypatch):
    monkeypatch.setenv("STEERLAB_MAX_MEMORY", "0.2")
    assert main(["run", str(_write(tmp_path)), "--out", str(tmp_path / "o"), "--quiet"]) == 2
    assert "STEERLAB_MAX_MEMORY" in capsys.readouterr().err
    monkeypatch.setenv("STEERLAB_MAX_MEMORY", "lots")
    assert main(["run", str(_write(tmp_path)), "--out", str(tmp_path / "o"), "--quiet"]) == 2
    assert "STEERLAB_MAX_MEMORY: must be a finite number" in capsys.readouterr().err
    monkeypatch.delenv("STEERLAB_MAX_MEMORY")
    assert main(["run", str(_write(tmp_path)), "--out", str(tmp_path / "o"), "--max-memory", "nan"]) == 2
    assert "--max-memory" in capsys.readouterr().err


def test_record_every_lowers_the_estimate():
    from steerlab.resources import run_bytes

    assert run_bytes(10_000_000, 8, 100) < 0.3 * run_bytes(10_000_000, 8, 1)


def test_a_full_disk_is_refused_before_the_run(tmp_path, capsys, monkeypatch):
    import collections
    import shutil

    usage = collections.namedtuple("usage", "total used free")
    monkeypatch.setattr(shutil, "disk_usage", lambda p: usage(10**9, 10**9 - 1000, 1000))
    assert main(["run", str(_write(tmp_path)), "--out", str(tmp_path / "o"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("steerlab: error: --out: timeseries.csv of 3001 rows needs about") and "GB free" in err


def test_a_grid_typo_is_refused_at_once(tmp_path, capsys):
    """Three 540-value axes: 157 M points. It was built (34 s) and died with MemoryError."""
    t0 = time.perf_counter()
    code = main(["robustness", str(_write(tmp_path)), "--vary", "speed_kn=1:540:1", "--vary",
                 "gear.rate_max_deg_s=1:540:1", "--vary", "gear.T_sg=1:540:1", "--out", str(tmp_path / "o")])
    assert code == 2 and time.perf_counter() - t0 < 120.0   # a hang guard (34 s, then MemoryError, before)
    assert "--vary: 157464000 grid points (540 x 540 x 540); allowed at most 100000" in capsys.readouterr().err


def test_a_grid_of_distinct_seas_over_the_limit_is_refused(tmp_path, capsys):
    code = main(["robustness", str(_write(tmp_path)), "--vary", "environment.wave_power=0:1e-3:1e-5",
                 "--max-memory", "0.26", "--out", str(tmp_path / "o"), "--quiet"])
    err = capsys.readouterr().err
    assert code == 2 and "--vary: a grid of 101 points with 101 distinct sea(s)" in err, err


def test_montecarlo_estimate_names_runs(tmp_path, capsys):
    code = main(["montecarlo", str(_write(tmp_path)), "--runs", "100000", "--record-every", "1",
                 "--max-memory", "2", "--out", str(tmp_path / "o"), "--quiet"])
    err = capsys.readouterr().err
    assert code == 2 and "--runs: 100000 runs of 3000 steps logged every 1 step(s) needs about 10 GB" in err, err


def test_every_command_checks_the_set_up_before_building_it(tmp_path, capsys):
    """50 M steps: the disturbance sequence alone (5.85 GB) is refused before build() allocates
    it; the Monte-Carlo estimate comes first of all (nothing built), each with --max-memory."""
    big = str(_write(tmp_path, dt=0.02, duration=1e6))
    t0 = time.perf_counter()
    assert main(["robustness", big, "--vary", "speed_kn=10:12:1", "--max-memory", "1",
                 "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "duration: the disturbance sequence of 50000000 steps (duration 1e+06 s / dt 0.02 s) needs about 5.85 GB" \
        in err and "limit of 1 GB" in err
    assert main(["montecarlo", big, "--runs", "4", "--max-memory", "7", "--out", str(tmp_path / "o")]) == 2
    assert "--runs: 4 runs of 50000000 steps" in capsys.readouterr().err
    assert time.perf_counter() - t0 < 120.0                                 # a hang guard


def test_tune_estimate_names_seeds(tmp_path, capsys):
    t0 = time.perf_counter()
    code = main(["tune", str(_write(tmp_path)), "--params", "kp", "--bounds", "0.5:5", "--seeds", "500",
                 "--max-memory", "0.3", "--out", str(tmp_path / "o"), "--quiet"])
    err = capsys.readouterr().err
    assert code == 2 and "--seeds: 500 conditions of 3000 steps x a population of 30 needs about" in err, err
    assert time.perf_counter() - t0 < 120.0                                 # a hang guard


def test_a_run_that_never_settles_far_off_its_course_says_what_to_try(tmp_path, capsys):
    """The paper's PID gains (gains = "paper") on the Zeefakkel (thesis Table 2.3) overshoot a 20 deg change to
    126 deg and end 96 deg off: the run still reports (no spin), and stderr says why and what
    designs settings, within the output width; a run that settles gets no such line."""
    from steerlab.commands._run_options import tracking_hint
    from steerlab.text_table import MAX_WIDTH

    toml = ('name = "zeefakkel-pid"\nduration = 600.0\n[ship]\nmodel = "zeefakkel-nomoto-10deg"\nspeed_kn = 12.0\n'
            '[controller]\ntype = "pid"\ngains = "paper"\n[guidance]\npsi0_deg = 0.0\nchanges = [{ t = 10.0, psi_deg = 20.0 }]\n')
    p = tmp_path / "zee.toml"
    p.write_text(toml)
    assert main(["run", str(p), "--out", str(tmp_path / "o")]) == 0
    err = capsys.readouterr().err
    assert "the heading did not settle on its reference (final error -95.6 deg)" in err
    assert "'zeefakkel-nomoto-10deg'" in err and "steerlab tune" in err
    hint = err[err.index("the heading did not settle"):].split("wrote")[0]
    assert max(len(line) for line in err.splitlines() if line.split("] ", 1)[-1] in hint) <= MAX_WIDTH
    assert tracking_hint({"settling_time_1deg_s": 36.5, "final_error_deg": 0.0}, "x") is None      # settled
    assert tracking_hint({"settling_time_1deg_s": None, "final_error_deg": 3.0}, "x") is None       # close
    assert tracking_hint({"settling_time_1deg_s": float("nan"), "final_error_deg": -9.0}, "x")      # far
