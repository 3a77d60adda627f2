"""MMG model: Clarke arithmetic (eqs 6-7), eqs (8)-(11), Fujiwara wind (12)-(16), Kosoko, current."""

import math

import numpy as np
import pytest

from steerlab.environment.channels import N_CHANNELS, W_WIND_DIR, W_WIND_SPEED, set_current
from steerlab.environment.wind_fujiwara import (TABLE1, WindGeometry, fujiwara_coefficients,
                                               relative_wind, wind_force)
from steerlab.errors import InputError
from steerlab.ships.clarke import (clarke_derivatives, clarke_regressions, course_stability_index,
                                   linear_model_eq8, nomoto_KT_eq11, prime_mass, state_space_eq10)
from steerlab.ships.linear_analysis import nomoto_from_linear
from steerlab.ships.mmg import (get_mmg_data, mmg_rhs, propeller_rate, propeller_rate_for_speed)
from steerlab.ships.registry import get_ship
from steerlab.sim.engine import simulate_compiled, simulate_readable
from steerlab.sim.scenario import scenario_from_dict
from steerlab.sim.setup import build
from steerlab.units import ms_to_knots, rad

KOSOKO = get_mmg_data("kosoko")
U0 = KOSOKO.design.speed_m_s


# ------------------------------------------------------------------ Clarke, eqs (5)-(11)

from conftest import batch_parity_and_vectorisation  # noqa: E402


def test_clarke_regressions_hand_computed():
    # L = 100, B = 20, T = 5, C_b = 0.5, A = 50 m^2: B/T = 4, B/L = 0.2, T/L = 0.05
    f = math.pi * 0.05**2
    d = clarke_regressions(100.0, 20.0, 5.0, 0.5, 50.0)
    assert d.Y_vdot == pytest.approx(-(1 + 0.32 - 0.204) * f)
    assert d.Y_rdot == pytest.approx(-(0.134 - 0.0528) * f)
    assert d.N_vdot == pytest.approx(-(0.22 - 0.164) * f)
    assert d.N_rdot == pytest.approx(-(1 / 12 + 0.034 - 0.066) * f)
    assert d.Y_v == pytest.approx(-1.8 * f)
    assert d.Y_r == pytest.approx(0.38 * f)
    assert d.N_v == pytest.approx(-0.62 * f)
    assert d.N_r == pytest.approx(-0.294 * f)
    assert d.Y_delta == pytest.approx(0.015) and d.N_delta == pytest.approx(-0.0075)
    # eq (7): dY'v = -0.3 * 0.015 = -0.0045; dY'r = dN'v = +0.00225; dN'r = -0.001125
    c = clarke_derivatives(100.0, 20.0, 5.0, 0.5, 50.0)
    assert c.Y_v == pytest.approx(-1.8 * f - 0.0045)
    assert c.Y_r == pytest.approx(0.38 * f + 0.00225)
    assert c.N_v == pytest.approx(-0.62 * f + 0.00225)
    assert c.N_r == pytest.approx(-0.294 * f - 0.001125)
    assert c.Y_vdot == d.Y_vdot and c.Y_delta == d.Y_delta
    mp = prime_mass(100.0, 20.0, 5.0, 0.5)
    assert mp.m == pytest.approx(0.5 * 100 * 20 * 5 / (0.5 * 100**3)) and mp.I_zz == pytest.approx(mp.m / 16)


def test_eq10_is_eq8_solved_and_eq11_is_the_nomoto_reading():
    d = clarke_derivatives(100.0, 20.0, 5.0, 0.5, 50.0)
    mp = prime_mass(100.0, 20.0, 5.0, 0.5, x_c=2.0)
    M, F, G = linear_model_eq8(d, mp, 100.0, 6.0)
    A, B = state_space_eq10(d, mp, 100.0, 6.0)
    np.testing.assert_allclose(A, np.linalg.solve(M, F), rtol=1e-12)
    np.testing.assert_allclose(B, np.linalg.solve(M, G), rtol=1e-12)
    assert G[1] == pytest.approx(6.0**2 / 100 * d.N_delta)   # N'delta in the yaw row, not Y'delta
    K, T = nomoto_KT_eq11(A, B)
    n = nomoto_from_linear(A, B)
    assert K == pytest.approx(n["K"], rel=1e-9) and T == pytest.approx(n["T"], rel=1e-9)
    assert course_stability_index(d, mp) > 0 and K < 0 < T     # stable; paper sign: delta > 0 to port


