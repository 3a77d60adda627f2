"""Performance indices on synthetic arrays with known answers."""

import math
from pathlib import Path

import numpy as np
import pytest

from steerlab.metrics import (compute_metrics, integral_metrics, last_setpoint_change, settling_time,
                              speed_loss_J, step_metrics)
from steerlab.metrics_online import (M_ABS_DELTA, M_D2_DEG, M_DURATION, M_E2_DEG, M_IAE, M_ISE, M_ITAE,
                                     M_MAX_ABS_E, M_REVERSALS, M_TRAVEL, accumulate, new_accumulator,
                                     online_metrics_from_result)
from steerlab.sim.engine import simulate_compiled, simulate_readable
from steerlab.sim.result import Result
from steerlab.sim.setup import build

R2D = 180.0 / math.pi


def _acc(e, delta, dt):
    """Accumulate arrays e[k], delta[k] over steps k = 0..N-1 (delta[N] is the final rudder)."""
    acc = new_accumulator()
    for k in range(len(e) - 1):
        accumulate(acc, k * dt, e[k], delta[k], delta[k + 1], dt)
    return acc


def _result(time, psi, psi_ref, delta=None, u=None):
    n = len(time)
    delta = np.zeros(n) if delta is None else delta
    cols, names = [psi, delta], ["psi", "delta"]
    if u is not None:
        cols, names = [psi, u, np.zeros(n), delta], ["psi", "u", "v", "delta"]
    return Result(time=time, states=np.column_stack(cols), state_names=tuple(names),
                  state_units=tuple("-" for _ in names), delta_cmd=delta.copy(), psi_ref=psi_ref,
                  r_ref=np.zeros(n), disturbance=np.zeros((n, 1)))


# ---------------------------------------------------------------- integral indices

@pytest.mark.parametrize("e0", [0.01, -0.02])
def test_constant_error_integrals(e0):
    N, dt = 1000, 0.1
    T = N * dt
    e = np.full(N + 1, e0)
    acc = _acc(e, np.zeros(N + 1), dt)
    assert acc[M_IAE] == pytest.approx(abs(e0) * T, rel=1e-12)
    assert acc[M_ISE] == pytest.approx(e0**2 * T, rel=1e-12)
    # rectangle rule: sum_k t_k |e| dt = |e| dt^2 N (N - 1) / 2 (continuous: |e| T^2 / 2)
    assert acc[M_ITAE] == pytest.approx(abs(e0) * dt**2 * N * (N - 1) / 2, rel=1e-12)
    assert acc[M_ITAE] == pytest.approx(abs(e0) * T**2 / 2, rel=2e-3)
    assert acc[M_DURATION] == pytest.approx(T, rel=1e-12)
    assert acc[M_MAX_ABS_E] == abs(e0)
    assert acc[M_TRAVEL] == 0.0 and acc[M_REVERSALS] == 0.0
    m = integral_metrics(acc)
    assert m["iae_deg_s"] == pytest.approx(abs(e0) * T * R2D, rel=1e-12)
    assert m["ise_deg2_s"] == pytest.approx(e0**2 * T * R2D**2, rel=1e-12)
    assert m["max_abs_error_deg"] == pytest.approx(abs(e0) * R2D)


def test_ramp_error_integrals():
    # e_k = a k dt: IAE = a dt^2 N(N-1)/2, ISE = a^2 dt^3 sum k^2
    N, dt, a = 500, 0.2, 1e-3
    k = np.arange(N + 1)
    e = a * k * dt
    acc = _acc(e, np.zeros(N + 1), dt)
    kk = np.arange(N)
    assert acc[M_IAE] == pytest.approx(a * dt**2 * N * (N - 1) / 2, rel=1e-12)
    assert acc[M_ISE] == pytest.approx(a**2 * dt**3 * np.sum(kk**2.0), rel=1e-12)
    assert acc[M_ITAE] == pytest.approx(a * dt**3 * np.sum(kk**2.0), rel=1e-12)
    assert acc[M_MAX_ABS_E] == pytest.approx(a * (N - 1) * dt)   # e_N is not integrated


