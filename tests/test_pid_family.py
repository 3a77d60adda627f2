"""The PID family: classic autopilot, ITAE-robust PID, gain-shaping PID, LQ-optimal PD.

Tuning rules are checked against python-control; the kernels against the continuous designs;
closed loops run on the nominal first-order Nomoto ship ``nomoto1`` (K = 0.1 1/s, T = 50 s).
The four controllers share two fused loops (``lq_pd`` and ``gain_shaping_pid`` run the PID
kernel), so this file compiles three (ship, controller) pairs.
"""

import math

import numpy as np
import pytest

from steerlab.control.classic_autopilot import ClassicAutopilot, classic_autopilot_update, dead_band
from steerlab.control.gain_shaping_pid import gain_shaping_gains, nomoto_gain_shaping_gains
from steerlab.control.itae_pid import ItaePID, itae_gains, itae_pid_update, prefilter_coefficients
from steerlab.control.lq_pd import lq_pd_gains
from steerlab.errors import InputError
from steerlab.sim.engine import simulate
from steerlab.sim.scenario import scenario_from_dict
from steerlab.units import deg, rad

K_SHIP, T_SHIP = 0.1, 50.0
SHIP = {"model": "nomoto1", "speed_kn": 10.0, "options": {"K": K_SHIP, "T": T_SHIP}}

CONTROLLERS = {     # the papers' settings (gains = "paper"; docs/controllers-pid.md)
    "classic_autopilot": {"type": "classic_autopilot", "Kp": 1.0, "Kd": 20.0, "Ki": 0.01},
    "itae_pid": {"type": "itae_pid", "gains": "paper", "t_r": 53.0},
    "lq_pd": {"type": "lq_pd", "gains": "paper", "lam": 1.0},
    "gain_shaping_pid": {"type": "gain_shaping_pid", "gains": "paper", "T01": 20.0},
}
INTEGRAL = {"classic_autopilot": True, "itae_pid": True, "lq_pd": False, "gain_shaping_pid": False}


def _scenario(ctrl, **over):
    d = {"name": "pid-family", "seed": 3, "dt": 0.1, "duration": 600.0, "ship": SHIP,
         "controller": CONTROLLERS[ctrl] if isinstance(ctrl, str) else ctrl,
         "guidance": {"psi0_deg": 0.0, "changes": []}, "environment": {}}
    d.update(over)
    return scenario_from_dict(d)


def _x(psi=0.0, r=0.0, u=5.0):
    x = np.zeros(7)
    x[2], x[3], x[5] = psi, u, r
    return x


def _steady_kp(ctrl):
    """Proportional gain of the PD laws as designed (for the steady-error prediction)."""
    if ctrl == "lq_pd":
        return lq_pd_gains(1.0, K_SHIP, T_SHIP)[0]
    return nomoto_gain_shaping_gains(20.0, K_SHIP, T_SHIP)[0]


# ------------------------------------------------------------------ tuning rules

@pytest.mark.parametrize("t_r", [20.0, 38.0, 53.0, 120.0])
def test_itae_eq6_closed_loop_denominator(t_r, control):
    """polynomial="eq6": the loop of Fig. 1 with the Nomoto model has the printed M(s) (6)."""
    k, T = 0.1256, 48.5
    h1, h2, h3 = itae_gains(t_r, k, T, "eq6")
    w0 = 5.0 / t_r
    loop = control.feedback(control.tf([h3, h1, h2], [1, 0]) * control.tf([k], [T, 1, 0]), 1)
    den = np.asarray(loop.den[0][0], dtype=float)
    np.testing.assert_allclose(den / den[0], [1.0, 1.75 * w0, w0**2, w0**3], rtol=1e-12)


