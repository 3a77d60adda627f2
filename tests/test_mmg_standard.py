"""MMG standard method (KVLCC2), the original MSS tanker, the kvlcc2-validation experiment, the Kosoko slipstream check.

Numbers asserted here are the ones steerlab computes (this branch), with tolerances that say
what would count as a change of model rather than of rounding:

* KVLCC2 35 deg turn, 15.5 kn, 2.32 deg/s gear: advance 3.08 L, tactical diameter 3.11 L
  (starboard), 3.09 / 3.09 L (port). Tolerance 1 %: the trial interpolates the 90/180 deg
  crossings on a 0.1 s grid (about 0.1 % of L); a 1 % move means the forces changed.
* The L7 model at the free-running test's conditions (U0 1.179 m/s, 15.68 deg/s, self-propulsion
  11.85 rev/s): 3.08 / 3.12 L starboard, 3.09 / 3.10 L port; YY2015 Table 4's test is 3.25 /
  3.34 and 3.11 / 3.08; a lower propeller rate widens the turn.
* 10/10 zig-zag: overshoots 5.0 / 14.0 deg, 20/20: 10.6 / 15.9 deg (0.3 deg tolerance: the
  overshoot is read at the heading's turning point on the 0.1 s grid).
* Froude scaling: the 7 m model (fresh water) and the 320 m ship give the same advance/L and
  tactical/L within 0.5 % (x_G is 11.2 m, not 11.4 m = 0.25 m x 45.7).
* MSS tanker vs esso, 20 deg rudder at 80 rpm from 16 kn: the original's steady rate of turn
  is 40-55 % higher (issue 16 says about 45 %; steerlab gets +47 % starboard, +51 % port).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from steerlab.environment.channels import N_CHANNELS
from steerlab.errors import InputError
from steerlab.ships import esso_3dof, mmg, mmg_standard as ms, mss_tanker as mt
from steerlab.ships.registry import SHIPS


def rk4_run(rhs, p, u0, rudder, T, dt, v0=0.0):
    """Open loop, ideal rudder ``rudder(t)`` [rad]; returns the state history (N, nx)."""
    nx = mt.N_STATES if rhs is mt.tanker_rhs else 6
    w = np.zeros(N_CHANNELS)
    x = np.zeros(nx)
    x[3], x[4] = u0, v0
    out = np.empty((int(round(T / dt)) + 1, nx))
    out[0] = x
    k1, k2, k3, k4 = (np.zeros(nx) for _ in range(4))
    for k in range(1, out.shape[0]):
        t = (k - 1) * dt
        d = rudder(t)
        rhs(t, x, d, w, p, k1)
        rhs(t, x + 0.5 * dt * k1, d, w, p, k2)
        rhs(t, x + 0.5 * dt * k2, d, w, p, k3)
        rhs(t, x + dt * k3, d, w, p, k4)
        x = x + dt / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
        out[k] = x
    return out


# ------------------------------------------------------------------ MMG standard: physics

KV = ms.get_mmgstd_data("kvlcc2")
U_SERVICE = 15.5 * 1852.0 / 3600.0


from conftest import batch_parity_and_vectorisation  # noqa: E402


def test_registered_ships_and_source():
    for name in ("kvlcc2", "kvlcc2-l7", "mss-tanker"):
        assert name in SHIPS
    assert "Yasukawa" in SHIPS["kvlcc2"].source and "tanker.m" in SHIPS["mss-tanker"].source


def test_straight_run_is_steady_at_the_self_propulsion_rate():
    n = ms.propeller_rate_for_speed(U_SERVICE, KV)
    # (1 - t_P) T = R at the straight-ahead wake
    assert (1 - KV.propeller.t_P) * ms.thrust(U_SERVICE, n, KV) == pytest.approx(ms.resistance(U_SERVICE, KV), rel=1e-12)
    X = rk4_run(ms.mmgstd_rhs, ms.pack(KV, n), U_SERVICE, lambda t: 0.0, 600.0, 1.0)
    assert np.max(np.abs(X[:, 3] - U_SERVICE)) < 1e-9
    assert np.max(np.abs(X[:, 2])) == 0.0 and np.max(np.abs(X[:, 5])) == 0.0
    assert 60 * n == pytest.approx(60 * 11.855 / math.sqrt(45.714), rel=2e-3)   # Froude-scaled model rate


def test_turn_rate_sign_speed_loss_and_near_symmetry():
    n = ms.propeller_rate_for_speed(U_SERVICE, KV)
    p = ms.pack(KV, n)
    ramp = math.radians(2.32)
    stb = rk4_run(ms.mmgstd_rhs, p, U_SERVICE, lambda t: min(math.radians(35), ramp * t), 1500.0, 1.0)
    prt = rk4_run(ms.mmgstd_rhs, p, U_SERVICE, lambda t: -min(math.radians(35), ramp * t), 1500.0, 1.0)
    assert np.all(stb[20:, 5] > 0) and np.all(prt[20:, 5] < 0)          # starboard rudder turns to starboard
    assert stb[-1, 4] < 0 < prt[-1, 4]                                   # drifts out of the turn
    assert 0.3 < stb[-1, 3] / U_SERVICE < 0.6                            # turning speed loss (about 0.38 U0)
    # asymmetric data (gamma_R, C_2): the port turn settles 3.2 % faster (gamma_R = 0.395 there
    # straightens the rudder inflow less than 0.640 to starboard), not more than 5 %
    assert abs(prt[-1, 5]) / stb[-1, 5] == pytest.approx(1.032, abs=0.01)


def test_rudder_gamma_asymmetry_is_what_it_says():
    """With gamma_R and C_2 made equal the response mirrors exactly."""
    d = KV.model_copy(update={
        "rudder": KV.rudder.model_copy(update={"gamma_R_minus": KV.rudder.gamma_R_plus}),
        "propeller": KV.propeller.model_copy(update={"C_2_minus": KV.propeller.C_2_plus})})
    p = ms.pack(d, ms.propeller_rate_for_speed(U_SERVICE, d))
    a = rk4_run(ms.mmgstd_rhs, p, U_SERVICE, lambda t: math.radians(20), 300.0, 1.0)
    b = rk4_run(ms.mmgstd_rhs, p, U_SERVICE, lambda t: -math.radians(20), 300.0, 1.0)
    np.testing.assert_allclose(b[:, 5], -a[:, 5], rtol=1e-9, atol=1e-15)
    assert SHIPS["kvlcc2"].symmetric(U_SERVICE) is False


def test_linearisation_is_the_kernel_jacobian():
    A, B = ms.linearise_data(KV, U_SERVICE)
    assert A.shape == (2, 2) and B.shape == (2,)
    assert B[1] > 0            # steerlab sign: starboard rudder gives starboard yaw acceleration
    # KVLCC2 is (slightly) course-unstable in the linear sense: one positive eigenvalue
    assert np.max(np.linalg.eigvals(A).real) > 0 > np.min(np.linalg.eigvals(A).real)


# ------------------------------------------------------------------ KVLCC2 trials (the published-number checks)

@pytest.fixture(scope="module")
def kv_trials():
    from steerlab.experiments import kvlcc2_validation as kv

    return kv.trials("kvlcc2"), kv.trials("kvlcc2-l7")


def test_kvlcc2_turning_and_zigzag_numbers(kv_trials):
    nd = kv_trials[0]["nd"]
    assert nd["advance_starboard"] == pytest.approx(3.08, rel=0.01)
    assert nd["tactical_starboard"] == pytest.approx(3.11, rel=0.01)
    assert nd["advance_port"] == pytest.approx(3.09, rel=0.01)
    assert nd["tactical_port"] == pytest.approx(3.09, rel=0.01)
    assert nd["zz10_first"] == pytest.approx(5.0, abs=0.3)
    assert nd["zz10_second"] == pytest.approx(14.0, abs=0.3)
    assert nd["zz20_first"] == pytest.approx(10.6, abs=0.3)
    assert nd["zz20_second"] == pytest.approx(15.9, abs=0.3)


@pytest.fixture(scope="module")
def kv_tank():
    """kvlcc2-l7 at the free-running test's conditions, two rates of the sensitivity table."""
    from steerlab.experiments import kvlcc2_validation as kv

    saved = kv.SENSITIVITY_RPS
    kv.SENSITIVITY_RPS = (11.0, 12.5)
    try:
        return kv.tank_trials()
    finally:
        kv.SENSITIVITY_RPS = saved