def test_kosoko_is_course_unstable_by_clarke_and_says_so():
    d, mp = KOSOKO.derivatives(), KOSOKO.prime_mass()
    assert course_stability_index(d, mp) < 0
    A, _ = get_ship("kosoko").linearise(U0)
    assert np.max(np.linalg.eigvals(A).real) > 0
    K, T = get_ship("kosoko").nomoto(U0)
    assert T < 0   # unstable first-order reading; the nonlinear model stays bounded (below)


# ------------------------------------------------------------------ the kernel

def _rhs(x, delta=0.0, w=None, p=None, t=0.0):
    p = build_kosoko_params() if p is None else p
    dx = np.zeros(6)
    mmg_rhs(t, np.asarray(x, dtype=float), delta, np.zeros(N_CHANNELS) if w is None else w, p, dx)
    return dx


def build_kosoko_params(rpm=None, options=None):
    spec = get_ship("kosoko")
    return spec.pack(U0, rpm, spec.options(options))


def test_linearisation_of_the_kernel_is_eq10_in_steerlab_sign():
    p = build_kosoko_params()
    x0 = np.array([0.0, 0.0, 0.0, U0, 0.0, 0.0])
    J = np.empty((2, 3))
    for j, (i, h) in enumerate(((4, 1e-6), (5, 1e-6))):
        xp, xm = x0.copy(), x0.copy()
        xp[i] += h
        xm[i] -= h
        J[:, j] = (_rhs(xp, p=p)[4:6] - _rhs(xm, p=p)[4:6]) / (2 * h)
    J[:, 2] = (_rhs(x0, 1e-6, p=p)[4:6] - _rhs(x0, -1e-6, p=p)[4:6]) / 2e-6
    A, B = get_ship("kosoko").linearise(U0)
    np.testing.assert_allclose(J[:, :2], A, rtol=1e-5)
    np.testing.assert_allclose(J[:, 2], B, rtol=1e-5)
    assert B[1] > 0          # steerlab: starboard rudder gives r' > 0
    _, B_paper = state_space_eq10(KOSOKO.derivatives(), KOSOKO.prime_mass(), KOSOKO.hull.L, U0)
    np.testing.assert_allclose(B, -B_paper)


def test_kosoko_steady_straight_at_design_rpm_and_rpm_for_speed():
    assert propeller_rate_for_speed(U0, KOSOKO) * 60 == pytest.approx(KOSOKO.design.rpm)
    dx = _rhs([0, 0, 0.3, U0, 0, 0])
    np.testing.assert_allclose(dx[2:], 0.0, atol=1e-12)
    assert dx[0] == pytest.approx(U0 * math.cos(0.3)) and dx[1] == pytest.approx(U0 * math.sin(0.3))
    # another speed: the rate for that speed holds it; more rpm accelerates
    n = propeller_rate_for_speed(0.3, KOSOKO)
    assert 0 < n * 60 < KOSOKO.design.rpm
    assert _rhs([0, 0, 0, 0.3, 0, 0], p=build_kosoko_params(rpm=n * 60))[3] == pytest.approx(0.0, abs=1e-12)
    assert _rhs([0, 0, 0, 0.3, 0, 0], p=build_kosoko_params(rpm=n * 60 + 50))[3] > 0


def test_rpm_schedule_interpolates_and_steps():
    p = build_kosoko_params(options={"rpm_schedule": [[0, 600], [10, 300], [20, 300], [20, 120], [30, 0]]})
    assert [propeller_rate(t, p) * 60 for t in (0.0, 5.0, 10.0, 15.0, 20.0, 25.0, 40.0)] == \
        pytest.approx([600, 450, 300, 300, 120, 60, 0])


