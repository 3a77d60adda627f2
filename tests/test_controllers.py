"""PID, ADRC and ESO kernels, gain design, and the guidance (course reference)."""

import math

import numpy as np
import pytest

from steerlab.control.adrc import A_C0, A_KD, A_KDSIGN, A_KP, ADRC, adrc_gains, adrc_update
from steerlab.control.estimators import (PAPER_L, eso_gains_bandwidth, eso_gains_lqr, eso_gains_poles,
                                         eso_matrices, eso_poles, eso_step)
from steerlab.control.pid import PID, pid_update
from steerlab.control.registry import get_controller
from steerlab.errors import InputError
from steerlab.guidance.reference_models import course_reference, course_schedule
from steerlab.units import rad


def _x(psi=0.0, r=0.0):
    x = np.zeros(7)
    x[2] = psi
    x[5] = r
    return x


# ---------------------------------------------------------------- PID

def test_pid_law_unsaturated():
    p = PID(Kp=2.0, Ki=0.1, Kd=5.0).pack()
    z = np.array([0.3])
    ref = np.array([0.1, 0.0])
    u = pid_update(z, p, 0.0, _x(psi=0.05, r=0.002), ref, 0.5)
    assert u == pytest.approx(2.0 * 0.05 + 0.1 * 0.3 - 5.0 * 0.002)
    assert z[0] == pytest.approx(0.3 + 0.05 * 0.5)          # integrates e * h


def test_pid_uses_wrapped_error():
    p = PID(Kp=1.0, Ki=0.0, Kd=0.0).pack()
    u = pid_update(np.zeros(1), p, 0.0, _x(psi=rad(359.0)), np.array([rad(1.0), 0.0]), 0.1)
    assert u == pytest.approx(rad(2.0), abs=1e-12)


def test_pid_output_limited():
    p = PID(Kp=100.0, Ki=0.0, Kd=0.0, u_max=rad(20.0)).pack()
    for e in np.linspace(-1.0, 1.0, 41):
        u = pid_update(np.zeros(1), p, 0.0, _x(), np.array([e, 0.0]), 0.1)
        assert abs(u) <= rad(20.0)
        if abs(e) > 0.01:
            assert u == pytest.approx(math.copysign(rad(20.0), e))


def test_pid_anti_windup():
    p = PID(Kp=1.0, Ki=0.05, Kd=0.0, u_max=0.1).pack()
    z = np.zeros(1)
    ref = np.array([0.5, 0.0])
    h = 0.1
    # 1000 samples of a large constant error: saturated all the time, integral does not grow
    for _ in range(1000):
        u = pid_update(z, p, 0.0, _x(), ref, h)
        assert u == 0.1
    assert z[0] == 0.0
    # without anti-windup the integral would be 0.5 * 100 s = 50 rad s -> Ki*I = 2.5 rad,
    # and the order would stay saturated long after the error reverses. With it, a small
    # reversed error unsaturates the output at once:
    u = pid_update(z, p, 0.0, _x(psi=0.52), ref, h)
    assert u == pytest.approx(-0.02)
    assert z[0] == pytest.approx(-0.02 * h)


def test_pid_integrates_when_error_drives_output_back():
    p = PID(Kp=1.0, Ki=1.0, Kd=0.0, u_max=0.1).pack()
    z = np.array([1.0])                  # wound-up integral, output saturated positive
    u = pid_update(z, p, 0.0, _x(psi=0.05), np.array([0.0, 0.0]), 0.1)   # e = -0.05
    assert u == 0.1
    assert z[0] == pytest.approx(1.0 - 0.005)   # e * ud < 0: integrate (unwind)


def test_pid_derivative_on_yaw_rate_relative_to_reference_rate():
    p = PID(Kp=0.0, Ki=0.0, Kd=10.0).pack()
    u = pid_update(np.zeros(1), p, 0.0, _x(r=0.003), np.array([0.0, 0.001]), 0.1)
    assert u == pytest.approx(-10.0 * 0.002)