@pytest.mark.parametrize("lam", [0.1, 0.5])
def test_speed_loss_J(lam):
    N, dt = 2000, 0.1
    T = N * dt
    e = np.full(N + 1, math.radians(2.0))
    d = np.full(N + 1, math.radians(-5.0))
    acc = _acc(e, d, dt)
    assert acc[M_E2_DEG] == pytest.approx(4.0 * T, rel=1e-12)
    assert acc[M_D2_DEG] == pytest.approx(25.0 * T, rel=1e-12)
    assert speed_loss_J(acc, lam) == pytest.approx(0.0076 * (4.0 + lam * 25.0), rel=1e-12)
    m = integral_metrics(acc, lam)
    assert m["speed_loss_J"] == pytest.approx(0.0076 * (4.0 + lam * 25.0), rel=1e-12)
    assert m["lambda"] == lam
    assert m["mean_abs_rudder_deg"] == pytest.approx(5.0, rel=1e-12)
    assert acc[M_ABS_DELTA] == pytest.approx(math.radians(5.0) * T, rel=1e-12)
    assert math.isnan(speed_loss_J(new_accumulator()))


def _zigzag(legs, amp, n_leg, hold=0):
    """Triangle wave 0 -> +amp -> -amp -> ... with ``legs`` monotone legs and optional holds."""
    out = [0.0]
    target = amp
    cur = 0.0
    for i in range(legs):
        seg = np.linspace(cur, target, n_leg + 1)[1:]
        out.extend(seg)
        out.extend([target] * hold)
        cur = target
        target = -target
    return np.array(out)


@pytest.mark.parametrize("legs, hold", [(1, 0), (2, 0), (7, 0), (7, 15)])
def test_rudder_reversals_and_travel(legs, hold):
    amp = math.radians(10.0)
    d = _zigzag(legs, amp, 40, hold)
    acc = _acc(np.zeros(len(d)), d, 0.1)
    assert acc[M_REVERSALS] == legs - 1
    expected_travel = amp + (legs - 1) * 2 * amp
    assert acc[M_TRAVEL] == pytest.approx(expected_travel, rel=1e-12)
    assert integral_metrics(acc)["rudder_reversals"] == legs - 1


def test_pause_then_same_direction_is_not_a_reversal():
    up = np.linspace(0.0, 0.1, 11)
    d = np.concatenate([up, np.full(10, 0.1), up[1:] + 0.1, up[::-1][1:] + 0.1])
    acc = _acc(np.zeros(len(d)), d, 0.1)
    assert acc[M_REVERSALS] == 1
    # moves below REVERSAL_EPS are ignored (numerical jitter is not a reversal)
    jitter = 1e-12 * np.sin(np.arange(200))
    acc = _acc(np.zeros(200), jitter, 0.1)
    assert acc[M_REVERSALS] == 0


# ---------------------------------------------------------------- step metrics

def _second_order(t, zeta, wn):
    wd = wn * math.sqrt(1 - zeta**2)
    return 1 - np.exp(-zeta * wn * t) * (np.cos(wd * t) + zeta / math.sqrt(1 - zeta**2) * np.sin(wd * t))


def _last_crossing(f, level, t_max, dt=1e-3):
    """Last t in (0, t_max) with |f(t) - 1| = level (dense scan + brentq)."""
    t = np.arange(dt, t_max, dt)
    g = np.abs(f(t) - 1.0) - level
    idx = np.nonzero(np.sign(g[:-1]) != np.sign(g[1:]))[0][-1]
    from scipy.optimize import brentq     # here, not at collection (every pytest worker collects)

    return brentq(lambda s: abs(f(s) - 1.0) - level, t[idx], t[idx + 1])


def _first_crossing(f, level, t_max, dt=1e-3):
    t = np.arange(0.0, t_max, dt)
    idx = np.nonzero(f(t) >= level)[0][0]
    from scipy.optimize import brentq

    return brentq(lambda s: f(s) - level, t[idx - 1], t[idx])