def test_kvlcc2_l7_at_the_test_conditions(kv_tank):
    """U0 1.179 m/s, 15.68 deg/s, self-propulsion 11.85 rev/s: 3.08/3.12 L starboard,
    3.09/3.10 L port (issue 32's measurement); YY2015 Table 4's test: 3.25/3.34, 3.11/3.08."""
    assert kv_tank["n_sp"] == pytest.approx(11.85, abs=0.01)
    nd = kv_tank["nd"]
    assert nd["advance_starboard"] == pytest.approx(3.08, rel=0.01)
    assert nd["tactical_starboard"] == pytest.approx(3.12, rel=0.01)
    assert nd["advance_port"] == pytest.approx(3.09, rel=0.01)
    assert nd["tactical_port"] == pytest.approx(3.10, rel=0.01)


def test_a_lower_propeller_rate_widens_the_turn(kv_tank):
    """Less thrust, slower rudder inflow: 1.5 rev/s less widens advance by 0.1-0.2 L."""
    (n1, lo), (n2, hi) = kv_tank["sensitivity"]
    assert n1 < n2
    for key in ("advance_starboard", "tactical_starboard", "advance_port", "tactical_port"):
        assert lo[key] > hi[key]
    assert 0.1 < lo["advance_starboard"] - hi["advance_starboard"] < 0.2