@pytest.mark.parametrize("kw, field", [(dict(Kp=-1.0), "controller.Kp"), (dict(Ki=math.nan), "controller.Ki"),
                                       (dict(Kd=-0.1), "controller.Kd"), (dict(u_max=0.0), "controller.u_max")])
def test_pid_pack_validation(kw, field):
    with pytest.raises(InputError) as ei:
        PID(**kw).pack()
    assert ei.value.field == field


# ---------------------------------------------------------------- ADRC gains and law

def test_adrc_gains_eq38():
    kp, kd = adrc_gains(150.0)
    assert kp == pytest.approx(36.0 / 150.0**2)
    assert kd == pytest.approx(12.0 / 150.0)
    kp2, kd2 = adrc_gains(150.0, "printed")
    assert kp2 == kp
    assert kd2 == pytest.approx(2.0 / 150.0)
    # herbst: double pole at -6/T (s^2 + Kd s + Kp)
    np.testing.assert_allclose(np.roots([1.0, kd, kp]), [-6 / 150.0] * 2, rtol=1e-6)
    # printed (38): damping 1/6
    wn = math.sqrt(kp2)
    assert kd2 / (2 * wn) == pytest.approx(1 / 6)


@pytest.mark.parametrize("T, rule, field", [(0.0, "herbst", "controller.T_settle"),
                                            (math.inf, "herbst", "controller.T_settle"),
                                            (100.0, "other", "controller.kd_rule")])
def test_adrc_gains_bad_input(T, rule, field):
    with pytest.raises(InputError) as ei:
        adrc_gains(T, rule)
    assert ei.value.field == field


def test_adrc_pack_and_law_sign():
    c = ADRC.from_settling_time(150.0, c0=9.18e-4)
    p = c.pack()
    assert p[A_C0] == 9.18e-4 and p[A_KP] == pytest.approx(36 / 150**2) and p[A_KD] == pytest.approx(12 / 150)
    assert p[A_KDSIGN] == -1.0
    assert ADRC.from_settling_time(150.0, c0=9.18e-4, law="printed").pack()[A_KDSIGN] == 1.0
    assert tuple(c.L) == PAPER_L


@pytest.mark.parametrize("kw, field", [
    (dict(c0=0.0), "controller.c0"), (dict(c0=math.nan), "controller.c0"),
    (dict(law="weird"), "controller.law"), (dict(L=(1.0, 1.0)), "controller.L"),
    (dict(L=(1.0, -1.0, 1.0)), "controller.L2"), (dict(u_max=-0.1), "controller.u_max"),
])
def test_adrc_pack_validation(kw, field):
    args = dict(c0=1e-3, Kp=1e-3, Kd=0.1)
    args.update(kw)
    with pytest.raises(InputError) as ei:
        ADRC(**args).pack()
    assert ei.value.field == field


def test_adrc_update_law_then_eso():
    c0, h = 8e-4, 0.1
    c = ADRC.from_settling_time(100.0, c0=c0)
    p = c.pack()
    z = np.array([0.01, 0.001, 2e-5])
    z_before = z.copy()
    x = _x(psi=0.01, r=0.0)
    ref = np.array([0.05, 0.0])
    u = adrc_update(z, p, 0.0, x, ref, h)
    kp, kd = adrc_gains(100.0)
    expected = (kp * 0.04 - kd * (0.001 - 0.0) - 2e-5) / c0
    assert u == pytest.approx(expected, rel=1e-12)
    # the ESO advanced with the (limited) order
    zz = z_before.copy()
    eso_step(zz, c0, *PAPER_L, 0.01, expected, h)
    np.testing.assert_array_equal(z, zz)


def test_adrc_update_limits_output():
    c = ADRC.from_settling_time(10.0, c0=1e-4, u_max=rad(35.0))
    u = adrc_update(np.zeros(3), c.pack(), 0.0, _x(), np.array([1.0, 0.0]), 0.1)
    assert u == pytest.approx(rad(35.0))
    u = adrc_update(np.zeros(3), c.pack(), 0.0, _x(), np.array([-1.0, 0.0]), 0.1)
    assert u == pytest.approx(-rad(35.0))