def test_itae_dorf_reading_is_eq10_as_printed(control):
    """Default reading: H1, H2, H3 and the pre-filter exactly as printed in (10)-(11)."""
    k, T, t_r = 0.1256, 48.5, 53.0
    h1, h2, h3 = itae_gains(t_r, k, T)
    assert h1 == pytest.approx(53.75 * T / (t_r**2 * k), rel=1e-13)
    assert h2 == pytest.approx(125.0 * T / (t_r**3 * k), rel=1e-13)
    assert h3 == pytest.approx((8.75 * T / t_r - 1.0) / k, rel=1e-13)
    a2, a1 = prefilter_coefficients(t_r, k, T)      # (11) divided by 125 T
    assert a2 == pytest.approx((8.75 * T - t_r) * t_r**2 / (125.0 * T), rel=1e-12)
    assert a1 == pytest.approx(53.75 * T * t_r / (125.0 * T), rel=1e-12)
    # the whole loop G_p * T_cl is w0^3 / (s^3 + 1.75 w0 s^2 + 2.15 w0^2 s + w0^3): no zeros
    w0 = 5.0 / t_r
    loop = control.feedback(control.tf([h3, h1, h2], [1, 0]) * control.tf([k], [T, 1, 0]), 1)
    whole = control.minreal(control.tf([1.0], [a2, a1, 1.0]) * loop, tol=1e-9, verbose=False)
    num, den = np.asarray(whole.num[0][0], float), np.asarray(whole.den[0][0], float)
    assert len(num) == 1 and len(den) == 4
    np.testing.assert_allclose(den / den[0], [1.0, 1.75 * w0, 2.15 * w0**2, w0**3], rtol=1e-8)
    assert num[0] / den[0] == pytest.approx(w0**3, rel=1e-8)


def test_itae_rejects_impossible_designs():
    with pytest.raises(InputError, match=r"controller\.t_r"):
        itae_gains(8.75 * 50.0, 0.1, 50.0)          # H3 = 0: pre-filter not stable
    with pytest.raises(InputError, match=r"controller\.polynomial"):
        itae_gains(50.0, 0.1, 50.0, "itae")
    with pytest.raises(InputError, match=r"controller\.K"):
        itae_gains(50.0, 0.0, 50.0)


@pytest.mark.parametrize("lam,K,T", [(0.1, 0.1, 50.0), (1.0, 0.05, 120.0), (10.0, 0.3, 20.0), (4.0, 1.0, 1.0)])
def test_lq_pd_equals_python_control_lqr(lam, K, T, control):
    """(3.5)-(3.6) are the LQR gains of [eps, r] with Q = diag(1, 0), R = lambda."""
    kp, kd = lq_pd_gains(lam, K, T)
    A = np.array([[0.0, 1.0], [0.0, -1.0 / T]])
    B = np.array([[0.0], [K / T]])
    G, _, _ = control.lqr(A, B, np.diag([1.0, 0.0]), np.array([[lam]]))
    np.testing.assert_allclose([kp, kd], G[0], rtol=1e-8)
    assert kp == pytest.approx(1.0 / math.sqrt(lam))


def test_gain_shaping_gives_first_order_closed_loop(control):
    """(18): with the error derivative the loop is 1/(T01 s + 1); the ship pole stays in the
    disturbance loop: characteristic polynomial (T s + 1)(T01 s + 1)/T01."""
    T01 = 20.0
    kp, ki, kd = nomoto_gain_shaping_gains(T01, K_SHIP, T_SHIP)
    assert (kp, ki, kd) == pytest.approx((1.0 / (K_SHIP * T01), 0.0, T_SHIP / (K_SHIP * T01)))
    loop = control.minreal(control.feedback(control.tf([kd, kp], [1]) * control.tf([K_SHIP], [T_SHIP, 1, 0]), 1),
                           tol=1e-9, verbose=False)
    np.testing.assert_allclose(np.real(loop.poles()), [-1.0 / T01], rtol=1e-9)
    char = np.polyadd([T_SHIP, 1.0, 0.0], K_SHIP * np.array([kd, kp]))
    np.testing.assert_allclose(np.sort(np.roots(char)), np.sort([-1.0 / T_SHIP, -1.0 / T01]), rtol=1e-9)
    assert gain_shaping_gains(T01, 2.0, 3.0, 4.0, 5.0) == pytest.approx((3 / 100, 4 / 100, 2 / 100))