def test_published_rows_and_reasons(kv_trials, kv_tank, monkeypatch):
    """Table 4 and 6 values with their source; every turn more than 5 % off carries its measured
    cause; without a reason the experiment stops; no typed-in values of another code remain."""
    from steerlab.experiments import kvlcc2_validation as kv

    full, model = kv_trials
    rows = kv.comparison_rows(full, model, kv_tank)
    pub = {r["quantity"]: r for r in rows if r["quantity"].startswith(("free-running", "their"))}
    assert len(pub) == 12
    assert pub["free-running test (YY2015 Table 4): 35 deg turn to starboard: advance / L"]["paper"] == 3.25
    assert pub["their full-scale simulation (YY2015 Table 6): 35 deg turn to port: tactical diameter / L"]["paper"] == 3.59
    for r in pub.values():
        gap = abs(r["steerlab"] - r["paper"]) / r["paper"]
        assert "Table" in r["note"] and "DyadShip" in r["note"]
        assert ("not reproduced within 5 %" in r["note"]) == (gap > 0.05)
    starboard_test = pub["free-running test (YY2015 Table 4): 35 deg turn to starboard: advance / L"]["note"]
    assert "propeller rate" in starboard_test and "asymmetry" in starboard_test
    assert not any("open-source" in r["quantity"] for r in rows)
    assert sum(r["quantity"].startswith("propeller-rate sensitivity") for r in rows) == 8
    monkeypatch.setattr(kv, "WHY_NOT", {})
    with pytest.raises(ValueError, match="WHY_NOT"):
        kv.comparison_rows(full, model, kv_tank)


def test_froude_scaling_model_and_ship_agree(kv_trials):
    full, model = kv_trials[0]["nd"], kv_trials[1]["nd"]
    for key in ("advance_starboard", "tactical_starboard", "advance_port", "tactical_port"):
        assert model[key] == pytest.approx(full[key], rel=0.005)


def test_experiment_is_registered():
    from steerlab.experiments import EXPERIMENTS
    from steerlab.experiments import kvlcc2_validation as kv

    assert EXPERIMENTS["kvlcc2-validation"] is kv


# ------------------------------------------------------------------ bad input

GOOD = (ms.resources.files("steerlab.ships") / "data" / "mmgstd_kvlcc2.toml").read_text(encoding="utf-8")


@pytest.mark.parametrize("line,repl,field", [
    ("Y_v = -0.315", "Y_v = nan", "hull.Y_v"),
    ("N_r = -0.049", "N_r = 0.049", "hull.N_r"),
    ("t_R = 0.387", "t_R = 1.5", "rudder.t_R"),
    ("kappa = 0.50", "", "rudder.kappa"),
    ("w_P0 = 0.40", "w_P0 = inf", "propeller.w_P0"),
])
def test_bad_data_is_refused_naming_the_field(line, repl, field):
    assert line in GOOD
    with pytest.raises(InputError) as e:
        ms.load_mmgstd_data(GOOD.replace(line, repl), "x.toml")
    assert field in e.value.field and "\n" not in str(e.value)