@pytest.mark.parametrize("opts, msg", [
    ({"rpm_schedule": [[10, 600], [5, 300]]}, "non-decreasing"),
    ({"rpm_schedule": [[0, -5]]}, "rpm"),
    ({"rpm_schedule": [[0, 600, 3]]}, "rpm_schedule"),
    ({"rpm_schedule": "fast"}, "rpm_schedule"),
    ({"rpm": 600}, "rpm"),
])
def test_bad_options_name_the_field(opts, msg):
    with pytest.raises(InputError, match=msg) as ei:
        build(scenario_from_dict({"ship": {"model": "kosoko", "speed_kn": 1.0, "options": opts}}))
    assert ei.value.field.startswith("ship.options.") and ei.value.field != "ship.options."
    assert ei.value.field.split(".")[2] in opts


KOSOKO_TOML = (__import__("importlib").resources.files("steerlab.ships") / "data" / "mmg_kosoko.toml").read_text(
    encoding="utf-8")


@pytest.mark.parametrize("line, repl, field, msg", [
    ("C_b = 0.55", "C_b = nan", "hull.C_b", "finite"),                       # NaN
    ("C_b = 0.55", "C_b = 1.5", "hull.C_b", "less than 1"),                  # out of range, bound named
    ("D = 0.08 ", "", "propeller.D", "required"),                           # missing
    ("w_p = 0.20", "w_p = inf", "propeller.w_p", "finite"),
    ("kt = [0.30,", "kt = [nan,", "propeller.kt.0", "finite"),
    ("kt = [0.30,", "kt = [-0.30,", "propeller.kt", r"K_T\(0\) must be > 0"),  # no bollard thrust
    ("area = 0.0069", "area = 0.0", "rudder.area", "greater than 0"),
    ("C = 0.104", "C = nan", "wind.C", "finite"),
    ("speed_range_m_s = [0.05, 1.5]", "speed_range_m_s = [1.5, 0.05]", "speed_range_m_s", "lo < hi"),
    ("speed_m_s = 0.5 ", "speed_m_s = 2.0 ", "design.speed_m_s", "outside the data's speed_range"),
])
def test_bad_kosoko_data_is_refused_naming_the_field(line, repl, field, msg):
    """A missing, NaN or out-of-range coefficient of an MMG data file: one InputError naming the field."""
    from steerlab.ships.mmg import load_mmg_data

    assert line in KOSOKO_TOML
    load_mmg_data(KOSOKO_TOML, "k.toml")                                     # the shipped file is valid
    with pytest.raises(InputError, match=msg) as ei:
        load_mmg_data(KOSOKO_TOML.replace(line, repl), "k.toml")
    assert ei.value.field == f"k.toml: {field}" and "\n" not in str(ei.value)


def test_kosoko_speed_outside_the_data_validity_is_refused():
    """speed_range_m_s = [0.05, 1.5] m/s (model scale): 5 kn = 2.57 m/s is refused by the trials and
    flagged in a scenario run, naming the speed field."""
    from steerlab.trials.runner import TrialConditions

    with pytest.raises(InputError, match="validity range") as ei:
        TrialConditions(ship="kosoko", speed_kn=5.0).resolved()
    assert ei.value.field == "speed_kn"
    # a scenario run is allowed but flagged (a warning naming the field, written to metrics.json)
    from steerlab.sim.sanity import scenario_warnings

    flagged = scenario_warnings(scenario_from_dict({"ship": {"model": "kosoko", "speed_kn": 5.0}}))
    assert any(w.startswith("ship.speed_kn") and "2.92 kn" in w for w in flagged), flagged
    assert not scenario_warnings(scenario_from_dict({"ship": {"model": "kosoko", "speed_kn": 1.0}}))


def test_rpm_and_schedule_together_is_an_error():
    with pytest.raises(InputError) as ei:
        build(scenario_from_dict({"ship": {"model": "kosoko", "speed_kn": 1.0, "rpm": 600.0,
                                           "options": {"rpm_schedule": [[0, 600]]}}}))
    assert ei.value.field == "ship.options.rpm_schedule"