# ------------------------------------------------------------------ kernels

def test_classic_dead_band_on_error_and_on_order():
    assert [dead_band(v, 0.1) for v in (-0.3, -0.05, 0.0, 0.1, 0.25)] == pytest.approx([-0.2, 0, 0, 0, 0.15])
    p = ClassicAutopilot(Kp=2.0, Ki=0.0, Kd=0.0, weather=rad(1.0)).pack()
    assert classic_autopilot_update(np.zeros(2), p, 0.0, _x(), np.array([rad(0.9), 0.0]), 0.1) == 0.0
    u = classic_autopilot_update(np.zeros(2), p, 0.0, _x(), np.array([rad(3.0), 0.0]), 0.1)
    assert u == pytest.approx(2.0 * rad(2.0))
    p = ClassicAutopilot(Kp=2.0, Ki=0.0, Kd=0.0, weather=rad(1.0), weather_on="order").pack()
    u = classic_autopilot_update(np.zeros(2), p, 0.0, _x(), np.array([rad(3.0), 0.0]), 0.1)
    assert u == pytest.approx(2.0 * rad(3.0) - rad(1.0))


def test_classic_integral_frozen_during_course_changes():
    p = ClassicAutopilot(Kp=1.0, Ki=0.1, Kd=0.0, course_change=rad(5.0)).pack()
    z = np.array([0.2, 0.0])
    classic_autopilot_update(z, p, 0.0, _x(), np.array([rad(4.0), 0.0]), 0.5)      # keeping
    assert z[0] == pytest.approx(0.2 + rad(4.0) * 0.5)
    z = np.array([0.2, 0.0])
    u = classic_autopilot_update(z, p, 0.0, _x(), np.array([rad(6.0), 0.0]), 0.5)  # |e| > 5 deg
    assert z[0] == 0.2 and u == pytest.approx(rad(6.0) + 0.1 * 0.2)             # frozen, still applied
    classic_autopilot_update(z, p, 0.0, _x(), np.array([rad(1.0), rad(0.5)]), 0.5)  # reference turning
    assert z[0] == 0.2


def test_classic_low_pass_is_the_sampled_first_order_lag():
    p = ClassicAutopilot(Kp=1.0, Ki=0.0, Kd=0.0, lowpass_T=10.0).pack()
    z = np.zeros(2)
    a = math.exp(-0.5 / 10.0)
    for n in range(1, 30):
        u = classic_autopilot_update(z, p, 0.0, _x(), np.array([0.05, 0.0]), 0.5)
        assert u == pytest.approx(0.05 * (1.0 - a**n), rel=1e-12)


def test_itae_speed_scheduling_is_eq2():
    """At V = 2 V_m the scheduled controller acts as the one designed for k = 2 k_m, T = T_m/2."""
    base = dict(t_r=30.0, u_max=1.0)
    sched = ItaePID(k_m=0.1, T_m=50.0, V_m=5.0, schedule=True, **base).pack()
    fixed = ItaePID(k_m=0.2, T_m=25.0, V_m=10.0, schedule=False, **base).pack()
    za, zb = np.array([0.0, 0.0, 0.0]), np.array([0.0, 0.0, 0.0])
    for k in range(50):
        x = _x(psi=0.002 * k, r=0.001, u=10.0)
        ua = itae_pid_update(za, sched, 0.0, x, np.array([0.1, 0.0]), 0.5)
        ub = itae_pid_update(zb, fixed, 0.0, x, np.array([0.1, 0.0]), 0.5)
        assert ua == pytest.approx(ub, rel=1e-12, abs=1e-15)
    np.testing.assert_allclose(za, zb, rtol=1e-12)
    # unscheduled gains do not move with speed
    h1 = ItaePID(t_r=30.0, k_m=0.1, T_m=50.0, V_m=5.0).gains()
    assert ItaePID(t_r=30.0, k_m=0.1, T_m=50.0, V_m=5.0).gains(10.0) == pytest.approx(
        itae_gains(30.0, 0.2, 25.0))
    assert h1 == pytest.approx(itae_gains(30.0, 0.1, 50.0))