def test_bad_kt_and_speed_range_refused():
    with pytest.raises(InputError, match="k0"):
        ms.load_mmgstd_data(GOOD.replace("kt = [0.2931", "kt = [-0.2931"), "x.toml")
    with pytest.raises(InputError, match="speed_range"):
        ms.load_mmgstd_data(GOOD.replace("speed_range_m_s = [2.0, 10.8]", "speed_range_m_s = [3.0, 1.0]"), "x.toml")


def test_speed_outside_the_data_validity_is_refused():
    from steerlab.trials.runner import TrialConditions

    with pytest.raises(InputError, match="validity range"):
        TrialConditions(ship="kvlcc2", speed_kn=30.0).resolved()
    with pytest.raises(InputError, match="depth_m"):
        SHIPS["mss-tanker"].options({"depth_m": 18.0})


# ------------------------------------------------------------------ MSS tanker vs esso

def test_mss_tanker_straight_equilibrium_at_80_rpm():
    n, v0, d0 = mt.straight_equilibrium(8.23)
    assert 60 * n == pytest.approx(80.0, abs=0.1)             # tanker.m: nominal 80 rpm at 8.23 m/s
    assert d0 != 0.0 and abs(math.degrees(d0)) < 1.0          # the propeller's side moment needs a little rudder
    X = rk4_run(mt.tanker_rhs, mt.pack(n), 8.23, lambda t: d0, 300.0, 1.0, v0=v0)
    assert np.max(np.abs(X[:, 5])) < 1e-12 and np.max(np.abs(X[:, 3] - 8.23)) < 1e-9
    # without that rudder it turns by itself (to port: NT < 0)
    X0 = rk4_run(mt.tanker_rhs, mt.pack(n), 8.23, lambda t: 0.0, 300.0, 1.0)
    assert X0[-1, 5] < -1e-6


def _steady_rate(rhs, p, deg):
    X = rk4_run(rhs, p, 8.23, lambda t: math.radians(deg), 3000.0, 0.5)
    return float(np.mean(X[-200:, 5]))


def test_mss_tanker_shaft_dynamics_follow_the_rpm_command():
    """rpm_schedule 80 -> 40 rpm at t = 100 s: the shaft lags with T_m = 50 s, the ship slows."""
    spec = SHIPS["mss-tanker"]
    opts = spec.options({"rpm_schedule": [[0, 80], [100, 80], [100, 40]]})
    p = spec.pack(8.23, 80.0, opts)
    X = rk4_run(mt.tanker_rhs, p, 8.23, lambda t: mt.straight_equilibrium(8.23, n_rps=80 / 60)[2], 400.0, 0.5)
    n = 80 / 60 + X[:, 6]
    assert np.all(np.abs(n[:200] - 80 / 60) < 1e-12)                       # constant before the step
    k = 200 + 100                                                         # t = 150 s: 50 s = T_m after the step
    assert n[k] == pytest.approx(40 / 60 + (40 / 60) * math.exp(-1.0), rel=1e-3)
    assert X[-1, 3] < 8.23 - 1.0                                           # a heavy ship slows slowly (6.66 m/s)
    with pytest.raises(InputError, match="rpm_schedule"):
        spec.options({"rpm_schedule": [[0, 90]]})
    with pytest.raises(InputError, match="shaft_time_constant_s"):
        spec.options({"shaft_time_constant_s": 0.0})


def test_mss_tanker_turns_about_45_percent_faster_than_the_paper_form():
    n = 80.0 / 60.0
    for deg in (20.0, -20.0):
        orig = _steady_rate(mt.tanker_rhs, mt.pack(n), deg)
        paper = _steady_rate(esso_3dof.esso_rhs, esso_3dof.pack(n_rps=n), deg)
        assert np.sign(orig) == np.sign(paper) == np.sign(deg)
        assert 1.40 < orig / paper < 1.55, (deg, orig / paper)