@pytest.mark.parametrize("step_deg", [20.0, -20.0])
def test_step_metrics_second_order(step_deg):
    zeta, wn, dt, tc = 0.5, 0.5, 0.01, 10.0
    time = np.arange(0.0, 120.0 + dt / 2, dt)
    step = math.radians(step_deg)
    psi_ref = np.where(time >= tc - dt / 2, step, 0.0)
    tau = np.clip(time - tc, 0.0, None)
    psi = step * _second_order(tau, zeta, wn)
    m = step_metrics(time, psi, psi_ref)
    f = lambda s: _second_order(s, zeta, wn)
    over = math.exp(-zeta * math.pi / math.sqrt(1 - zeta**2))
    assert m["overshoot_pct"] == pytest.approx(100 * over, abs=1e-3)
    assert m["overshoot_deg"] == pytest.approx(over * abs(step_deg), abs=1e-4)
    rise = _first_crossing(f, 0.9, 50) - _first_crossing(f, 0.1, 50)
    assert m["rise_time_s"] == pytest.approx(rise, abs=2 * dt)
    ts2 = _last_crossing(f, 0.02, 100)
    assert ts2 <= m["settling_time_2pct_s"] <= ts2 + dt + 1e-9
    ts1 = _last_crossing(f, 1.0 / abs(step_deg), 100)
    assert ts1 <= m["settling_time_1deg_s"] <= ts1 + dt + 1e-9
    assert 10.0 < m["settling_time_2pct_s"] < 25.0      # ~ 4 / (zeta wn) = 16 s


def test_step_metrics_no_overshoot_and_not_settled():
    dt = 0.1
    time = np.arange(0.0, 100.0 + dt / 2, dt)
    psi_ref = np.where(time >= 5.0 - dt / 2, 0.2, 0.0)
    psi = 0.2 * (1 - np.exp(-np.clip(time - 5.0, 0, None) / 5.0))          # first order, tau 5 s
    m = step_metrics(time, psi, psi_ref)
    assert m["overshoot_pct"] == 0.0 and m["overshoot_deg"] == 0.0
    assert m["rise_time_s"] == pytest.approx(5.0 * math.log(9.0), abs=2 * dt)
    assert m["settling_time_2pct_s"] == pytest.approx(5.0 * math.log(50.0), abs=dt + 1e-9)
    # a response that never reaches the band has no settling time
    m = step_metrics(time, 0.5 * psi, psi_ref)
    assert m["settling_time_2pct_s"] is None and m["settling_time_1deg_s"] is None


def test_step_metrics_without_setpoint_change():
    dt = 0.1
    time = np.arange(0.0, 60.0 + dt / 2, dt)
    e0 = math.radians(5.0)
    psi = -e0 * np.exp(-time / 10.0)                                   # e = 5 deg e^{-t/10}
    m = step_metrics(time, psi, np.zeros_like(time))
    # nothing to measure a step response from: every step metric is n/a (not "from t = 0")
    assert all(v is None for v in m.values()), m
    assert all(v is None for v in step_metrics(time, np.zeros_like(time), np.zeros_like(time)).values())
    # the rejection of a disturbance is timed explicitly from its onset
    assert settling_time(time, psi, math.radians(1.0), t0=0.0) == pytest.approx(10.0 * math.log(5.0),
                                                                                abs=dt + 1e-9)


def test_step_metrics_of_the_calm_default_run_agree_with_python_control_step_info():
    """The default scenario up to 0.1.0 (``examples/scenarios/calm_default.toml``: Esso + ADRC,
    20 deg change at t = 100 s, eq (39) noise): overshoot, 10-90 % rise and 2 % settling as
    python-control's ``step_info`` computes them on the same response (10.80 %, 85.7 s,
    306.3 s), measured from the change."""
    import control

    from steerlab.sim.engine import simulate
    from steerlab.sim.scenario import load_scenario

    res = simulate(load_scenario(Path(__file__).resolve().parent.parent / "examples" / "scenarios"
                                 / "calm_default.toml"))
    m = compute_metrics(res)
    sel = res.time >= 100.0
    info = control.step_info(res.psi[sel], T=res.time[sel] - 100.0, yfinal=math.radians(20.0))
    assert m["overshoot_pct"] == pytest.approx(info["Overshoot"], rel=1e-9)
    assert m["rise_time_s"] == pytest.approx(info["RiseTime"], abs=1e-9)
    assert m["settling_time_2pct_s"] == pytest.approx(info["SettlingTime"], abs=1e-9)
    assert (round(m["overshoot_pct"], 2), round(m["rise_time_s"], 1), round(m["settling_time_2pct_s"], 1)) \
        == (10.80, 85.7, 306.3)


