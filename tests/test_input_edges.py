"""Hardened input and honest runs (issue 15): bounds, refusals, warnings, the design guard,
divergence and spin checks, diverged batch runs, tuning and identification warnings."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

from conftest import make_scenario, make_scenario_dict
from steerlab.cli import MAX_MESSAGE, main, one_line
from steerlab.errors import DivergedError, InputError
from steerlab.sim.scenario import load_scenario, scenario_from_dict
from steerlab.sim.setup import build

KOSOKO_10KN = """
name = "kosoko-fast"
dt = 0.5
duration = 30.0
[ship]
model = "kosoko"
speed_kn = 10.0
[controller]
type = "pid"
gains = "paper"
[guidance]
changes = [{ t = 2.0, psi_deg = 20.0 }]
"""


def _write(tmp_path, text, name="s.toml"):
    p = tmp_path / name
    p.write_text(text)
    return p


# ---------------------------------------------------------------- bounds of the schema


@pytest.mark.parametrize("over, field", [
    (dict(dt=5e-324), "dt"),
    (dict(dt=1e-5), "dt"),
    (dict(gear={"T_sg": 1e-300}), "gear.T_sg"),
    (dict(controller={"type": "adrc", "T_settle": 1e-300}), "controller.T_settle"),
    (dict(controller={"type": "itae_pid", "t_r": 1e-300}), "controller.t_r"),
    (dict(controller={"type": "gain_shaping_pid", "T01": 5e-324}), "controller.T01"),
    (dict(controller={"type": "sliding_mode", "design_T2": 1e-300}), "controller.design_T2"),
    (dict(controller={"type": "nonlinear_adrc", "delta2": 1e-300}), "controller.delta2"),
    (dict(ship={"model": "esso", "speed_kn": 5e-324}), "ship.speed_kn"),
])
def test_physical_lower_bounds_name_the_field(over, field):
    """Each crashed in the design (ZeroDivisionError, OverflowError, LinAlgError) before."""
    with pytest.raises(InputError) as e:
        build(make_scenario(**over))
    assert e.value.field == field
    assert "greater than or equal" in e.value.message


def test_sliding_mode_on_a_tiny_gear_time_constant_is_an_input_error():
    """T_sg = 1e-300 gave LinAlgError in the sliding-mode design; now refused by the schema,
    and a pole placement that still fails names controller.poles."""
    s = make_scenario_dict(ship={"model": "b481", "speed_kn": 14.0}, controller={"type": "sliding_mode"},
                           gear={"T_sg": 1e-300})
    with pytest.raises(InputError, match="gear.T_sg"):
        build(scenario_from_dict(s))
    from steerlab.control.sliding_mode import sliding_surface_design

    A = np.zeros((4, 4))
    with pytest.raises(InputError, match="controller.poles: pole placement failed"):
        sliding_surface_design(A, np.zeros(4), (-0.1, -0.2, -0.3))


# ---------------------------------------------------------------- files


def test_invalid_utf8_names_the_byte(tmp_path):
    p = tmp_path / "s.toml"
    p.write_bytes(b'name = "ok"\n# caf\xe9\n')
    with pytest.raises(InputError, match=r"s.toml: not valid UTF-8 at byte 17 \(line 2\)"):
        load_scenario(p)


def test_nul_and_directories_and_fifos_are_refused_at_once(tmp_path):
    import os

    p = tmp_path / "s.toml"
    p.write_bytes(b'name = "a\x00"\n')
    with pytest.raises(InputError, match="binary file"):
        load_scenario(p)
    with pytest.raises(InputError, match="is a directory"):
        load_scenario(tmp_path)
    fifo = tmp_path / "fifo.toml"
    os.mkfifo(fifo)
    with pytest.raises(InputError, match="not a regular file"):   # reading it would hang
        load_scenario(fifo)


def test_nesting_is_bounded_before_parsing(tmp_path):
    p = _write(tmp_path, "x = " + "{a = " * 40 + "1" + "}" * 40 + "\n")
    with pytest.raises(InputError, match="nesting deeper than 32 levels at line 1"):
        load_scenario(p)
    # strings, comments and numbers with dots do not count
    ok = _write(tmp_path, 'name = "[[[[{{{{a.b.c.d"  # [[[[ a.b.c\n' + "dt = 0.1\n", "ok.toml")
    assert load_scenario(ok).name == "[[[[{{{{a.b.c.d"


def test_route_file_with_invalid_utf8_names_the_field(tmp_path):
    (tmp_path / "r.csv").write_bytes(b"0,0\n100,\xff\n")
    p = _write(tmp_path, '[guidance]\ntype = "los"\nroute_file = "r.csv"\n')
    with pytest.raises(InputError, match=r"guidance.route_file: r.csv: not valid UTF-8 at byte 8 \(line 2\)"):
        build(load_scenario(p))


# ---------------------------------------------------------------- refusals and warnings


def test_course_change_after_the_end_is_refused(tmp_path, capsys):
    p = _write(tmp_path, 'duration = 100.0\n[guidance]\nchanges = [{ t = 50.0, psi_deg = 5.0 }, '
                         '{ t = 150.0, psi_deg = 10.0 }]\n')
    assert main(["run", str(p), "--out", str(tmp_path / "o"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("steerlab: error: guidance.changes[1].t: 150 s is after the end of the run")
    assert not (tmp_path / "o").exists()


def test_warnings_for_speed_range_and_radians():
    from steerlab.sim.sanity import scenario_warnings

    assert scenario_warnings(make_scenario()) == []
    w = scenario_warnings(make_scenario(ship={"model": "kosoko", "speed_kn": 10.0},
                                        gear={"delta_max_deg": 0.61, "rate_max_deg_s": 0.04}))
    assert w[0].startswith("ship.speed_kn: 10 kn is outside the validity range of 'kosoko' (0.0972-2.92 kn)")
    assert w[1].startswith("gear.delta_max_deg: a rudder limit of 0.61 deg is below 2 deg; did you type radians?")
    assert w[2].startswith("gear.rate_max_deg_s: a rudder rate of 0.04 deg/s")
    w = scenario_warnings(make_scenario(controller={"type": "pid", "u_max_deg": 0.5}))
    assert w == [w[0]] and w[0].startswith("controller.u_max_deg")


def test_design_guard_turns_an_unexpected_exception_into_one_line(tmp_path, capsys, monkeypatch):
    """The last-resort net: an exception the bounds missed, in the design, is exit 2 naming the stage."""
    import steerlab.sim.setup as setup_mod

    def broken(scenario):
        raise ZeroDivisionError("float division by zero")

    monkeypatch.setattr(setup_mod, "build", broken)     # the design (called by the guarded preflight)
    p = _write(tmp_path, '[controller]\ntype = "pid"\n')
    assert main(["run", str(p), "--out", str(tmp_path / "o"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("steerlab: error: scenario design: failed with ZeroDivisionError: float division by zero")
    assert len(err.splitlines()) == 1 and not (tmp_path / "o").exists()


def test_messages_are_one_printable_bounded_line():
    s = one_line("bad \x1b[31mred\x1b[0m\nsecond line " + "x" * 1000)
    assert "\x1b" not in s and "\n" not in s and len(s) == MAX_MESSAGE and s.endswith("...")
    assert "\\x1b[31m" in s and "\\n" in s


def test_unknown_ship_message_is_short_and_names_the_field(tmp_path, capsys):
    p = _write(tmp_path, "[ship]\nmodel = \"" + "z" * 100_000 + "\"\n")
    assert main(["run", str(p), "--out", str(tmp_path / "o"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("steerlab: error: ship.model: unknown ship 'zzz")
    assert len(err.splitlines()) == 1 and len(err) <= len("steerlab: error: ") + MAX_MESSAGE + 1


# ---------------------------------------------------------------- runs that lie


def test_check_run_names_the_first_non_finite_sample():
    from steerlab.sim.divergence import check_run
    from steerlab.sim.engine import simulate

    setup = build(make_scenario(duration=20.0))
    res = simulate(setup, engine="compiled")
    check_run(res, setup)                         # a good run passes
    res.states[57:, 4] = np.nan                  # v from t = 5.7 s
    with pytest.raises(DivergedError) as e:
        check_run(res, setup)
    assert e.value.time == pytest.approx(5.7) and e.value.what.startswith("v = nan")
    assert "dt = 0.1 s may be too large" in e.value.hint


def test_a_spinning_ship_is_not_reported_as_good(tmp_path, capsys):
    """Zero gains and a 35 deg rudder disturbance: the Esso turns full circles; the heading error
    wraps, so the metrics looked bounded. Now exit 3 and no output."""
    p = _write(tmp_path, 'duration = 1500.0\n[controller]\ntype = "pid"\nKp = 0.0\nKi = 0.0\nKd = 0.0\n'
                         '[environment]\nconstant_rudder_deg = 35.0\n')
    assert main(["run", str(p), "--out", str(tmp_path / "o"), "--quiet"]) == 3
    err = capsys.readouterr().err
    assert "the ship spun" in err and len(err.splitlines()) == 1
    assert not (tmp_path / "o").exists()


def test_a_python_result_says_whether_it_can_be_reported(tmp_path):
    """``Result.divergence()``: the CLI's check for users of the Python API (``simulate`` returns
    such runs as they are): None for a good run; the spin, with the time it began; the first
    non-finite sample."""
    from steerlab.sim.engine import simulate

    good = simulate(build(make_scenario(duration=20.0)))
    assert good.divergence() is None
    p = _write(tmp_path, 'duration = 1500.0\n[controller]\ntype = "pid"\nKp = 0.0\nKi = 0.0\nKd = 0.0\n'
                         '[environment]\nconstant_rudder_deg = 35.0\n')
    from steerlab.sim.scenario import load_scenario

    spun = simulate(load_scenario(p)).divergence()
    assert isinstance(spun, DivergedError) and "the ship spun" in spun.what and 0.0 < spun.time < 1500.0
    good.states[57:, 4] = np.nan
    bad = good.divergence()
    assert bad.time == pytest.approx(5.7) and bad.what.startswith("v = nan") and "validity range" in bad.hint


@pytest.mark.parametrize("toml, line", [
    ("duration = nan\n", "duration: Input should be a finite number (allowed: gt 0.0, le 1000000.0)"),
    ("[ship]\nspeed_kn = inf\n", "ship.speed_kn: Input should be a finite number (allowed: ge 0.01, le 40.0)"),
    ("[gear]\nT_sg = -inf\n", "gear.T_sg: Input should be a finite number (allowed: ge 0.001, le 100.0)"),
    ("[guidance]\nchanges = [{ t = 10.0, psi_deg = nan }]\n",
     "guidance.changes.0.psi_deg: Input should be a finite number (allowed: ge -360.0, le 360.0)"),
    ('[controller]\ntype = "pid"\nKp = nan\n',
     "controller.Kp: Input should be a finite number (allowed: ge 0.0, le 10000.0)"),
], ids=["duration", "speed", "gear", "guidance-list", "controller"])
def test_a_nan_or_inf_names_the_fields_allowed_range(toml, line):
    """pydantic refuses NaN and inf before it compares with the bounds, so its message gave none;
    the line now names the range declared on the field (nested tables, lists, the controller's
    own config)."""
    with pytest.raises(InputError) as e:
        scenario_from_dict(__import__("tomllib").loads(toml))
    assert str(e.value) == line


@pytest.mark.parametrize("text", ["", "# only a comment\n\n"], ids=["empty", "comments-only"])
def test_a_scenario_file_that_sets_nothing_is_refused(tmp_path, capsys, text):
    """An empty file ran a 3000 s run of the built-in defaults with every metric 0, silently."""
    p = _write(tmp_path, text)
    assert main(["run", str(p), "--out", str(tmp_path / "o"), "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("steerlab: error: scenario: s.toml sets nothing") and len(err.splitlines()) == 1
    assert not (tmp_path / "o").exists()


def test_a_spin_before_an_overflow_is_reported_as_the_spin():
    """An open-loop course-unstable ship (Nomoto K 0.1 1/s, T -5 s, zero gains) spins from
    about t = 50 s and its state overflows minutes later: the report names the spin and when it
    began (the cause), and says when the state left the finite numbers; it blamed the step."""
    from steerlab.sim.divergence import divergence
    from steerlab.sim.engine import simulate

    setup = build(scenario_from_dict({
        "dt": 0.1, "duration": 600.0, "ship": {"model": "nomoto1", "speed_kn": 12.0, "options": {"K": 0.1, "T": -5.0}},
        "controller": {"type": "pid", "Kp": 0.0, "Kd": 0.0, "Ki": 0.0},
        "guidance": {"psi0_deg": 0.0, "changes": [{"t": 50.0, "psi_deg": 20.0}]}, "environment": {"waves": True}}))
    res = simulate(setup)
    assert not np.isfinite(res.states).all()          # the case: it does overflow, later
    err = divergence(res, setup)
    assert "the ship spun" in err.what and err.time < 120.0
    assert "left the finite numbers at t = " in err.what and "controller does not suit" in err.hint
    first_bad = res.time[np.argmax(~np.isfinite(res.states).all(axis=1))]
    assert first_bad > err.time + 60.0


def test_kosoko_at_10_kn_diverges_and_says_so(tmp_path):
    """The issue's case: catalogued 0.1-2.9 kn, run at 10 kn with dt 0.5 s; it exited 0 with metrics."""
    out = tmp_path / "o"
    proc = subprocess.run([sys.executable, "-m", "steerlab", "run", str(_write(tmp_path, KOSOKO_10KN)),
                           "--out", str(out), "--quiet"], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 3, proc.stderr
    lines = proc.stderr.splitlines()
    assert lines[0].startswith("steerlab: warning: ship.speed_kn: 10 kn is outside the validity range")
    assert lines[1].startswith("steerlab: error: the run diverged at t = ")
    assert "outside the validity range of 'kosoko'" in lines[1] and "dt = 0.5 s" in lines[1]
    assert len(lines) == 2 and proc.stdout == "" and not out.exists()


def test_batch_flags_diverged_runs():
    from steerlab.sim.batch import BatchResult

    fs = np.array([[0.0, 1.0], [np.nan, 1.0], [0.0, 1.0]])
    acc = np.array([[1.0], [1.0], [np.inf]])
    assert BatchResult(acc, fs).diverged.tolist() == [False, True, True]
    br = BatchResult(acc, fs, np.zeros(1), np.zeros((3, 1, 2)), np.zeros((3, 1)), np.zeros((3, 1, 2)), ("a", "b"))
    assert br.diverged.tolist() == [False, True, True]


def test_population_evaluator_gives_diverged_runs_the_penalty():
    from steerlab.tuning import evaluator as ev_mod

    ev = ev_mod.PopulationEvaluator.__new__(ev_mod.PopulationEvaluator)

    def fake_metrics(X):
        ev.last_diverged = np.array([[False, True]])
        return {"itae": np.array([[1.0, 2.0]])}

    ev.metrics = fake_metrics
    ev.costs = [lambda m: m["itae"]]
    ev.aggregate = "mean"
    pc = ev.per_condition_costs(np.zeros((1, 1)))
    assert pc[0, 0, 0] == 1.0 and pc[0, 0, 1] == ev_mod.PENALTY
    assert ev(np.zeros((1, 1)))[0, 0] == pytest.approx(0.5 * (1.0 + ev_mod.PENALTY))


def test_tuning_warns_of_an_optimum_on_its_bound():
    from types import SimpleNamespace

    from steerlab.tuning.session import tuning_warnings

    pm = SimpleNamespace(names=["kp", "kd"], bounds=np.array([[0.5, 10.0], [5.0, 100.0]]))
    r = SimpleNamespace(x=np.array([10.0, 40.0]), f=np.array([3.0]), front_x=None)
    w = tuning_warnings(pm, r)
    assert len(w) == 1 and w[0].startswith("kp: the optimum 10 is on its upper bound 10")
    r = SimpleNamespace(x=np.array([0.5001, 40.0]), f=np.array([1e12]), front_x=None)
    w = tuning_warnings(pm, r)
    assert w[0].startswith("kp: the optimum 0.5001 is on its lower bound") and "every candidate failed" in w[1]


def test_identify_marks_a_bad_fit_and_poorly_determined_parameters(tmp_path, capsys):
    """A heading unrelated to the rudder: before, K and T came with intervals as if they meant something."""
    from steerlab.identification.record import make_record, write_record

    rng = np.random.default_rng(1)
    t = np.arange(0.0, 400.0, 1.0)
    delta = np.radians(10.0) * np.sign(np.sin(2 * np.pi * t / 120.0))
    psi = np.cumsum(rng.normal(0.0, np.radians(2.0), t.size))
    rec = make_record(t, delta, psi, np.gradient(psi, t))
    p = tmp_path / "rec.csv"
    write_record(p, rec)
    assert main(["identify", str(p), "--model", "nomoto1", "--json"]) == 0
    cap = capsys.readouterr()
    s = json.loads(cap.out)
    assert s["quality"]["fit"] == "bad" and s["quality"]["nrmse"] > 0.3
    assert set(s["quality"]["poorly_determined"]) == {"K", "T"}
    assert all(p["poorly_determined"] for p in s["parameters"])
    assert "BAD FIT" in cap.err and "poorly determined" in cap.err


def test_montecarlo_leaves_diverged_runs_out_and_flags_them():
    """A fake executor returns one diverged run of three: its metrics are NaN, the others count."""
    from steerlab.metrics_online import N_ACC
    from steerlab.sweeps.montecarlo import run_montecarlo
    from steerlab.sim.batch import BatchResult

    class Fake:
        def run(self, batch, record_every, progress=None):
            n, nx = batch.X.shape
            n_rec = batch.n_steps // record_every + 1
            acc = np.ones((n, N_ACC))
            fs = np.zeros((n, nx))
            fs[1, 4] = np.nan
            states = np.zeros((n, n_rec, nx))
            return BatchResult(acc, fs, np.arange(n_rec) * record_every * batch.dt, states,
                               np.zeros((n, n_rec)), np.zeros((n, n_rec, 2)))

    res = run_montecarlo(make_scenario(duration=50.0), 3, record_every=10, executor=Fake())
    assert res.diverged.tolist() == [False, True, False] and res.n_diverged == 1
    assert np.isnan(res.per_run["iae_deg_s"][1]) and np.isfinite(res.per_run["iae_deg_s"][[0, 2]]).all()
    assert res.stats["iae_deg_s"]["n"] == 2 and res.stats["iae_deg_s"]["n_undefined"] == 1


def test_a_bad_runs_count_is_the_only_line_not_after_a_design_warning(tmp_path, capsys):
    """``montecarlo --runs -5`` on a scenario whose design warns (ADRC without the wave filter in
    a sea): the option's error alone, before any set-up; it came after the design's warning."""
    p = _write(tmp_path, '[controller]\ntype = "adrc"\n[environment.wave]\nmodel = "spectrum"\n'
                         'spectrum = "jonswap"\nsea_state = 5\n')
    assert main(["run", str(p), "--out", str(tmp_path / "r"), "--quiet"]) == 0
    assert "chases the wave yaw" in capsys.readouterr().err      # the case: its design does warn
    assert main(["montecarlo", str(p), "--runs", "-5", "--out", str(tmp_path / "o")]) == 2
    assert capsys.readouterr().err.strip() == "steerlab: error: --runs: must be in [2, 100000], got -5"
    assert not (tmp_path / "o").exists()
