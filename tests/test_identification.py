"""Identification recovers known parameters from records simulated with noise.

Records come from the simulator (closed-loop engine, or the engine's RK4 plant step with a
rate-limited steering gear), not from the identification's own response function, and carry
white measurement noise (yaw rate 0.02 deg/s, heading 0.1 deg, seeded). Stated tolerances:
first-order and second-order Nomoto 3 %; Norrbin and Bech dynamic parameters 5-10 %, the spiral
polynomial's dominant terms 5-10 %.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys

import numpy as np
import pytest

from steerlab.environment.channels import N_CHANNELS
from steerlab.errors import InputError
from steerlab.identification.fit import identify
from steerlab.identification.record import load_record, make_record, write_record
from steerlab.ships.catalogue import get_entry
from steerlab.ships.registry import get_ship
from steerlab.sim.engine import simulate
from steerlab.sim.kernels import plant_step
from steerlab.sim.scenario import scenario_from_dict
from steerlab.steering_gear import SteeringGear
from steerlab.units import knots_to_ms, rad

DEG = 180.0 / math.pi


def _noisy(t, delta, psi, r, seed=3):
    rng = np.random.default_rng(seed)
    return make_record(t, delta, psi + rng.normal(0, rad(0.1), t.size), r + rng.normal(0, rad(0.02), t.size))


def _open_loop_record(ship, speed, program, duration, dt=0.5, rate=2.5):
    spec = get_ship(ship)
    ps = spec.pack(speed, None, None)
    pg = SteeringGear(rad(35.0), rad(rate), 1.0, 0.0).pack()
    step = plant_step(spec.rhs)
    x = np.zeros(spec.n_states + 1)
    x[3] = speed
    w = np.zeros(N_CHANNELS)
    work = np.empty((5, x.size))
    n = int(duration / dt)
    X = np.empty((n + 1, x.size))
    X[0] = x
    for k in range(n):
        step(k * dt, x, program(k * dt, x), w, ps, pg, dt, work)
        X[k + 1] = x
    t = np.arange(n + 1) * dt
    return _noisy(t, X[:, -1], X[:, 2], X[:, 5])


def _zigzag(amp_deg):
    s = {"sign": 1.0}

    def program(t, x):
        if s["sign"] > 0 and x[2] >= rad(amp_deg):
            s["sign"] = -1.0
        elif s["sign"] < 0 and x[2] <= -rad(amp_deg):
            s["sign"] = 1.0
        return s["sign"] * rad(amp_deg)
    return program


def test_nomoto1_from_a_closed_loop_run_of_a_catalogue_ship():
    s = scenario_from_dict({"dt": 0.5, "duration": 900.0,
                            "ship": {"model": "frigate-nomoto-10deg", "speed_kn": 9.0 / 0.514444},
                            "controller": {"type": "pid", "Kp": 2.0, "Ki": 0.0, "Kd": 15.0},
                            "guidance": {"changes": [{"t": 10.0, "psi_deg": 30.0}, {"t": 300.0, "psi_deg": -20.0},
                                                     {"t": 600.0, "psi_deg": 10.0}]}})
    res = simulate(s)
    rec = _noisy(res.time, res.delta, res.psi, res.r)
    fit = identify(rec, "nomoto1")
    K, T = get_ship("frigate-nomoto-10deg").nomoto(9.0)
    assert fit.params["K"] == pytest.approx(K, rel=0.03)
    assert fit.params["T"] == pytest.approx(T, rel=0.03)
    for k in ("K", "T"):
        assert 0 < fit.ci95[k] < 0.05 * fit.params[k]
    assert fit.rms_yaw_rate_deg_s == pytest.approx(0.02, rel=0.2)   # residual = the noise


def test_nomoto2_from_heading_only():
    from steerlab.ships import nomoto2  # noqa: F401  (registers the generic ship)

    rec = _open_loop_record("nomoto2", 5.0, _zigzag(20.0), 1000.0)
    rec = make_record(rec.t, rec.delta, psi=rec.psi)          # drop the yaw rate
    fit = identify(rec, "nomoto2")
    assert fit.fitted_on == "heading"
    K, T1, T2, T3 = 0.1, 60.0, 8.0, 12.0                      # nomoto2 defaults
    assert fit.params["K"] == pytest.approx(K, rel=0.03)
    assert fit.params["T1"] == pytest.approx(T1, rel=0.03)
    # T2 and T3 are nearly a pole-zero pair: only T2 - T3 is well determined
    assert fit.params["T2"] - fit.params["T3"] == pytest.approx(T2 - T3, abs=0.5)


def test_norrbin_unstable_tanker_spiral_then_dynamics():
    """Morawski's 1:24 tanker (course-unstable): steady turns at +-5..30 deg, then a zig-zag."""
    v = knots_to_ms(3.1)
    levels = [5.0, -5.0, 10.0, -10.0, 20.0, -20.0, 30.0, -30.0]
    zz = _zigzag(15.0)

    def program(t, x):
        i = int(t // 400.0)
        return rad(levels[i]) if i < len(levels) else zz(t, x)
    rec = _open_loop_record("tanker-176k-model-norrbin", v, program, 400.0 * len(levels) + 600.0)
    fit = identify(rec, "norrbin")
    assert fit.spiral is not None and len(fit.spiral.points) == len(levels)
    c = dict(zip(get_entry("tanker-176k-model-norrbin").columns, get_entry("tanker-176k-model-norrbin").rows[0]))
    assert fit.params["n1"] == -1.0
    assert fit.params["K"] == pytest.approx(c["k_m"], rel=0.1)
    assert fit.params["T"] == pytest.approx(c["T_m"], rel=0.05)
    assert fit.params["n3"] / fit.params["K"] == pytest.approx(c["a3"] * DEG ** 2 / c["k_m"], rel=0.05)
    assert fit.params["n0"] * DEG == pytest.approx(c["a0"], rel=0.2)


def test_bech_without_spiral_from_zigzags_and_table_2_6_reading():
    """Small tanker, 9 m/s: recover a, b, T3 from a 20/20 zig-zag. Then the check behind the
    reading of Table 2.6's lost headings: a first-order Nomoto fitted to this model's 10/10
    zig-zag lands near the table's own Nomoto columns (K 0.07 1/s, tau 34 s)."""
    rec = _open_loop_record("small-tanker-bech", 9.0, _zigzag(20.0), 1500.0)
    fit = identify(rec, "bech")
    p = get_ship("small-tanker-bech").pack(9.0, None, None)
    assert fit.params["a"] == pytest.approx(p[0], rel=0.1)
    assert fit.params["b"] == pytest.approx(p[1], rel=0.1)
    assert fit.params["T3"] == pytest.approx(p[2], rel=0.1)
    assert fit.params["c3"] == pytest.approx(p[7], rel=0.1)
    zz = _open_loop_record("small-tanker-bech", 9.0, _zigzag(10.0), 1500.0)
    nom = identify(make_record(zz.t[600:], zz.delta[600:], zz.psi[600:], zz.r[600:]), "nomoto1")
    assert nom.params["K"] == pytest.approx(0.07, rel=0.35)
    assert nom.params["T"] == pytest.approx(34.0, rel=0.35)


def test_record_columns_and_errors(tmp_path):
    t = np.arange(100) * 0.5
    rec = make_record(t, rad(np.ones(100)), psi=np.zeros(100), r=np.zeros(100), speed=np.full(100, 5.0))
    p = write_record(tmp_path / "rec.csv", rec)
    back = load_record(p)
    np.testing.assert_allclose(back.delta, rec.delta)
    assert back.mean_speed == 5.0
    (tmp_path / "bad.csv").write_text("time [s],heading [deg]\n0,1\n1,2\n")
    with pytest.raises(InputError, match=r"record\.rudder"):
        load_record(tmp_path / "bad.csv")
    with pytest.raises(InputError, match=r"record\.time"):
        make_record(np.r_[t[:50], t[50:] * 1.1], np.zeros(100), r=np.zeros(100))
    with pytest.raises(InputError, match="heading or a yaw-rate"):
        make_record(t, np.zeros(100))


def test_cli_identify_on_steerlab_run_output(tmp_path):
    s = scenario_from_dict({"dt": 0.5, "duration": 600.0, "ship": {"model": "nomoto1", "options": {"K": 0.07, "T": 35.0}},
                            "controller": {"type": "pid", "Kp": 2.0, "Ki": 0.0, "Kd": 15.0},
                            "guidance": {"changes": [{"t": 10.0, "psi_deg": 30.0}, {"t": 300.0, "psi_deg": -20.0}]}})
    simulate(s).to_csv(tmp_path / "timeseries.csv")
    out = subprocess.run([sys.executable, "-m", "steerlab", "identify", str(tmp_path / "timeseries.csv"),
                          "--model", "nomoto1", "--json", "--out", str(tmp_path / "fit")],
                         capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    d = json.loads(out.stdout)
    vals = {p["name"]: p["value"] for p in d["parameters"]}
    assert vals["K"] == pytest.approx(0.07, rel=1e-3) and vals["T"] == pytest.approx(35.0, rel=1e-3)
    assert (tmp_path / "fit" / "fit.json").exists() and (tmp_path / "fit" / "fit.png").exists()
    bad = subprocess.run([sys.executable, "-m", "steerlab", "identify", str(tmp_path / "nope.csv"),
                          "--model", "bech", "--out", str(tmp_path / "x")], capture_output=True, text=True)
    assert bad.returncode == 2 and "record" in bad.stderr and not (tmp_path / "x").exists()