def test_mss_tanker_shallow_water_turns_wider():
    """Steady 20 deg turn at 80 rpm: diameter 2U/r grows as the keel clearance shrinks
    (deep 2.95 L, h = 25 m 3.08 L, h = 20 m 14.9 L: the Yuvz term switches on for z >= 0.8)."""
    def diameter(depth):
        X = rk4_run(mt.tanker_rhs, mt.pack(80.0 / 60.0, depth_m=depth), 8.23, lambda t: math.radians(20), 3000.0, 0.5)
        return 2.0 * math.hypot(X[-1, 3], X[-1, 4]) / X[-1, 5] / mt.COEF.L

    deep, h25, h20 = diameter(None), diameter(25.0), diameter(20.0)
    assert deep == pytest.approx(2.95, abs=0.02)
    assert deep < h25 < h20 and h20 > 4 * deep


def test_mss_tanker_kernel_equals_an_independent_rederivation_of_the_published_equations():
    """tanker_rhs (steerlab sign, packed record) vs the plain-Python transcription of MSS tanker.m's
    equations (MSS sign) at random states, deep and shallow water (both sides of z = 0.8)."""
    from steerlab.environment.channels import N_CHANNELS
    from steerlab.experiments import tanker_reference as tr

    rng = np.random.default_rng(16)
    w = np.zeros(N_CHANNELS)
    for depth in (None, 60.0, 25.0, 20.0):
        p_by_n = {}
        for _ in range(100):
            u, v, r = rng.uniform(1.0, 9.0), rng.uniform(-2.0, 2.0), rng.uniform(-0.01, 0.01)
            d, n = rng.uniform(-0.6, 0.6), round(rng.uniform(0.3, 1.4), 2)
            p = p_by_n.setdefault(n, mt.pack(n, depth_m=depth))
            x = np.zeros(mt.N_STATES)
            x[mt.IU], x[mt.IV], x[mt.IR] = u, v, r
            dx = np.zeros(mt.N_STATES)
            mt.tanker_rhs(0.0, x, d, w, p, dx)
            ref = tr.accelerations(u, v, r, -d, n, depth)
            np.testing.assert_allclose(dx[mt.IU:mt.IR + 1], ref, rtol=1e-11, atol=1e-16)
    # the two drift-angle forms differ only through beta: equal with v = 0, not with drift
    assert tr.accelerations(8.0, 0.0, 0.003, 0.3, 1.3, beta_form="ratio") == tr.accelerations(8.0, 0.0, 0.003, 0.3, 1.3)
    assert tr.accelerations(8.0, 2.0, 0.003, 0.3, 1.3, beta_form="ratio") != tr.accelerations(8.0, 2.0, 0.003, 0.3, 1.3)


def test_the_four_planar_kernels_share_one_start():
    """kinematics.planar_start: track rates (current included), psi' = r, d = delta + equivalent
    rudder; esso, mmg, mmg_standard and mss_tanker call it (one definition of the preamble)."""
    import inspect

    from steerlab.environment.channels import W_CURRENT_E, W_CURRENT_N, W_RUDDER
    from steerlab.ships import kinematics
    from steerlab.ships.state import IPSI, IX, IY

    x = np.array([5.0, 7.0, math.radians(30.0), 4.0, -0.5, 0.01])
    w = np.zeros(N_CHANNELS)
    w[W_RUDDER], w[W_CURRENT_N], w[W_CURRENT_E] = 0.02, 0.3, -0.2
    dx = np.zeros(6)
    psi, u, v, r, d = kinematics.planar_start(x, 0.1, w, dx)
    assert (psi, u, v, r) == (x[2], 4.0, -0.5, 0.01) and d == 0.1 + 0.02
    c, s = math.cos(x[2]), math.sin(x[2])
    assert dx[IX] == pytest.approx(4.0 * c + 0.5 * s + 0.3, rel=1e-14)
    assert dx[IY] == pytest.approx(4.0 * s - 0.5 * c - 0.2, rel=1e-14)
    assert dx[IPSI] == 0.01
    for kernel in (esso_3dof.esso_rhs, mmg._mmg_derivatives, ms.mmgstd_rhs, mt.tanker_rhs):
        src = inspect.getsource(kernel.py_func)
        assert "planar_start(x, delta, w, dx)" in src and "earth_velocity" not in src, kernel


# ------------------------------------------------------------------ Kosoko: slipstream refusal

