"""The conformance matrix and the random Nomoto plants (issue 30, "What must show").

* The judge (steerlab.conformance.judge) on synthetic records: it must be able to fail a run
  for each reason it names, and pass one that settles (so the matrix cannot pass by a judge
  that always says yes); the vectorised reversal counter of the plants gives the same counts
  as the single one.
* Operating points: design speed inside the range, ends as documented, one point for a ship
  tabulated at one speed, rpm points for the rpm-indexed entries.
* The matrix (every built-in ship x every built-in law x calm and sea state 5, run once per
  session for every pytest-xdist worker): every case is run; no case fails silently (a
  refusal is one line that starts with the field it names, a failure has a reason of a known
  kind, nothing crashed); and the fraction that steers is at least :data:`STEER_TARGET`.
* Random plants: >= 200 seeded first- and second-order Nomoto plants of both signs in plain
  NumPy, every law designed from (K, T) alone: the fraction of (plant, law) lanes that hold
  the 20 deg change is at least :data:`HOLD_TARGET`.

The matrix's and the plants' tests are the conformance evaluation (marked ``conformance``, about
9 minutes of CPU from a cold cache): the default ``pytest`` run leaves them out,
``pytest -m conformance`` runs them, and ``.ci/run`` runs them as its second step
(tests/conftest.py: ``EVALUATION_MARK``). The judge, operating-point and reused-sea tests above
them run in every run.

The two thresholds are issue 30's target. On the code before the design rules landed
(commit 3f3992e) the matrix steers 26 % of its cases (439 of 1672) and the plants hold 26 % (738 of 2816), so both
threshold tests were marked ``xfail(strict=True)``. The plants meet it now (2701 of 2816 lanes,
95.9 %: asa designed from (K, T) of either sign, gain_shaping_pid's pole placement for T < 0,
and the bandwidth rule designing course-unstable plants past the gear caps while the rudder can
hold the turn), so their mark is gone. The matrix met it on 2026-11-29 (1716 of 1804 cases,
95.1 %: docs/conformance.md), and its mark is gone too.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from steerlab.conformance import judge as J
from steerlab.conformance.cases import CALM, SEA5, Case, run_length, time_scale
from steerlab.conformance.matrix import TARGET, build_case, builtin_controllers, builtin_ships, cases
from steerlab.conformance.points import OPEN_HIGH, OPEN_LOW, operating_points
from steerlab.ships.registry import get_ship
from steerlab.units import KNOT

STEER_TARGET = TARGET
"""Fraction of matrix cases that must steer (issue 30: 0.95)."""
HOLD_TARGET = 0.95
"""Fraction of (random plant, law) lanes that must hold the change (issue 30: 0.95)."""
N_RANDOM_PLANTS = 256
"""Random plants drawn (issue 30: at least 200)."""
CALM_STEER_FLOOR = 0.97
"""Measured floor (after issue 30's design rules): fraction of calm-water cases that steer
(measured 0.986 on 2026-11-29, 889 of 902; a margin for another machine's floating-point path)."""
SEA_HOLD_FLOOR = 0.88
"""Measured floor (the laws behind the designed wave filter with its yaw-bias state and its gain
scaled to the sample time; Norrbin ships taking the waves superposed): fraction of the
sea-state-5 cases that hold the change with bounded rudder reversals (measured 0.917 on
2026-11-29, 827 of 902, the course made good through the judge's triangular window; the
matrix's 95 % is met by both legs together, 1716 of 1804)."""
DESIGNED_HOLD_FLOOR = 0.95
"""Of the random-plant lanes a law designed (not refused), the fraction that must hold the change."""
KINDS = {"diverged", "spins", "never turns", "limit cycle", "steady offset", "not settled", "rudder reversals"}
"""The failure kinds the judge names (``crashed`` is a defect, asserted absent)."""


# ----------------------------------------------------------------------------- the judge
def _record(e_deg, dt=0.1, t_change=50.0, delta=None):
    """A heading record: 0 before the change, then the error ``e_deg(t - t_change)`` off 20 deg."""
    t = np.arange(0.0, 2000.0 + dt / 2, dt)
    psi = np.where(t < t_change, 0.0, np.radians(20.0 + e_deg(np.maximum(t - t_change, 0.0))))
    d = np.zeros_like(t) if delta is None else delta(t)
    return t, psi, d


def _judge(rec, waves=False, hold=400.0):
    t, psi, d = rec
    return J.judge(t, psi, d, 50.0, 0.0, math.radians(20.0), hold, waves)


def test_judge_passes_a_settling_turn_and_fails_each_bad_one():
    settle = _record(lambda s: -20.0 * np.exp(-s / 60.0))
    assert _judge(settle).verdict == J.STEERS
    assert _judge(settle).metrics["settle_time"] == pytest.approx(60.0 * math.log(20.0), abs=0.2)
    cycle = _record(lambda s: 3.0 * np.sin(2 * np.pi * s / 120.0))
    assert _judge(cycle).kind == "limit cycle"
    assert "period about 120 s" in _judge(cycle).reason
    assert _judge(_record(lambda s: 2.0 + 0.0 * s)).kind == "steady offset"
    assert _judge(_record(lambda s: -20.0 + 0.0 * s)).kind == "never turns"
    assert _judge(_record(lambda s: 0.5 * s)).kind == "spins"
    assert _judge(_record(lambda s: -20.0 * np.exp(-s / 800.0))).kind == "not settled"
    t, psi, d = settle
    psi = psi.copy()
    psi[15000] = np.nan
    assert _judge((t, psi, d)).kind == "diverged"
    # the heading holds, the rudder works: 2 deg at 0.1 Hz is 12 reversals a minute
    chatter = _record(lambda s: -20.0 * np.exp(-s / 60.0), delta=lambda t: np.radians(2.0) * np.sin(0.2 * np.pi * t))
    assert _judge(chatter).kind == "rudder reversals"
    small = _record(lambda s: -20.0 * np.exp(-s / 60.0), delta=lambda t: np.radians(0.2) * np.sin(0.2 * np.pi * t))
    assert _judge(small).verdict == J.STEERS          # below the hysteresis


def test_judge_in_waves_holds_the_mean_heading():
    waves = _record(lambda s: -20.0 * np.exp(-s / 60.0) + 3.0 * np.sin(2 * np.pi * s / 10.0))
    assert _judge(waves, waves=False).verdict == J.FAILS      # the heading itself swings 3 deg
    assert _judge(waves, waves=True).verdict == J.STEERS      # its 60 s mean is on course
    drift = _record(lambda s: -20.0 * np.exp(-s / 60.0) + 3.0 * np.sin(2 * np.pi * s / 10.0) + 0.004 * s)
    assert _judge(drift, waves=True).verdict == J.FAILS       # the mean drifts off course


def test_course_made_good_removes_the_wave_yaw_and_keeps_a_slow_swing():
    """The triangular window's gains: sinc(L / 2P)^2 (judge.course_made_good)."""
    t = np.arange(0.0, 3000.0, 0.1)
    late = t > 1000.0

    def left(period):
        e = np.sin(2 * np.pi * t / period)
        return np.max(np.abs(J.course_made_good(t, e)[late]))

    def boxcar_left(period):
        return np.max(np.abs(J.trailing_mean(t, np.sin(2 * np.pi * t / period), J.WAVE_WINDOW)[late]))

    for period in (7.0, 9.0, 9.7, 13.0):                 # the wave yaw of sea state 5
        assert left(period) <= (period / (np.pi * J.WAVE_WINDOW / 2)) ** 2 + 1e-3
        assert left(period) < 0.25 * boxcar_left(period)
    # a 9-s yaw of 5.8 deg std (the Zeefakkel at 3.9 kn) leaves under 0.06 deg, not +-0.55
    assert np.degrees(np.radians(5.8 * math.sqrt(2)) * left(9.0)) < 0.06
    assert 0.8 < left(120.0) < 0.82                      # a real slow swing is kept ...
    assert left(120.0) > boxcar_left(120.0) + 0.15       # ... better than by one 60-s mean
    assert J.course_made_good(t, np.full_like(t, 0.3))[-1] == pytest.approx(0.3)   # unit gain


def test_reversal_counts_and_the_vector_counter_agree():
    t = np.arange(0.0, 60.0, 0.1)
    assert J.count_reversals(np.radians(2.0) * np.sin(2 * np.pi * t / 10.0), math.radians(0.5)) == 12   # 6 periods: 12 extremes
    assert J.count_reversals(np.radians(0.2) * np.sin(2 * np.pi * t / 10.0), math.radians(0.5)) == 0
    rng = np.random.default_rng(4)
    walks = np.cumsum(rng.normal(0.0, 0.004, (40, 3000)), axis=1)
    walks[:5] = np.round(walks[:5], 2)                         # held stretches too
    counter = J.ReversalCounter(walks[:, 0], math.radians(0.5))
    for k in range(1, walks.shape[1]):
        counter.update(walks[:, k])
    expected = [J.count_reversals(w, math.radians(0.5)) for w in walks]
    assert counter.count.tolist() == expected
    assert max(expected) > 5


# ----------------------------------------------------------------------------- points and runs
def test_operating_points_follow_the_range():
    frigate = get_ship("frigate-norrbin")
    lo, hi = frigate.speed_range
    pts = {p.label: p for p in operating_points(frigate)}
    assert (pts["low"].speed, pts["high"].speed) == (pytest.approx(lo), pytest.approx(hi))
    assert lo < pts["design"].speed < hi
    esso = get_ship("esso")                                     # range 0 to inf: clipped
    pts = {p.label: p for p in operating_points(esso)}
    vd = pts["design"].speed
    assert pts["low"].speed == pytest.approx(OPEN_LOW * vd)
    assert pts["high"].speed == pytest.approx(OPEN_HIGH * vd)
    assert [p.label for p in operating_points(get_ship("tanker-176k-model-norrbin"))] == ["design"]
    capella = operating_points(get_ship("capella-norrbin"))
    assert sorted(p.rpm for p in capella) == [110.0, 160.0, 220.0]
    for p in capella + operating_points(esso):
        assert 0.01 <= p.speed / KNOT <= 40.0


def test_run_length_follows_the_ship_and_stays_bounded():
    fast = time_scale(get_ship("kosoko"), operating_points(get_ship("kosoko"))[0])
    slow = time_scale(get_ship("mss-tanker"), operating_points(get_ship("mss-tanker"))[0])
    assert fast < 60.0 < slow
    for t_s in (fast, slow, 1e6):
        duration, hold = run_length(t_s)
        assert 1000.0 <= duration - 50.0 <= 8000.0 and 300.0 <= hold <= 0.5 * (duration - 50.0)


def test_a_scale_model_meets_the_froude_scaled_sea_and_is_judged_in_full_scale_time():
    """The KVLCC2 L7 model (lambda = 45.7) gets sea state 5 at model scale, Hs / lambda and
    Tp / sqrt(lambda), not the full-scale waves (3.25 m on a 7 m model); a full-size ship gets
    the sea state itself; and the model's record is judged with time x sqrt(lambda)."""
    from steerlab.conformance.cases import SEA, scenario_dict, sea_block
    from steerlab.conformance.matrix import full_scale_time
    from steerlab.environment.sea_state import sea_state

    model, ship = get_ship("kvlcc2-l7"), get_ship("esso")
    lam = model.model_scale
    assert lam == pytest.approx(320.0 / 7.0, rel=1e-4)     # the catalogue stores 45.714
    row = sea_state(5, "sea_state")
    wave = sea_block(model)
    assert wave["Hs"] == pytest.approx(row.Hs / lam) and wave["Tp"] == pytest.approx(row.Tp / math.sqrt(lam))
    assert "sea_state" not in wave and wave["wave_angle_deg"] == SEA["wave_angle_deg"]
    assert sea_block(ship) == SEA and full_scale_time(ship) == 1.0
    assert full_scale_time(model) == pytest.approx(math.sqrt(lam))
    case = Case("kvlcc2-l7", "pid", operating_points(model)[1], SEA5)
    assert scenario_dict(case, 100.0)["environment"]["wave"] == wave


def test_reused_sea_is_the_full_build():
    """build_case reuses a ship's sea for the next controller: the same setup, array for array."""
    from dataclasses import fields

    from steerlab.conformance import matrix
    from steerlab.conformance.cases import scenario_dict
    from steerlab.sim.scenario import scenario_from_dict
    from steerlab.sim.setup import build

    point = operating_points(get_ship("esso"))[0]
    matrix._SEAS.clear()
    first = build_case(Case("esso", "pid", point, SEA5), 1500.0)
    case = Case("esso", "adrc", point, SEA5)
    reused = build_case(case, 1500.0)
    assert reused.w is first.w
    full = build(scenario_from_dict(scenario_dict(case, 1500.0)))
    assert np.any(full.w != 0.0)
    for f in fields(full):
        a, b = getattr(full, f.name), getattr(reused, f.name)
        if isinstance(a, np.ndarray):
            assert np.array_equal(a, b), f.name
        elif f.name not in ("name", "guidance"):
            assert a == b, f.name
    matrix._SEAS.clear()


@pytest.mark.parametrize("ship,law", [("esso", "pid"), ("esso", "adrc"), ("mss-container", "sliding_mode"),
                                      ("nomoto2", "classic_autopilot")])
def test_calm_water_runs_in_the_sea_legs_loop_bit_for_bit(ship, law):
    """The matrix runs a calm case by its law's "+wf" loop with the filter off (matrix.one_loop,
    one compiled loop per ship and law): the same design and every recorded state, rudder and
    order the same bits as the plain law's own loop, at every operating point. (esso + pid and
    esso + adrc are the suite's usual loops; the container ship has 4 DOF and an rpm state;
    classic_autopilot's integral starts at the straight-course rudder.)"""
    from steerlab.conformance.matrix import one_loop
    from steerlab.sim.engine import simulate

    spec = get_ship(ship)
    for point in operating_points(spec):
        setup = build_case(Case(ship, law, point, CALM), run_length(time_scale(spec, point))[0])
        through = one_loop(setup)
        assert through.controller.name == law + "+wf" and setup.controller.name == law
        plain, filtered = simulate(setup), simulate(through)
        for name in ("time", "states", "delta_cmd", "psi_ref", "r_ref"):
            a, b = getattr(plain, name), getattr(filtered, name)
            assert a.shape == b.shape and np.array_equal(a, b, equal_nan=True), (point.label, name)
    asa = build_case(Case("nomoto1", "asa", operating_points(get_ship("nomoto1"))[0], CALM), 200.0)
    assert one_loop(asa) is asa                       # its own filter: run as it is


@pytest.mark.parametrize("ship,sea", [("nomoto1", SEA5), ("small-tanker-nomoto-10deg", SEA5), ("esso", CALM),
                                      ("nomoto2", CALM)])
def test_backstepping_a_cases_issue_30_named_now_steer(ship, sea):
    """backstepping_a's column (issue 30): the Nomoto ships it spun in sea state 5 (behind the
    designed wave filter) and the ships whose b2 differs from K/T that its design rule refused
    (the 3-DOF Esso, b2 = 2.5 K/T; the second-order Nomoto ship) steer the matrix's case: the
    design rule no longer feeds r' back (control/backstepping_a.py)."""
    from steerlab.conformance.matrix import run_case

    point = [p for p in operating_points(get_ship(ship)) if p.label == "design"][0]
    out = run_case(Case(ship, "backstepping_a", point, sea))
    assert out.verdict == J.STEERS, out.reason
    assert abs(out.metrics["final_error_deg"]) <= J.TOL_DEG and out.metrics["max_error_deg"] < 40.0


# ----------------------------------------------------------------------------- the matrix
@pytest.fixture(scope="module")
def matrix(tmp_path_factory):
    from conftest import once_per_session

    from steerlab.conformance.matrix import run_matrix

    return once_per_session(tmp_path_factory, "conformance-matrix", lambda folder: run_matrix(workers=2).to_dict())


@pytest.mark.slow
@pytest.mark.conformance
def test_matrix_runs_every_case_and_none_fails_silently(matrix):
    outcomes = matrix["outcomes"]
    expected = cases()
    assert [(o["ship"], o["controller"], o["point"], o["sea"]) for o in outcomes] == [c.key for c in expected]
    assert {o["ship"] for o in outcomes} == set(builtin_ships())
    assert {o["controller"] for o in outcomes} == set(builtin_controllers())
    assert {o["sea"] for o in outcomes} == {CALM, SEA5}
    crashed = []
    for o in outcomes:
        where = f"{o['ship']} + {o['controller']} at {o['point']} ({o['sea']})"
        assert o["verdict"] in J.VERDICTS, where
        if o["verdict"] == J.STEERS:
            assert o["reason"] == "" and abs(o["metrics"]["final_error_deg"]) <= J.TOL_DEG, where
        elif o["verdict"] == J.REFUSED:
            assert o["field_name"] and "\n" not in o["reason"], where
            assert o["reason"].startswith(o["field_name"] + ": ") and len(o["reason"]) > len(o["field_name"]) + 10, where
        elif o["reason"].startswith("crashed"):
            crashed.append(f"{where}: {o['reason']}")
        else:
            assert o["reason"].split(":", 1)[0] in KINDS and "\n" not in o["reason"], (where, o["reason"])
    assert not crashed, "a design or run raised something other than InputError:\n" + "\n".join(crashed)
    t = matrix["total"]
    assert t["steers"] + t["refused"] + t["fails"] == len(outcomes)


@pytest.mark.slow
@pytest.mark.conformance
def test_matrix_fraction_that_steers_meets_the_target(matrix):
    by_law = {law: f"{c['steers']}/{sum(c.values())}" for law, c in matrix["by_controller"].items()}
    assert matrix["fraction_steers"] >= STEER_TARGET, by_law


@pytest.mark.slow
@pytest.mark.conformance
def test_calm_water_cases_steer_or_are_refused(matrix):
    """Calm water: the designs carry (>= CALM_STEER_FLOOR steer) and at most 2 % fail (the rest
    are refused in one line naming what to give)."""
    calm = [o for o in matrix["outcomes"] if o["sea"] == CALM]
    steers = sum(o["verdict"] == J.STEERS for o in calm) / len(calm)
    fails = [f"{o['ship']} + {o['controller']} ({o['point']}): {o['reason']}" for o in calm if o["verdict"] == J.FAILS]
    assert steers >= CALM_STEER_FLOOR, steers
    assert len(fails) <= 0.02 * len(calm), fails


@pytest.mark.slow
@pytest.mark.conformance
def test_sea_cases_hold_behind_the_designed_wave_filter(matrix):
    """Sea state 5: at least SEA_HOLD_FLOOR of the cases hold the change with at most six rudder
    reversals a minute (each law behind the wave filter designed for the 0.1 s step; without it
    15 of 836 did)."""
    sea = [o for o in matrix["outcomes"] if o["sea"] == SEA5]
    steers = sum(o["verdict"] == J.STEERS for o in sea) / len(sea)
    assert steers >= SEA_HOLD_FLOOR, steers


# ----------------------------------------------------------------------------- random plants
def test_plain_plants_are_the_nomoto_models():
    """The NumPy plant's discretisation: first order, r = K delta (1 - exp(-t/T)); second
    order, the same DC gain and initial yaw acceleration K T3 / (T1 T2) per rad of rudder."""
    from steerlab.conformance.plants import Plant, _discrete, random_plants

    p1 = Plant(1, 0.1, 50.0, 0.5, 0.05)
    Phi, Gam = _discrete(p1, 10.0)
    assert Gam[0] == pytest.approx(0.1 * (1 - math.exp(-10.0 / 50.0)), rel=1e-12)
    p2 = Plant(2, -0.1, -150.0, 0.5, 0.05, -124.0, 16.0, 42.0)    # MSS-tanker-like, course-unstable
    A, B, C = p2.matrices()
    assert np.linalg.eigvals(A).real.max() == pytest.approx(1.0 / 124.0, rel=1e-9)
    assert float(-C @ np.linalg.solve(A, B)) == pytest.approx(-0.1, rel=1e-12)     # DC gain K
    assert float(C @ B) == pytest.approx(-0.1 * 42.0 / (-124.0 * 16.0), rel=1e-12)
    plants = random_plants(N_RANDOM_PLANTS)
    assert len(plants) >= 200
    assert {(p.order, p.T > 0) for p in plants} == {(1, True), (1, False), (2, True), (2, False)}
    for p in plants:
        assert 0.01 <= abs(p.K) <= 0.5 and 20.0 <= abs(p.T) <= 400.0 and p.K * p.T > 0
        assert math.radians(20) <= p.delta_max <= math.radians(35) and math.radians(1.5) <= p.rate_max <= math.radians(7)
        if p.order == 2:
            assert p.T1 + p.T2 - p.T3 == pytest.approx(p.T) and p.T1 * p.T > 0 and p.T2 > 0 and p.T3 > 0


@pytest.fixture(scope="module")
def plant_outcomes(tmp_path_factory):
    from conftest import once_per_session

    from steerlab.conformance.plants import random_plants, run_plants

    def make(folder):
        return [o.__dict__ for o in run_plants(random_plants(N_RANDOM_PLANTS))]

    return once_per_session(tmp_path_factory, "conformance-plants", make)


@pytest.mark.slow
@pytest.mark.conformance
def test_random_plants_every_lane_is_judged(plant_outcomes):
    assert len(plant_outcomes) == N_RANDOM_PLANTS * len(builtin_controllers())
    for o in plant_outcomes:
        if o["verdict"] == J.REFUSED:
            assert o["field_name"] and o["reason"].startswith(o["field_name"] + ": ") and "\n" not in o["reason"]
        elif o["verdict"] == J.FAILS:
            assert o["reason"].split(":", 1)[0] in KINDS, o
        else:
            assert o["verdict"] == J.STEERS and o["reason"] == ""


@pytest.mark.slow
@pytest.mark.conformance
def test_random_plants_a_designed_law_holds_the_change(plant_outcomes):
    """Every design a law makes from (K, T) alone holds the 20 deg change on >= 95 % of the plants."""
    designed = [o for o in plant_outcomes if o["verdict"] != J.REFUSED]
    holds = sum(o["verdict"] == J.STEERS for o in designed) / len(designed)
    assert holds >= DESIGNED_HOLD_FLOOR, holds


@pytest.mark.slow
@pytest.mark.conformance
def test_random_plants_hold_the_change(plant_outcomes):
    """Issue 30's target: >= 95 % of the (plant, law) lanes hold (2701 of 2816 measured); every
    law, asa and gain_shaping_pid included, designs course-unstable plants (at most one
    plant in 64 refused per law: a gear that cannot hold the turn)."""
    holds = sum(o["verdict"] == J.STEERS for o in plant_outcomes) / len(plant_outcomes)
    by_law = {}
    for o in plant_outcomes:
        c = by_law.setdefault(o["controller"], {J.STEERS: 0, J.REFUSED: 0, J.FAILS: 0})
        c[o["verdict"]] += 1
    assert holds >= HOLD_TARGET, by_law
    for law, c in by_law.items():
        assert c[J.REFUSED] <= N_RANDOM_PLANTS // 64, (law, c)


# ----------------------------------------------------------------------------- the command
def test_conformance_command(tmp_path, capsys):
    from steerlab.cli import main

    out = tmp_path / "conf"
    assert main(["conformance", "--ships", "nomoto1", "--controllers", "lq_pd", "--sea-points",
                 "--workers", "1", "--quiet", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "lq_pd" in text and "3 cases" in text
    assert (out / "matrix.json").exists()
    page = (out / "conformance.md").read_text(encoding="utf-8")
    assert "| `nomoto1` |" in page
    assert main(["conformance", "--ships", "no-such-ship"]) == 2
    assert "ship.model" in capsys.readouterr().err


# ------------------------------------------------------------- the evaluation is its own step
EVALUATION_TESTS = {"test_matrix_runs_every_case_and_none_fails_silently",
                    "test_matrix_fraction_that_steers_meets_the_target",
                    "test_calm_water_cases_steer_or_are_refused",
                    "test_sea_cases_hold_behind_the_designed_wave_filter",
                    "test_random_plants_every_lane_is_judged",
                    "test_random_plants_a_designed_law_holds_the_change",
                    "test_random_plants_hold_the_change"}


@pytest.mark.parametrize("marks,selected", [((), "others"), (("-m", "conformance"), "evaluation"),
                                            (("-m", "not realtime"), "others")])
def test_the_default_run_leaves_the_evaluation_to_its_own_step(marks, selected):
    """The README's ``pytest`` run collects every test of this module but the seven of the
    evaluation; ``-m conformance`` (what ``.ci/run`` runs second) collects exactly those seven;
    another ``-m`` expression does not bring them back."""
    import subprocess
    import sys
    from pathlib import Path

    repo = Path(__file__).resolve().parent.parent
    proc = subprocess.run([sys.executable, "-m", "pytest", "--collect-only", "-q", "-n", "0",
                           "-p", "no:cacheprovider", *marks, "tests/test_conformance_matrix.py"],
                          cwd=repo, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    names = {line.split("::")[1].split("[")[0] for line in proc.stdout.splitlines() if "::" in line}
    if selected == "evaluation":
        assert names == EVALUATION_TESTS
    else:
        assert not names & EVALUATION_TESTS and "test_conformance_command" in names
    ci = (repo / ".ci" / "run").read_text(encoding="utf-8").splitlines()
    assert ci.index("python3 -m pytest -q") < ci.index("python3 -m pytest -q -m conformance")