def test_registry():
    assert get_controller("pid").update is pid_update and get_controller("pid").n_state == 1
    assert get_controller("adrc").update is adrc_update and get_controller("adrc").n_state == 3
    with pytest.raises(InputError) as ei:
        get_controller("lqg")
    assert ei.value.field == "controller.type" and "lqg" in str(ei.value)


# ---------------------------------------------------------------- ESO

@pytest.mark.parametrize("w", [0.1, 0.5, 2.0])
def test_eso_bandwidth_gains(w):
    np.testing.assert_allclose(eso_gains_bandwidth(w), [3 * w, 3 * w**2, w**3], rtol=1e-9)
    np.testing.assert_allclose(np.sort_complex(eso_poles(eso_gains_bandwidth(w))), [-w] * 3, atol=1e-4 * w)


def test_eso_gains_poles_places_poles():
    L = eso_gains_poles([-0.3, -0.5, -0.7])
    np.testing.assert_allclose(np.sort(eso_poles(L).real), [-0.7, -0.5, -0.3], rtol=1e-9)
    A, _, C = eso_matrices()
    np.testing.assert_allclose(np.sort(np.linalg.eigvals(A - np.outer(L, C)).real), [-0.7, -0.5, -0.3],
                               rtol=1e-9)


@pytest.mark.parametrize("q, r", [((1.0, 1.0, 1.0), 1.0), ((10.0, 1.0, 0.01), 0.1), ((1.0, 1.0, 1e-6), 1.0)])
def test_eso_lqr_gives_stable_observer(q, r):
    L = eso_gains_lqr(q, r)
    assert L.shape == (3,) and np.all(L > 0)
    A, _, C = eso_matrices()
    ev = np.linalg.eigvals(A - np.outer(L, C))
    assert np.all(ev.real < 0)
    np.testing.assert_allclose(np.sort_complex(ev), np.sort_complex(eso_poles(L)), atol=1e-9)


def test_eso_lqr_default_closed_form():
    # q = I, r = 1 for the triple integrator: L = [1 + sqrt2, 1 + sqrt2, 1]
    np.testing.assert_allclose(eso_gains_lqr(), [1 + math.sqrt(2), 1 + math.sqrt(2), 1.0], rtol=1e-8)


def test_paper_observer_poles():
    ev = eso_poles(PAPER_L)
    assert np.all(ev.real < 0)
    slow = ev[np.argmin(np.abs(ev))]
    assert abs(slow.imag) < 1e-12
    assert slow.real == pytest.approx(-0.0022, rel=0.03)


def test_eso_tracks_triple_integrator_with_constant_disturbance():
    c0, f, h = 1e-3, 2e-4, 0.05
    L = eso_gains_bandwidth(1.0)
    z = np.zeros(3)
    x1 = x2 = 0.0
    for k in range(2000):
        u = 0.1 * math.sin(0.01 * k * h)
        eso_step(z, c0, *L, x1, u, h)
        # exact plant step: x1'' = c0 u + f with u held
        a = c0 * u + f
        x1 += x2 * h + 0.5 * a * h * h
        x2 += a * h
    assert z[2] == pytest.approx(f, rel=1e-2)
    assert z[1] == pytest.approx(x2, rel=1e-2)


def test_eso_wraps_heading():
    z = np.array([rad(179.0), 0.0, 0.0])
    eso_step(z, 1e-3, 1.0, 0.0, 0.0, rad(-179.0), 0.0, 0.1)   # y is 2 deg ahead, across +-180
    assert z[0] == pytest.approx(rad(179.0) + 0.1 * rad(2.0), abs=1e-12)
    z = np.array([rad(179.9), 0.0, 0.0])
    eso_step(z, 1e-3, 10.0, 0.0, 0.0, rad(-179.0), 0.0, 0.1)
    assert -math.pi <= z[0] < math.pi


# ---------------------------------------------------------------- guidance

def _ref(t, g):
    ref = np.zeros(2)
    course_reference(t, g, ref)
    return ref