def test_last_setpoint_change():
    dt = 0.5
    time = np.arange(0.0, 100.0, dt)
    ref = np.zeros_like(time)
    assert last_setpoint_change(time, ref) is None
    ref[time >= 10.0] = 0.3
    ref[time >= 50.0] = -0.1
    t_c, before, step = last_setpoint_change(time, ref)
    assert t_c == 50.0 and before == 0.3 and step == pytest.approx(-0.4)
    # rate-limited ramp: the change starts where the reference starts to move
    ramp = np.clip((time - 20.0) * 0.01, 0.0, 0.2)
    t_c, before, step = last_setpoint_change(time, ramp)
    assert 20.0 <= t_c <= 20.0 + dt and before == 0.0 and step == pytest.approx(0.2)
    # across +-pi: short way round
    wrapped = np.where(time >= 30.0, math.radians(-179.0), math.radians(179.0))
    _, _, step = last_setpoint_change(time, wrapped)
    assert step == pytest.approx(math.radians(2.0))


# ---------------------------------------------------------------- compute_metrics

def test_compute_metrics_synthetic_result():
    dt = 0.1
    time = np.arange(0.0, 200.0 + dt / 2, dt)
    psi_ref = np.where(time >= 10.0 - dt / 2, math.radians(10.0), 0.0)
    psi = math.radians(10.0) * (1 - np.exp(-np.clip(time - 10.0, 0, None) / 20.0))
    delta = math.radians(3.0) * np.sin(time / 5.0)
    u = np.full(len(time), 8.0)
    u[500] = 7.0
    res = _result(time, psi, psi_ref, delta, u=u)
    m = compute_metrics(res)
    acc = online_metrics_from_result(res)
    assert m["iae_deg_s"] == pytest.approx(acc[M_IAE] * R2D)
    # IAE of 10 deg e^{-t/20} from t = 10 s: ~ 10 * 20 deg s (rectangle rule on dt = 0.1)
    assert m["iae_deg_s"] == pytest.approx(200.0 * (1 - math.exp(-190 / 20)), rel=5e-3)
    assert m["final_error_deg"] == pytest.approx(10.0 * math.exp(-190.0 / 20.0), rel=1e-9)
    assert m["max_abs_rudder_deg"] == pytest.approx(3.0, rel=1e-4)
    assert m["min_speed_kn"] == pytest.approx(7.0 / (1852 / 3600))
    assert m["overshoot_pct"] == 0.0
    assert m["max_abs_error_deg"] == pytest.approx(10.0)
    # sin(t/5) over 200 s changes direction at t = 5 pi/2 + 5 pi k: 13 reversals
    assert m["rudder_reversals"] == sum(1 for k in range(20) if 0 < 5 * math.pi / 2 + 5 * math.pi * k < 200)
    assert "min_speed_kn" not in compute_metrics(_result(time, psi, psi_ref, delta))
    assert all(not isinstance(v, np.floating) for v in m.values())


def test_compute_metrics_same_for_both_engines(scenario):
    s = build(scenario(duration=300.0, controller={"type": "adrc"}, environment={"waves": True},
                       guidance={"changes": [{"t": 20.0, "psi_deg": 15.0}]}))
    mc = compute_metrics(simulate_compiled(s))
    mr = compute_metrics(simulate_readable(s))
    assert mc.keys() == mr.keys()
    for k in mc:
        if mc[k] is None:
            assert mr[k] is None, k
        else:
            assert mr[k] == pytest.approx(mc[k], rel=1e-12, abs=1e-12), k
    assert mc["rudder_reversals"] > 10 and mc["speed_loss_J"] > 0


def test_settling_time_from_onset():
    from steerlab.metrics import settling_time

    t = np.arange(0.0, 100.0, 1.0)
    e = np.where((t >= 20) & (t < 50), 3.0, 0.2)
    assert settling_time(t, e, 1.0, t0=20.0) == pytest.approx(30.0)   # outside 20..49, inside from 50
    assert settling_time(t, e, 1.0, t0=60.0) == 0.0                   # never outside after t0
    assert settling_time(t, np.full_like(t, 2.0), 1.0) is None        # never settles