def test_itae_prefilter_wraps_and_settles_on_the_set_point():
    p = ItaePID(t_r=30.0, k_m=0.1, T_m=50.0, V_m=5.0, schedule=False).pack()
    z = np.array([rad(359.0) - 2 * math.pi, 0.0, 0.0])
    for _ in range(4000):
        itae_pid_update(z, p, 0.0, _x(psi=z[0]), np.array([rad(1.0), 0.0]), 0.1)
    assert z[0] == pytest.approx(rad(1.0), abs=1e-9)       # went the short way (2 deg)


def test_itae_kernel_matches_the_continuous_design(control):
    """Small step, fast gear: the sampled loop follows w0^3 / M(s) (the paper's design)."""
    t_r = 53.0
    sc = _scenario("itae_pid", dt=0.05, duration=200.0,
                   gear={"rate_max_deg_s": 100.0, "T_sg": 0.05},
                   guidance={"psi0_deg": 0.0, "changes": [{"t": 0.0, "psi_deg": 2.0}]})
    res = simulate(sc)
    w0 = 5.0 / t_r
    want = control.step_response(control.tf([w0**3], [1.0, 1.75 * w0, 2.15 * w0**2, w0**3]), T=res.time).outputs
    err = np.abs(deg(res.psi) - 2.0 * np.squeeze(want))
    assert err.max() < 0.01 * 2.0                  # within 1 % of the step over the whole run
    # eq (8) (w0 = 5/t_r, "zeta ~ 0.8") is only approximate: with the ITAE polynomial the 2 %
    # settling time is 7.63/w0 = 1.53 t_r (python-control step_info), and so it is here
    def settling(y):
        return res.time[np.nonzero(np.abs(y - 1.0) > 0.02)[0][-1]]

    ts = settling(deg(res.psi) / 2.0)
    assert ts == pytest.approx(settling(np.squeeze(want)), abs=0.5)
    assert ts == pytest.approx(1.53 * t_r, rel=0.02)


# ------------------------------------------------------------------ closed loops on nomoto1

@pytest.mark.parametrize("ctrl", list(CONTROLLERS))
def test_closed_loop_course_change_settles(ctrl):
    res = simulate(_scenario(ctrl, duration=800.0,
                             guidance={"psi0_deg": 0.0, "changes": [{"t": 10.0, "psi_deg": 10.0}]}))
    e = deg(res.psi_ref - res.psi)
    tail = res.time > 600.0
    assert np.abs(e[tail]).max() < 0.05
    assert np.abs(res.states[tail, 5]).max() < 1e-4
    assert np.abs(e).max() <= 10.0 + 1e-9 and deg(res.psi).max() < 14.0   # bounded overshoot


@pytest.mark.parametrize("ctrl", list(CONTROLLERS))
def test_constant_disturbance_steady_error(ctrl):
    """Integral laws remove a constant 3 deg equivalent-rudder disturbance; PD laws leave -d/Kp."""
    res = simulate(_scenario(ctrl, duration=2500.0, dt=0.2,
                             environment={"constant_rudder_deg": 3.0, "constant_start": 20.0}))
    e_end = deg(res.psi_ref[-1] - res.psi[-1])
    if INTEGRAL[ctrl]:
        assert abs(e_end) < 1e-3
        assert deg(res.delta[-1]) == pytest.approx(-3.0, abs=1e-3)   # permanent helm
    else:
        assert e_end == pytest.approx(-3.0 / _steady_kp(ctrl), abs=1e-3)