def test_course_reference_step():
    g = course_schedule(0.0, [(100.0, rad(20.0))])
    assert _ref(0.0, g)[0] == 0.0 and _ref(99.99, g)[0] == 0.0
    np.testing.assert_allclose(_ref(100.0, g), [rad(20.0), 0.0])
    np.testing.assert_allclose(_ref(1e4, g), [rad(20.0), 0.0])


def test_course_reference_rate_limited_ramp():
    rate = rad(0.5)
    g = course_schedule(0.0, [(100.0, rad(20.0))], rate_max=rate)
    np.testing.assert_allclose(_ref(100.0, g), [0.0, rate], atol=1e-15)
    np.testing.assert_allclose(_ref(120.0, g), [rad(10.0), rate], rtol=1e-12)
    np.testing.assert_allclose(_ref(139.9, g), [rate * 39.9, rate], rtol=1e-12)
    np.testing.assert_allclose(_ref(140.01, g), [rad(20.0), 0.0], rtol=1e-12)
    np.testing.assert_allclose(_ref(500.0, g), [rad(20.0), 0.0], rtol=1e-12)
    # ramps monotonically at exactly rate_max and stops at the target
    t = np.arange(90.0, 200.0, 0.1)
    psi = np.array([_ref(tt, g)[0] for tt in t])
    assert np.max(np.diff(psi)) <= rate * 0.1 * (1 + 1e-9)
    assert np.min(np.diff(psi)) >= 0.0
    assert psi.max() == pytest.approx(rad(20.0))


def test_course_reference_multiple_changes():
    rate = rad(0.5)
    g = course_schedule(0.0, [(100.0, rad(20.0)), (110.0, rad(-10.0)), (200.0, rad(5.0))], rate_max=rate)
    np.testing.assert_allclose(_ref(110.0, g), [rad(5.0), -rate], rtol=1e-12)   # interrupted at 5 deg
    np.testing.assert_allclose(_ref(120.0, g), [0.0, -rate], atol=1e-15)
    np.testing.assert_allclose(_ref(140.01, g), [rad(-10.0), 0.0], rtol=1e-12)
    np.testing.assert_allclose(_ref(199.0, g), [rad(-10.0), 0.0], rtol=1e-12)
    np.testing.assert_allclose(_ref(205.0, g), [rad(-7.5), rate], rtol=1e-12)
    np.testing.assert_allclose(_ref(230.01, g), [rad(5.0), 0.0], rtol=1e-12)
    # steps (rate 0)
    g0 = course_schedule(0.0, [(100.0, rad(20.0)), (110.0, rad(-10.0))])
    np.testing.assert_allclose(_ref(105.0, g0), [rad(20.0), 0.0])
    np.testing.assert_allclose(_ref(110.0, g0), [rad(-10.0), 0.0])


def test_course_reference_short_way_round():
    rate = rad(0.5)
    g = course_schedule(rad(359.0), [(10.0, rad(1.0))], rate_max=rate)
    ref = _ref(12.0, g)
    assert ref[1] == rate                                     # turning to starboard
    assert ref[0] == pytest.approx(0.0, abs=1e-12)             # 359 + 1 = 360 deg
    assert _ref(20.0, g)[0] == pytest.approx(rad(1.0), abs=1e-12)
    g = course_schedule(rad(1.0), [(10.0, rad(359.0))], rate_max=rate)
    assert _ref(12.0, g)[1] == -rate
    assert _ref(20.0, g)[0] == pytest.approx(rad(-1.0), abs=1e-12)


def test_course_schedule_validation():
    with pytest.raises(InputError) as ei:
        course_schedule(0.0, [(100.0, 0.1), (50.0, 0.2)])
    assert ei.value.field == "guidance.changes[1].t"
    with pytest.raises(InputError) as ei:
        course_schedule(0.0, [], rate_max=-1.0)
    assert ei.value.field == "guidance.rate_max"
    with pytest.raises(InputError) as ei:
        course_schedule(math.nan)
    assert ei.value.field == "guidance.psi0"


# ---------------------------------------------------------------- closed loop (compiled engine)

def _final_error_deg(scenario, ctrl, dist_deg, duration=4000.0):
    from steerlab.sim.engine import simulate
    res = simulate(scenario(duration=duration, controller=ctrl,
                            environment={"constant_rudder_deg": dist_deg}))
    return np.degrees(res.heading_error), res