def test_current_moves_the_track_not_the_heading():
    w = np.zeros(N_CHANNELS)
    set_current(w, 0.2, rad(90.0))     # flowing east
    for x in ([0, 0, 0.4, U0, 0.02, 0.01], [1, 2, -2.0, 0.3, -0.01, -0.03]):
        calm, cur = _rhs(x, 0.1), _rhs(x, 0.1, w)
        np.testing.assert_allclose(cur[2:], calm[2:], atol=1e-15)
        np.testing.assert_allclose(cur[:2] - calm[:2], [0.0, 0.2], atol=1e-15)


# ------------------------------------------------------------------ Fujiwara wind

GEOM = WindGeometry(L=100.0, B=16.0, A_F=300.0, A_L=1200.0, A_OD=400.0, C=5.0, C_BR=-30.0, H_BR=25.0, H_C=8.0)


def test_fujiwara_coefficients_follow_eqs_14_16():
    c = fujiwara_coefficients(GEOM)
    x5 = TABLE1["x5"]
    assert c[3] == pytest.approx(x5[0] + x5[1] * 1200 / 400 + x5[2] * -30 / 100 + x5[3] * 1200 / (100 * 16))
    n3 = TABLE1["n3"]
    assert c[9] == pytest.approx(n3[0] + n3[1] * -30 / 100 + n3[2] * 300 / (16 * 25) + n3[3] * 1200 / 300)
    x0 = TABLE1["x0"]
    assert c[0] == pytest.approx(x0[0] + x0[1] * 16 * 25 / 300 + x0[2] * 5 / 8 + x0[3] * 400 / 100**2)


@pytest.mark.parametrize("geom", [GEOM, KOSOKO.wind_geometry()])
def test_wind_force_signs_symmetry_and_scaling(geom):
    c = fujiwara_coefficients(geom)
    f = lambda U, a: np.array(wind_force(c, 1.226, geom.A_F, geom.A_L, geom.L, U, a))  # noqa: E731
    head = f(10.0, 0.0)
    assert head[0] < 0 and head[1] == 0.0 and head[2] == 0.0          # head wind: drag, no yaw
    assert f(10.0, math.pi)[0] > 0 and abs(f(10.0, math.pi)[2]) < 1e-9  # following wind pushes ahead
    beam = f(10.0, math.pi / 2)
    assert beam[1] < 0                                                   # from starboard: to port
    for a in (0.3, 1.0, math.pi / 2, 2.5):
        np.testing.assert_allclose(f(10.0, -a), f(10.0, a) * [1, -1, -1], atol=1e-9)  # mirror
        np.testing.assert_allclose(f(20.0, a), 4 * f(10.0, a), rtol=1e-12)            # ~ U_R^2


def test_relative_wind():
    # ship at 5 m/s north into calm air: 5 m/s head wind
    assert relative_wind(5.0, 0.0, 0.0, 0.0, 0.0) == pytest.approx((5.0, 0.0))
    # 10 m/s from the east on a ship heading north at 10 m/s: from 45 deg starboard bow
    U, a = relative_wind(10.0, 0.0, 0.0, 10.0, math.pi / 2)
    assert U == pytest.approx(10 * math.sqrt(2)) and a == pytest.approx(math.pi / 4)
    # heading east into it: head wind of 20 m/s
    assert relative_wind(10.0, 0.0, math.pi / 2, 10.0, math.pi / 2) == pytest.approx((20.0, 0.0), abs=1e-12)


def test_wind_in_the_kernel_uses_the_relative_wind():
    w = np.zeros(N_CHANNELS)
    w[W_WIND_SPEED] = 1.5
    w[W_WIND_DIR] = rad(90.0)      # from the east = from starboard on a northbound ship
    x = [0, 0, 0.0, U0, 0, 0]
    d = _rhs(x, w=w) - _rhs(x)
    # the change equals the wind's (X, Y, N) on the relative wind (no current) through the masses
    c = fujiwara_coefficients(KOSOKO.wind_geometry())
    U, a = relative_wind(U0, 0.0, 0.0, 1.5, math.pi / 2)
    assert U == pytest.approx(math.hypot(U0, 1.5)) and 0 < a < math.pi / 2
    X, Y, N = wind_force(c, KOSOKO.wind.rho_air, KOSOKO.wind.A_F, KOSOKO.wind.A_L, KOSOKO.hull.L, U, a)
    assert Y < 0
    p = build_kosoko_params()
    assert d[3] == pytest.approx(X / p[0])
    assert d[4] == pytest.approx(p[4] * Y + p[5] * N) and d[5] == pytest.approx(p[6] * Y + p[7] * N)
    assert np.all(d[:3] == 0.0)