@pytest.mark.parametrize("ctrl", list(CONTROLLERS))
def test_output_within_limits(ctrl):
    cfg = dict(CONTROLLERS[ctrl], u_max_deg=10.0)
    res = simulate(_scenario(cfg, duration=300.0,
                             guidance={"psi0_deg": 0.0, "changes": [{"t": 5.0, "psi_deg": 60.0},
                                                                    {"t": 150.0, "psi_deg": -60.0}]}))
    assert np.abs(res.delta_cmd).max() <= rad(10.0) + 1e-15
    assert np.abs(res.delta_cmd).max() == pytest.approx(rad(10.0))   # the limit is reached
    assert np.abs(res.delta).max() <= rad(10.0) + 1e-12


@pytest.mark.parametrize("ctrl", list(CONTROLLERS))
def test_parity_and_determinism(ctrl):
    """Compiled and readable loops give bit-identical runs; a rerun reproduces exactly."""
    sc = _scenario(ctrl, duration=150.0, environment={"waves": True, "constant_rudder_deg": 1.0},
                   guidance={"psi0_deg": 359.0, "rate_max_deg_s": 0.5, "changes": [{"t": 5.0, "psi_deg": 15.0}]})
    a, b, c = simulate(sc), simulate(sc, "readable"), simulate(sc)
    for name in ("states", "delta_cmd", "psi_ref"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
        assert np.array_equal(getattr(a, name), getattr(c, name)), name


@pytest.mark.parametrize("cfg,field", [
    ({"type": "classic_autopilot", "Kp": -1.0}, r"controller\.Kp"),
    ({"type": "classic_autopilot", "weather_on": "rudder"}, r"controller\.weather_on"),
    ({"type": "classic_autopilot", "course_change_deg": 0.0}, r"controller\.course_change_deg"),
    ({"type": "itae_pid", "t_r": -1.0}, r"controller\.t_r"),
    ({"type": "itae_pid", "t_r": 500.0}, r"controller\.t_r"),              # > 8.75 T = 437.5 s
    ({"type": "itae_pid", "polynomial": "printed"}, r"controller\.polynomial"),
    ({"type": "itae_pid", "v_min_fraction": 0.0}, r"controller\.v_min_fraction"),
    ({"type": "lq_pd", "lam": 0.0}, r"controller\.lam"),
    ({"type": "lq_pd", "lam": float("nan")}, r"controller\.lam"),
    ({"type": "gain_shaping_pid", "T01": -2.0}, r"controller\.T01"),
    ({"type": "gain_shaping_pid", "bogus": 1.0}, r"controller\.bogus"),
])
def test_bad_config_names_the_field(cfg, field):
    with pytest.raises(InputError, match=field):
        from steerlab.sim.setup import build
        build(_scenario(cfg))


@pytest.mark.parametrize("ctrl", ["itae_pid", "lq_pd", "gain_shaping_pid"])
def test_K_and_T_of_opposite_signs_are_refused(ctrl):
    """K > 0 with T < 0 would be a rudder that turns the ship the wrong way at first: one line
    naming controller.K; an explicit design model of one sign is accepted."""
    from steerlab.sim.setup import build
    ship = {"model": "nomoto1", "speed_kn": 10.0, "options": {"K": 0.1, "T": -50.0}}
    with pytest.raises(InputError, match=r"controller\.K") as ei:
        build(_scenario(ctrl, ship=ship))
    assert "\n" not in str(ei.value)
    build(_scenario(dict(CONTROLLERS[ctrl], T=50.0), ship=ship))   # an explicit design T is accepted


def test_gain_shaping_paper_rule_refuses_a_course_unstable_ship_naming_the_laws_that_can():
    """The course-unstable Esso: the design rule places the poles (tests/test_linear_law_design.py);
    the paper's rule would cancel the unstable pole and refuses in one line."""
    from steerlab.sim.setup import build
    build(_scenario({"type": "gain_shaping_pid"}, ship={"model": "esso", "speed_kn": 16.0}))
    with pytest.raises(InputError) as ei:
        build(_scenario("gain_shaping_pid", ship={"model": "esso", "speed_kn": 16.0}))
    assert ei.value.field == "controller.type" and "\n" not in str(ei.value)
    assert '"pid"' in str(ei.value) and '"lq_pd"' in str(ei.value)