@pytest.mark.parametrize("dist", [10.0, -10.0])
def test_adrc_rejects_constant_disturbance(scenario, dist):
    e, res = _final_error_deg(scenario, {"type": "adrc"}, dist)
    assert abs(e[-1]) < 0.05
    assert np.max(np.abs(e)) > 1.0                          # the disturbance did push the ship
    # the rudder ends up cancelling the equivalent-rudder disturbance
    assert np.degrees(res.delta[-1]) == pytest.approx(-dist, abs=0.05)


def test_pid_without_integral_leaves_steady_error(scenario):
    e, _ = _final_error_deg(scenario, {"type": "pid", "Ki": 0.0}, 10.0)
    assert abs(e[-1]) > 1.0
    # and with its integral the same PID removes it
    e_i, _ = _final_error_deg(scenario, {"type": "pid"}, 10.0)
    assert abs(e_i[-1]) < 0.05


def test_printed_adrc_law_does_not_hold_course(scenario):
    from steerlab.sim.engine import simulate
    guid = {"changes": [{"t": 10.0, "psi_deg": 20.0}]}
    stable = simulate(scenario(duration=1500.0, controller={"type": "adrc"}, guidance=guid))
    printed = simulate(scenario(duration=1500.0, controller={"type": "adrc", "law": "printed"}, guidance=guid))
    es = np.degrees(np.abs(stable.heading_error))
    ep = np.degrees(np.abs(printed.heading_error))
    assert es.max() <= 20.0 + 1e-9 and es[-1] < 0.1
    assert ep.max() > 40.0                     # runs away to well past the step size
    assert np.mean(ep[-3000:]) > 10.0          # and does not come back


def test_printed_kd_rule_is_underdamped(scenario):
    from steerlab.sim.engine import simulate
    guid = {"changes": [{"t": 10.0, "psi_deg": 20.0}]}
    herbst = simulate(scenario(duration=1500.0, controller={"type": "adrc"}, guidance=guid))
    printed = simulate(scenario(duration=1500.0, controller={"type": "adrc", "kd_rule": "printed"},
                                guidance=guid))
    over_h = np.degrees(herbst.psi.max()) - 20.0
    over_p = np.degrees(printed.psi.max()) - 20.0
    # the plant is not the ideal double integrator (gear lag, ESO lag): some overshoot remains
    assert over_h < 3.0
    assert over_p > 3.0 * over_h and over_p > 8.0


def test_adrc_observer_that_diverges_at_its_sample_time_is_refused():
    """Forward-Euler ESO: a triple pole at -w has the discrete eigenvalue 1 - w h, so it
    converges for w h < 2 only; faster observers are refused with the field and the limit."""
    from steerlab.control.estimators import eso_discrete_radius, eso_gains_bandwidth
    from steerlab.errors import InputError
    from steerlab.sim.scenario import scenario_from_dict
    from steerlab.sim.setup import build

    assert eso_discrete_radius(eso_gains_bandwidth(5.0), 0.1) == pytest.approx(0.5, abs=1e-4)
    assert eso_discrete_radius(eso_gains_bandwidth(25.0), 0.1) == pytest.approx(1.5, abs=1e-3)
    ok = {"ship": {"model": "esso"}, "controller": {"type": "adrc", "observer": "bandwidth",
                                                     "observer_bandwidth": 15.0}}
    build(scenario_from_dict(ok))                                 # 15 * 0.1 = 1.5 < 2
    with pytest.raises(InputError) as err:
        build(scenario_from_dict({**ok, "controller": {**ok["controller"], "sample_time": 0.5}}))
    assert err.value.field == "controller.observer_bandwidth"
    assert "diverges" in str(err.value) and "below 4 rad/s" in str(err.value)
    with pytest.raises(InputError) as err:
        build(scenario_from_dict({"ship": {"model": "esso"},
                                  "controller": {"type": "adrc", "L": [300.0, 3e4, 1e6]}}))
    assert err.value.field == "controller.L"