def test_kosoko_slipstream_that_would_drive_the_turn_astern_is_refused():
    text = (ms.resources.files("steerlab.ships") / "data" / "mmg_kosoko.toml").read_text(encoding="utf-8")
    assert "slipstream = 0.0 " in text
    with pytest.raises(InputError) as e:
        mmg.load_mmg_data(text.replace("slipstream = 0.0 ", "slipstream = 0.626 "), "k.toml")
    assert e.value.field == "k.toml: rudder.slipstream" and "1.44" in str(e.value)
    assert mmg.slipstream_drag_ratio(mmg.get_mmg_data("kosoko")) == pytest.approx(1.443, rel=1e-3)


# ------------------------------------------------------------------ esso-models experiment

def test_esso_models_experiment(tmp_path):
    import json

    from steerlab.experiments import EXPERIMENTS
    from steerlab.experiments import esso_models as em

    assert EXPERIMENTS["esso-models"] is em
    rows = em.run(tmp_path / "out")
    assert json.loads((tmp_path / "out" / "comparison.json").read_text()) == rows
    by = {r["quantity"]: r for r in rows}
    rate = by["20 deg rudder held: steady rate of turn"]
    assert rate["paper"] == pytest.approx(0.280, abs=0.003)          # esso, deg/s
    assert rate["steerlab"] / rate["paper"] == pytest.approx(1.47, abs=0.03)
    # the first 180 deg are tighter in the paper's form (stronger rudder at the approach speed)
    tac = by["35 deg turn to starboard: tactical diameter / L"]
    assert tac["paper"] < tac["steerlab"]
    # the original is asymmetric (propeller side force), the paper's form is not
    assert by["35 deg turn to port: advance / L"]["paper"] == pytest.approx(
        by["35 deg turn to starboard: advance / L"]["paper"], rel=1e-9)
    assert by["35 deg turn to port: advance / L"]["steerlab"] != pytest.approx(
        by["35 deg turn to starboard: advance / L"]["steerlab"], rel=1e-3)
    # cross-check rows: the kernel = the independent re-derivation (to rounding), the PVS beta form is not
    cross = [r for r in rows if r["quantity"].startswith("original model cross-check")]
    assert len(cross) == len(em.CROSS_CHECKS) == 6
    for r in cross:
        assert "80 rpm" in r["note"] and "rudder held" in r["note"]
        if "PythonVehicleSimulator's beta" in r["quantity"]:
            assert r["steerlab"] / r["paper"] == pytest.approx(0.972, abs=0.005)
        else:
            assert r["steerlab"] == pytest.approx(r["paper"], rel=1e-10)
    steady20 = by["original model cross-check: 20 deg rudder held, deep water: steady turning diameter / L"]
    assert steady20["paper"] == pytest.approx(2.95, abs=0.01)          # as test_mss_tanker_shallow_water_turns_wider
    assert by["original model cross-check: 35 deg rudder to port held, deep water: steady rate of turn"]["paper"] < 0
    for f in ("esso_turning_track.png", "mss-tanker_turning_track.png", "mss-tanker_10_10_zigzag.png"):
        assert (tmp_path / "out" / f).stat().st_size > 10_000


# ------------------------------------------------------------------ batch: vectorised and bit-identical

@pytest.mark.skipif(not __import__("numba").config.LOOP_VECTORIZE, reason="numba's loop vectoriser is switched off")
def test_kvlcc2_batch_is_vectorised_and_bit_identical_to_single_runs():
    """mmgstd_rhs uses steerlab.vecmath (atan2, exp) and sincos: no library call, so the batch
    engine runs it as vector arithmetic; run i of a batch equals the same run alone."""
    from steerlab.sim.scenario import scenario_from_dict
    from steerlab.sim.setup import build

    setup = build(scenario_from_dict({
        "dt": 0.5, "duration": 120.0, "ship": {"model": "kvlcc2", "speed_kn": 15.5},
        "controller": {"type": "pid", "Kp": 1.0, "Kd": 10.0, "Ki": 0.0},
        "guidance": {"changes": [{"t": 5.0, "psi_deg": 15.0}]}}))
    final_single, final_batch, report = batch_parity_and_vectorisation(setup)
    np.testing.assert_array_equal(final_batch, final_single)
    assert report["vectorised_stages"] >= 4 and report["per_run_library_calls"] == []