# ------------------------------------------------------------------ closed loop on the Kosoko

def _kosoko_scenario(**over):
    d = {"dt": 0.05, "duration": 40.0,
         "ship": {"model": "kosoko", "speed_kn": ms_to_knots(U0)},
         "gear": {"delta_max_deg": 35.0, "rate_max_deg_s": 10.0, "T_sg": 0.2},
         "controller": {"type": "pid", "Kp": 0.84, "Ki": 0.001, "Kd": 1.56},
         "guidance": {"changes": [{"t": 2.0, "psi_deg": 30.0}]}}
    d.update(over)
    return scenario_from_dict(d)


def test_compiled_and_readable_agree_with_wind_current_and_rpm_schedule():
    s = build(_kosoko_scenario(
        environment={"wind_speed": 1.5, "wind_dir_deg": 60.0, "current_speed": 0.05, "current_dir_deg": 200.0},
        ship={"model": "kosoko", "speed_kn": ms_to_knots(U0),
              "options": {"rpm_schedule": [[0, 600], [20, 600], [30, 200]]}}))
    a = simulate_readable(s)
    b = simulate_compiled(s)
    np.testing.assert_allclose(a.states, b.states, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(a.delta_cmd, b.delta_cmd, rtol=1e-12, atol=1e-12)
    assert math.degrees(np.max(b.psi)) > 25.0              # the PID made the turn
    assert b.states[-1, 3] < 0.8 * U0                      # rpm cut slows the ship


def test_pid_holds_heading_in_a_beam_current_and_the_track_drifts():
    s = build(_kosoko_scenario(guidance={"changes": []},
                               environment={"current_speed": 0.1, "current_dir_deg": 90.0}))
    res = simulate_compiled(s)
    assert np.max(np.abs(res.psi)) == 0.0 and np.max(np.abs(res.delta)) == 0.0
    assert res.states[-1, 1] == pytest.approx(0.1 * 40.0)         # east drift = current x time
    assert res.states[-1, 0] == pytest.approx(U0 * 40.0, rel=1e-9)


def test_35deg_turn_is_bounded_and_loses_speed():
    s = build(_kosoko_scenario(controller={"type": "pid", "Kp": 0.0, "Ki": 0.0, "Kd": 0.0},
                               guidance={"changes": []}, environment={"constant_rudder_deg": 35.0},
                               duration=60.0))
    res = simulate_compiled(s)
    r, u = res.states[:, 5], res.states[:, 3]
    assert np.all(np.isfinite(res.states))
    assert abs(r[-1] - r[-200]) < 1e-3 * abs(r[-1])          # steady turn reached
    assert 0.2 * U0 < u[-1] < 0.8 * U0                      # speed drop in the turn
    diameter = 2 * math.hypot(u[-1], res.states[-1, 4]) / r[-1]
    assert 1.0 < diameter / KOSOKO.hull.L < 5.0              # paper Table 3: 4.24 m / 1.667 m = 2.5 L


# ------------------------------------------------------------------ batch: the Kosoko kernel vectorises

def test_kernel_follows_the_rpm_schedule_option_and_both_give_the_same_bits():
    """Without an rpm schedule the set-up picks mmg_rhs_constant_rate (no schedule look-up, so
    it vectorises); with one, mmg_rhs. For a record without a schedule the two are one body."""
    from steerlab.ships import mmg

    # the paper's ADRC: a designed one refuses Kosoko's full-scale default gear (gear.rate_max)
    ctrl = {"type": "adrc", "gains": "paper"}
    const = build(scenario_from_dict({"ship": {"model": "kosoko", "speed_kn": 0.97}, "controller": ctrl}))
    sched = build(scenario_from_dict({"ship": {"model": "kosoko", "speed_kn": 0.97,
                                               "options": {"rpm_schedule": [[0, 600], [5, 400]]}},
                                      "controller": ctrl}))
    assert const.ship.rhs is mmg.mmg_rhs_constant_rate and sched.ship.rhs is mmg.mmg_rhs
    assert get_ship("kosoko").rhs is mmg.mmg_rhs                  # the catalogue entry keeps the general one
    rng = np.random.default_rng(7)
    w = np.zeros(N_CHANNELS)
    for _ in range(300):
        x = rng.normal(size=6)
        w[W_WIND_SPEED], w[W_WIND_DIR] = rng.choice([0.0, 2.0]), rng.normal()
        a, b = np.zeros(6), np.zeros(6)
        d = 0.3 * rng.normal()
        mmg.mmg_rhs(3.0, x, d, w, const.ps, a)
        mmg.mmg_rhs_constant_rate(3.0, x, d, w, const.ps, b)
        np.testing.assert_array_equal(a, b)
    # a scheduled record through the general kernel does follow the schedule (600 -> 400 rpm)
    n_at = [propeller_rate(t, sched.ps) * 60.0 for t in (0.0, 2.5, 5.0, 9.0)]
    assert n_at == pytest.approx([600.0, 500.0, 400.0, 400.0])


@pytest.mark.skipif(not __import__("numba").config.LOOP_VECTORIZE, reason="numba's loop vectoriser is switched off")
def test_kosoko_batch_is_vectorised_and_bit_identical_to_single_runs():
    """With wind and current: the batch runs the Kosoko as vector arithmetic and run i of a
    batch equals the same run alone, bit for bit."""
    setup = build(scenario_from_dict({
        "dt": 0.05, "duration": 20.0, "ship": {"model": "kosoko", "speed_kn": 0.97},
        "controller": {"type": "pid", "Kp": 1.0, "Kd": 1.0, "Ki": 0.0},
        "environment": {"wind_speed": 1.5, "wind_dir_deg": 45.0, "current_speed": 0.05},
        "guidance": {"changes": [{"t": 2.0, "psi_deg": 20.0}]}}))
    final_single, final_batch, report = batch_parity_and_vectorisation(setup)
    np.testing.assert_array_equal(final_batch, final_single)
    assert report["vectorised_stages"] >= 4 and report["per_run_library_calls"] == []


def test_plain_arithmetic_wind_is_the_library_wind_to_rounding():
    """air_velocity_arith + wind_force_arith (no trigonometric call but one sincos; used by the
    vectorising kernel) against relative_wind + wind_force (C library), every direction,
    including calm air and dead astern."""
    from steerlab.environment.wind_fujiwara import air_velocity_arith, wind_force_arith

    c = fujiwara_coefficients(KOSOKO.wind_geometry())
    rng = np.random.default_rng(11)
    cases = [(rng.uniform(-1, 1), rng.uniform(-0.3, 0.3), rng.uniform(-4, 4), rng.uniform(0, 20), rng.uniform(-4, 4))
             for _ in range(2000)] + [(0.5, 0.0, 0.0, 0.0, 0.0), (0.0, 0.0, 0.3, 0.0, 1.0), (0.5, 0.0, 0.0, 3.0, math.pi)]
    for ug, vg, psi, ws, wf in cases:
        UR, psia = relative_wind(ug, vg, psi, ws, wf)
        ref = wind_force(c, 1.226, 0.233, 0.398, KOSOKO.hull.L, UR, psia)
        ua, va = air_velocity_arith(ug, vg, psi, ws, wf)
        got = wind_force_arith(c, 0, 1.226, 0.233, 0.398, KOSOKO.hull.L, ua, va)
        scale = 0.5 * 1.226 * UR * UR * 0.398 * KOSOKO.hull.L * 2.0 + 1e-300
        assert math.hypot(ua, va) == pytest.approx(UR, rel=1e-14, abs=1e-15)
        np.testing.assert_allclose(got, ref, rtol=0, atol=1e-13 * scale)
