"""Manoeuvring trials: closed forms on nomoto1, symmetry, stability verdicts, IMO limits, CLI.

Compiled trial loops: nomoto1 and esso (one each per process); everything else reuses them.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys

import numpy as np
import pytest

from steerlab.cli import main
from steerlab.errors import InputError
from steerlab.trials.imo_criteria import first_overshoot_10_limit_deg, second_overshoot_10_limit_deg
from steerlab.trials.program import TrialProgramConfig
from steerlab.trials.pullout import run_pullout
from steerlab.trials.runner import TrialConditions, run_program, trial_setup
from steerlab.ships.registry import get_ship
from steerlab.trials.spiral import loop_from_reversed, run_spiral
from steerlab.trials.turning import run_turning
from steerlab.trials.zigzag import reversal_times, run_zigzag
from steerlab.units import KNOT, deg, rad

N1 = TrialConditions("nomoto1", speed_kn=10.0, options={"K": 0.08, "T": 40.0, "L": 80.0})


# ------------------------------------------------------------------ IMO limits (eq 32)

def test_imo_limits_published_values():
    assert first_overshoot_10_limit_deg(5.0) == 10.0
    assert second_overshoot_10_limit_deg(5.0) == 25.0
    assert first_overshoot_10_limit_deg(20.0) == pytest.approx(15.0)      # 5 + 20/2
    assert second_overshoot_10_limit_deg(20.0) == pytest.approx(32.5)     # 17.5 + 0.75*20
    assert first_overshoot_10_limit_deg(45.0) == 20.0
    assert second_overshoot_10_limit_deg(45.0) == 40.0


@pytest.mark.parametrize("f", [first_overshoot_10_limit_deg, second_overshoot_10_limit_deg])
@pytest.mark.parametrize("edge", [10.0, 30.0])
def test_imo_limits_continuous_at_10_and_30_s(f, edge):
    eps = 1e-9
    assert f(edge - eps) == pytest.approx(f(edge), abs=1e-6)
    assert f(edge + eps) == pytest.approx(f(edge), abs=1e-6)
    xs = np.linspace(0.0, 60.0, 6001)
    assert np.max(np.abs(np.diff([f(x) for x in xs]))) < 0.01   # no jump anywhere


def test_imo_limit_rejects_bad_L_over_V():
    with pytest.raises(ValueError):
        first_overshoot_10_limit_deg(float("nan"))


# ------------------------------------------------------------------ turning circle

@pytest.mark.parametrize("gear", [True, False])
def test_turning_nomoto1_closed_forms(gear):
    """First-order Nomoto at constant speed: r = K delta, D = 2 U / (K delta)."""
    cond = TrialConditions("nomoto1", speed_kn=10.0, options={"K": 0.08, "T": 40.0, "L": 80.0}, gear=gear)
    m = run_turning(cond, rudder_deg=15.0).metrics
    K, U, d = 0.08, 10.0 * KNOT, rad(15.0)
    assert m["steady"]
    assert m["steady_rate_of_turn_deg_s"] == pytest.approx(deg(K * d), rel=1e-3)
    assert m["steady_diameter_m"] == pytest.approx(2.0 * U / (K * d), rel=1e-3)
    assert m["steady_diameter_fit_m"] == pytest.approx(2.0 * U / (K * d), rel=2e-3)
    assert m["speed_ratio"] == pytest.approx(1.0)
    assert m["steady_diameter_L"] == pytest.approx(m["steady_diameter_m"] / 80.0)
    # geometry of any turn: the tactical diameter exceeds the transfer; the lag of the yaw
    # response (T, and the gear) pushes the circle forward: advance > steady radius
    assert m["tactical_diameter_m"] > m["transfer_m"] > 0.0
    assert m["advance_m"] > 0.5 * m["steady_diameter_m"]
    assert m["imo"] == []      # IMO turning criteria apply to the maximum rudder only


def test_turning_gear_delays_the_turn():
    slow = run_turning(N1, rudder_deg=15.0).metrics
    fast = run_turning(TrialConditions(**{**N1.__dict__, "gear": False}), rudder_deg=15.0).metrics
    assert slow["advance_m"] > fast["advance_m"]
    assert slow["time_to_90deg_s"] > fast["time_to_90deg_s"]


def test_turning_port_mirrors_starboard_on_esso():
    cond = TrialConditions("esso")
    s = run_turning(cond, 35.0).metrics
    p = run_turning(cond, 35.0, port=True).metrics
    for k in ("advance_m", "transfer_m", "tactical_diameter_m", "steady_diameter_m", "steady_speed_m_s",
              "steady_rate_of_turn_deg_s"):
        assert p[k] == pytest.approx(s[k], rel=1e-9), k
    assert s["direction"] == "starboard" and p["direction"] == "port"
    assert s["steady"] and 0.0 < s["speed_ratio"] < 1.0    # the Esso loses speed in the turn
    assert [c["pass"] for c in s["imo"]] == [True, True]


# ------------------------------------------------------------------ zig-zag

def test_zigzag_reverses_at_the_heading_threshold():
    tr = run_zigzag(N1, 10.0, 10.0)
    res = tr.result
    e = deg(np.unwrap(res.psi) - res.psi[0])
    de = np.max(np.abs(np.diff(e)))
    for k, t in enumerate(reversal_times(res.time, res.delta_cmd, tr.t0)):
        i = int(np.searchsorted(res.time, t))
        side = 1.0 if k % 2 == 0 else -1.0
        assert side * e[i] >= 10.0 - 1e-9
        assert side * e[i] <= 10.0 + de + 1e-9
    m = tr.metrics
    assert m["complete"] and len(m["overshoot_angles_deg"]) >= 3
    assert m["period_s"] == pytest.approx(m["execute_times_s"][3] - m["execute_times_s"][1])
    assert all(o > 0.0 for o in m["overshoot_angles_deg"])


def test_zigzag_port_first_mirrors_starboard_first():
    s = run_zigzag(N1, 20.0, 20.0).metrics
    p = run_zigzag(N1, 20.0, 20.0, port_first=True).metrics
    assert p["overshoot_angles_deg"][:3] == pytest.approx(s["overshoot_angles_deg"][:3], rel=1e-9)
    assert [c["criterion"] for c in s["imo"]] == ["20/20 first overshoot"]


def test_zigzag_overshoot_grows_with_T():
    over = []
    for T in (20.0, 40.0, 80.0):
        cond = TrialConditions("nomoto1", speed_kn=10.0, options={"K": 0.08, "T": T, "L": 80.0})
        m = run_zigzag(cond, 10.0, 10.0).metrics
        over.append((m["first_overshoot_deg"], m["second_overshoot_deg"]))
    assert over[0][0] < over[1][0] < over[2][0]
    assert over[0][1] < over[1][1] < over[2][1]


def test_zigzag_10_10_has_the_imo_rows_with_eq32_limits():
    m = run_zigzag(N1, 10.0, 10.0).metrics
    rows = {c["criterion"]: c for c in m["imo"]}
    L_over_V = 80.0 / (10.0 * KNOT)
    assert rows["10/10 first overshoot"]["limit"] == pytest.approx(first_overshoot_10_limit_deg(L_over_V))
    assert rows["10/10 second overshoot"]["value"] == pytest.approx(m["second_overshoot_deg"])
    d = rows["initial turning: distance to 10 deg heading change"]
    assert d["value"] == pytest.approx(m["time_to_second_execute_s"] * 10.0 * KNOT / 80.0, rel=1e-3)


# ------------------------------------------------------------------ spiral and pull-out

def test_spiral_nomoto1_is_stable_with_slope_1_over_K():
    m = run_spiral(N1, max_rudder_deg=10.0, step_deg=5.0, n_rates=9, hold_s=400.0).metrics
    assert m["course_stable"] and m["verdict"] == "course-stable"
    assert m["slope_at_zero_deg_per_deg_s"] == pytest.approx(1.0 / 0.08, rel=1e-3)
    assert m["loop_width_deg"] == 0.0 and m["loop_height_deg_s"] == 0.0
    for p in m["direct"]:
        assert p["rate_deg_s"] == pytest.approx(0.08 * p["rudder_deg"], abs=1e-4)


def test_esso_spiral_is_unstable_with_a_loop_that_the_pullout_confirms():
    sp = run_spiral(TrialConditions("esso"), max_rudder_deg=10.0, step_deg=2.0, n_rates=21).metrics
    assert sp["verdict"] == "course-unstable" and not sp["course_stable"]
    assert sp["slope_at_zero_deg_per_deg_s"] < 0.0
    assert 0.1 < sp["loop_width_deg"] < 4.0
    assert sp["loop_height_deg_s"] > 0.0
    lo, hi = sp["loop_width_direct_bounds_deg"]
    assert lo <= sp["loop_width_deg"] <= hi
    # direct spiral: at zero rudder the two branches turn opposite ways (hysteresis)
    zero = {p["branch"]: p["rate_deg_s"] for p in sp["direct"] if p["rudder_deg"] == 0.0}
    assert zero["down"] > 0.0 > zero["up"]
    po = run_pullout(TrialConditions("esso"), 20.0).metrics
    assert po["verdict"] == "course-unstable"
    assert po["loop_height_deg_s"] == pytest.approx(sp["loop_height_deg_s"], rel=0.05)
    assert po["starboard"]["residual_rate_deg_s"] == pytest.approx(zero["down"], rel=0.05)


def test_loop_from_reversed_on_a_cubic():
    r = np.linspace(-1.0, 1.0, 2001)
    d = -r + r**3                            # extrema at r = +-1/sqrt(3)
    width, lo, hi = loop_from_reversed(r, d)
    rs = 1.0 / math.sqrt(3.0)
    assert width == pytest.approx(2.0 * (rs - rs**3), rel=1e-5)
    assert (lo, hi) == pytest.approx((-rs, rs), abs=1e-3)
    assert loop_from_reversed(r, r + r**3)[0] == 0.0


def test_pullout_nomoto1_decays_to_zero():
    m = run_pullout(N1, 20.0).metrics
    assert m["verdict"] == "course-stable" and m["loop_height_deg_s"] == 0.0
    assert m["starboard"]["steady_rate_before_deg_s"] == pytest.approx(deg(0.08 * rad(20.0)), rel=1e-3)


def test_diverging_model_is_an_input_error():
    with pytest.raises(InputError, match="diverges"):
        run_pullout(TrialConditions("nomoto1", options={"T": -50.0}), 20.0)


# ------------------------------------------------------------------ engines

def test_program_compiled_equals_readable():
    prog = TrialProgramConfig(kind="zigzag", t0=5.0, rudder_deg=10.0, heading_deg=5.0)
    a = run_program(N1, prog, 150.0, engine="compiled")
    b = run_program(N1, prog, 150.0, engine="readable")
    np.testing.assert_array_equal(a.states, b.states)
    np.testing.assert_array_equal(a.delta_cmd, b.delta_cmd)
    assert len(reversal_times(a.time, a.delta_cmd, 5.0)) >= 1


def test_no_gear_rudder_follows_the_order_within_three_steps():
    prog = TrialProgramConfig(kind="schedule", times=(1.0,), values=(20.0,))
    res = run_program(TrialConditions(**{**N1.__dict__, "gear": False}), prog, 3.0)
    k = int(round(1.0 / N1.dt))
    assert res.delta[k + 3] == pytest.approx(rad(20.0), rel=0.03)
    setup = trial_setup(N1, prog, 3.0)
    assert setup.controller.name == "trial-program" and setup.nc == 1


# ------------------------------------------------------------------ CLI

def test_cli_trial_zigzag_json(capsys):
    rc = main(["trial", "zigzag", "--ship", "nomoto1", "--ship-option", "K=0.08", "--ship-option", "T=40",
               "--ship-option", "L=80", "--speed-kn", "10", "--rudder", "20", "--heading", "20", "--json",
               "--quiet"])
    assert rc == 0
    m = json.loads(capsys.readouterr().out)
    assert m["rudder_deg"] == 20.0 and m["heading_deg"] == 20.0
    assert m["first_overshoot_deg"] > 0.0 and m["period_s"] > 0.0
    assert m["conditions"]["ship_options"] == {"K": 0.08, "T": 40, "L": 80}


def test_cli_imo_writes_self_contained_report(tmp_path, capsys):
    out = tmp_path / "imo"
    rc = main(["imo", "--ship", "nomoto1", "--ship-option", "K=0.08", "--ship-option", "T=40",
               "--ship-option", "L=80", "--speed-kn", "10", "--out", str(out), "--quiet"])
    assert rc == 0
    rep = json.loads((out / "imo.json").read_text())
    assert rep["overall_pass"] in (True, False)
    crit = {(c["trial"], c["criterion"]) for c in rep["criteria"]}
    assert ("zig-zag 10/10 starboard", "10/10 second overshoot") in crit
    assert ("turning 35 deg port", "turning: tactical diameter") in crit
    html = (out / "report.html").read_text()
    assert html.count("data:image/png;base64,") >= 8 and "<script" not in html
    assert "PASS" in capsys.readouterr().out or "FAIL" in html


@pytest.mark.parametrize("argv,field", [
    (["trial", "zigzag", "--ship", "nosuchship"], "steerlab: error: --ship: unknown ship 'nosuchship'"),
    (["imo", "--ship", "eso", "--out", "OUT"], "steerlab: error: --ship: unknown ship 'eso' (did you mean 'esso'?)"),
    (["trial", "zigzag", "--ship", "nomoto1", "--rudder", "40"], "--rudder"),
    (["trial", "turning", "--ship", "nomoto1", "--rudder", "nan"], "--rudder"),
    (["trial", "pullout", "--ship", "nomoto1", "--ship-option", "K=-1"], "ship.options.K"),
    (["trial", "spiral", "--ship", "nomoto1", "--ship-option", "K"], "--ship-option"),
    (["imo", "--ship", "nomoto1", "--speed-kn", "-3", "--out", "OUT"], "--speed-kn"),
])
def test_cli_bad_input_exit_2_one_line(argv, field, tmp_path, capsys):
    argv = [str(tmp_path / "o") if a == "OUT" else a for a in argv]
    assert main(argv + ["--quiet"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and field in err[0]
    assert not (tmp_path / "o").exists()


def test_cli_bad_input_subprocess():
    p = subprocess.run([sys.executable, "-m", "steerlab", "trial", "zigzag", "--ship", "nomoto1", "--rudder",
                        "36", "--json"], capture_output=True, text=True, timeout=120)
    assert p.returncode == 2 and p.stdout == ""
    assert len(p.stderr.strip().splitlines()) == 1 and "--rudder" in p.stderr


# ------------------------------------------------------------------ every registered ship

def _all_ships():
    from steerlab.ships.registry import SHIPS

    return sorted(SHIPS)


@pytest.mark.parametrize("ship", _all_ships())
def test_every_ship_runs_a_20_20_zigzag_within_the_gear(ship):
    """Any ship of the registry (default options and speed) runs the trial program unchanged."""
    tr = run_zigzag(TrialConditions(ship), 20.0, 20.0)
    m, res = tr.metrics, tr.result
    assert np.all(np.isfinite(res.states))
    assert m["complete"] and len(m["overshoot_angles_deg"]) >= 2
    assert all(math.isfinite(o) for o in m["overshoot_angles_deg"])
    assert np.max(np.abs(res.delta)) <= rad(35.0) + 1e-12
    rate = np.abs(np.diff(res.delta)) / res.dt
    # the ship's default gear: 2.33 deg/s, or Froude-scaled for a scale model (2.33 sqrt(lambda))
    spec = get_ship(ship)
    limit = rad(2.33) * (1.0 if spec.model_scale is None else math.sqrt(spec.model_scale))
    assert np.max(rate) <= limit * (1.0 + 1e-9)


def test_the_spiral_table_writes_each_sign_of_the_cubic_once():
    """It printed ``-0.00468 + -9.319 r``."""
    from steerlab.trials.tables import spiral_rows

    m = {"verdict": "unstable", "slope_at_zero_deg_per_deg_s": -8.06, "loop_width_deg": 1.0,
         "loop_height_deg_s": 0.1, "loop_width_direct_bounds_deg": [0.5, 1.5], "all_steady": True,
         "cubic_deg": {"c0": -0.00468, "c1": -9.319, "c2": 0.0, "c3": 0.51}}
    cubic = dict((r[0], r[1]) for r in spiral_rows(m))["cubic delta = H(r)"]
    assert cubic == "-0.00468 - 9.319 r + 0 r^2 + 0.51 r^3"
