"""Design rules of the linear laws (pid, classic_autopilot, lq_pd, gain_shaping_pid, itae_pid):
the poles they claim, K and T of both signs, the papers' presets bit for bit, the refusals."""

from __future__ import annotations

import math

import numpy as np
import pytest

from steerlab.components.controller import controller
from steerlab.components.linear import transfer_function
from steerlab.control.design_model import GEAR_USE, ZETA, bandwidth, design_model
from steerlab.control.itae_pid import itae_gains
from steerlab.errors import InputError
from steerlab.units import rad

LAWS = ("pid", "classic_autopilot", "lq_pd", "gain_shaping_pid", "itae_pid")
GEAR = {"delta_max_deg": 35.0, "rate_max_deg_s": 2.33, "T_sg": 1.0}


def _omega(K, T, gear=GEAR):
    from steerlab.components.design import design_context

    return bandwidth(design_model(design_context(nomoto=(K, T), gear=gear)))


@pytest.mark.parametrize("K,T", [(0.05, 80.0), (0.2, 30.0), (-0.05, -120.0), (-0.08, -650.0)])
def test_pid_places_the_poles_it_claims_for_both_signs(K, T, control):
    """C(s) P(s) with P = K/(s (T s + 1)): closed loop s^3 + 2 zeta w s^2 + w^2 s + w^3/10."""
    c = controller("pid", nomoto=(K, T), gear=GEAR)
    w = _omega(K, T)
    P = control.tf([K], [T, 1.0, 0.0])
    cl = control.feedback(transfer_function(c) * P, 1)
    want = np.roots([1.0, 2.0 * ZETA * w, w * w, w ** 3 / 10.0])
    np.testing.assert_allclose(np.sort_complex(control.poles(cl)), np.sort_complex(want), rtol=1e-7)
    assert np.all(np.real(want) < 0.0)
    # the first rudder of the 20 deg reference turn, Kp * 20 deg, within GEAR_USE of the limit
    assert c.params[0] * rad(20.0) <= GEAR_USE * rad(35.0) * (1 + 1e-12)


def test_classic_autopilot_designs_the_same_gains_as_pid():
    a = controller("pid", nomoto=(-0.05, -120.0))
    b = controller("classic_autopilot", nomoto=(-0.05, -120.0))
    np.testing.assert_array_equal(a.params[:3], b.params[:3])


@pytest.mark.parametrize("K,T,lam", [(0.05, 80.0, 1.0), (-0.05, -120.0, 0.3), (-0.08, -650.0, 4.0)])
def test_lq_pd_equals_python_control_lqr_for_both_signs(K, T, lam, control):
    c = controller("lq_pd", nomoto=(K, T), lam=lam, gains="paper")
    A = [[0.0, 1.0], [0.0, -1.0 / T]]
    B = [[0.0], [K / T]]
    G, _, E = control.lqr(A, B, np.diag([1.0, 0.0]), lam)
    np.testing.assert_allclose([c.params[0], c.params[2]], np.ravel(G), rtol=1e-7)
    assert np.all(np.real(E) < 0.0) and c.params[1] == 0.0


def test_lq_pd_design_lam_gives_the_shared_bandwidth():
    K, T = -0.05, -120.0
    c = controller("lq_pd", nomoto=(K, T))
    w = _omega(K, T)
    assert K / T * c.params[0] == pytest.approx(w * w, rel=1e-12)        # b Kp = omega_n^2
    assert c.params[1] == pytest.approx(c.params[0] * w / 10.0, rel=1e-12)


@pytest.mark.parametrize("K,T", [(0.1256, 48.5), (-0.05, -120.0)])
def test_itae_pole_placement_holds_for_both_signs(K, T, control):
    t_r = 60.0
    h1, h2, h3 = itae_gains(t_r, K, T)
    assert min(h1, h2, h3) > 0.0
    w0 = 5.0 / t_r
    loop = control.feedback(control.tf([h3, h1, h2], [1, 0]) * control.tf([K], [T, 1, 0]), 1)
    den = np.asarray(loop.den[0][0], dtype=float)
    np.testing.assert_allclose(den / den[0], [1.0, 1.75 * w0, 2.15 * w0 ** 2, w0 ** 3], rtol=1e-10)


def test_paper_presets_are_the_old_numbers_bit_for_bit():
    K, T = 0.05, 80.0
    np.testing.assert_array_equal(controller("pid", gains="paper").params[:3], [3.81, 0.00547, 3.95])
    np.testing.assert_array_equal(controller("classic_autopilot", gains="paper").params[:3], [1.0, 0.002, 20.0])
    lq = controller("lq_pd", nomoto=(K, T), gains="paper").params
    assert (lq[0], lq[1], lq[2]) == (1.0, 0.0, (math.sqrt(1.0 + 2.0 * K * T * 1.0) - 1.0) / K)
    gs = controller("gain_shaping_pid", nomoto=(K, T), gains="paper").params
    assert (gs[0], gs[1], gs[2]) == (1.0 / (K * 20.0), 0.0, T / (K * 20.0))
    it = controller("itae_pid", nomoto=(K, T), speed_kn=10.0, gains="paper")
    assert it.design.t_r == 53.0 and it.design.anti_windup is False


def test_a_given_gain_always_wins():
    c = controller("pid", nomoto=(0.05, 80.0), Kp=2.5)
    assert c.params[0] == 2.5 and c.params[2] == controller("pid", nomoto=(0.05, 80.0)).params[2]
    full = controller("pid", Kp=1.0, Ki=0.0, Kd=3.0)          # no model needed when every gain is given
    np.testing.assert_array_equal(full.params[:3], [1.0, 0.0, 3.0])


def test_designed_itae_pid_has_anti_windup_and_a_gear_settling_time():
    """omega_0 = omega_n / sqrt(c2): the ITAE loop's proportional gain H1 is the PD's omega_n^2 / b
    for which the shared rule caps omega_n by the gear (itae_pid.design_t_r)."""
    c = controller("itae_pid", nomoto=(0.1, 50.0), speed_kn=10.0)
    assert c.design.anti_windup is True
    w = _omega(0.1, 50.0)
    assert c.design.t_r == pytest.approx(5.0 * math.sqrt(2.15) / w, rel=1e-12)
    h1, _, _ = itae_gains(c.design.t_r, 0.1, 50.0)
    assert h1 == pytest.approx(w * w / (0.1 / 50.0), rel=1e-12)          # Kp of the PD pole placement
    eq6 = controller("itae_pid", nomoto=(0.1, 50.0), speed_kn=10.0, polynomial="eq6")
    assert eq6.design.t_r == pytest.approx(5.0 / w, rel=1e-12)            # c2 = 1: omega_0 = omega_n


def test_a_design_without_a_model_names_nomoto():
    with pytest.raises(InputError) as ei:
        controller("pid")
    assert ei.value.field == "nomoto"


def test_gain_shaping_designs_an_unstable_model_by_pole_placement_and_its_paper_rule_refuses():
    """T < 0: the gain-shaping zero would cancel the unstable pole, so the design rule places the
    poles as pid does (the same gains); the paper's rule (gains = "paper") refuses in one line."""
    gear = {"delta_max_deg": 30.0, "rate_max_deg_s": 3.0}
    gsp = controller("gain_shaping_pid", nomoto=(-0.05, -120.0), gear=gear)
    np.testing.assert_array_equal(gsp.params, controller("pid", nomoto=(-0.05, -120.0), gear=gear).params)
    assert gsp.params[0] > 0.0                 # a design, not the paper's fixed gains
    stable = controller("gain_shaping_pid", nomoto=(0.05, 120.0), gear=gear)
    assert not np.array_equal(stable.params, controller("pid", nomoto=(0.05, 120.0), gear=gear).params)
    with pytest.raises(InputError) as ei:
        controller("gain_shaping_pid", nomoto=(-0.05, -120.0), gains="paper")
    assert ei.value.field == "type" and "\n" not in str(ei.value)
    assert '"pid"' in str(ei.value) and '"lq_pd"' in str(ei.value)


def test_gain_shaping_does_not_cancel_a_pole_slower_than_its_integral(control):
    """A nearly neutral ship (Bech's small tanker at 8.25 m/s as a second-order Nomoto model:
    T1 = 1667 s, T2 = 10 s, T3 = 22 s; first-order K = 2 1/s, T = 1655 s): cancelling -1/T
    with the gain-shaping zero leaves a closed-loop mode of thousands of seconds on the real
    ship (the heading crept 8.7 deg past the new course); T > 10 T01, so the design rule places
    the poles as pid does, and every closed-loop pole is faster than 1/(10 T01)."""
    from steerlab.control.gain_shaping_pid import INTEGRAL_DIVISOR, design_T01
    from steerlab.components.design import design_context

    K, T1, T2, T3 = 2.0, 1667.0, 10.0, 22.0
    T = T1 + T2 - T3
    ship = control.tf([K * T3, K], np.polymul([T1, 1.0], [T2, 1.0, 0.0]))
    T01 = design_T01(design_model(design_context(nomoto=(K, T), gear=GEAR)))
    assert T > INTEGRAL_DIVISOR * T01

    def slowest(c):
        return min(abs(np.real(control.poles(control.feedback(transfer_function(c) * ship, 1)))))

    gsp = controller("gain_shaping_pid", nomoto=(K, T), gear=GEAR)
    np.testing.assert_array_equal(gsp.params, controller("pid", nomoto=(K, T), gear=GEAR).params)
    assert slowest(gsp) > 1.0 / (INTEGRAL_DIVISOR * T01)
    cancelling = controller("gain_shaping_pid", nomoto=(K, T), gear=GEAR, T01=T01)   # the paper's rule
    assert slowest(cancelling) < 1.0 / 1000.0
    # a course-stable ship with T within 10 T01 keeps the gain-shaping rule
    assert not np.array_equal(controller("gain_shaping_pid", nomoto=(0.1, 56.0), gear=GEAR).params,
                              controller("pid", nomoto=(0.1, 56.0), gear=GEAR).params)


def _step(law, K, T, gear, dmax, rate, t_end=4000.0, dt=0.1):
    """A first-order Nomoto ship in plain Python (Euler), the gear as a rate-limited saturation;
    a 20 deg course change at t = 100 s. Returns (time, heading) [s, rad]."""
    kw = {"speed_kn": 10.0} if law == "itae_pid" else {}
    c = controller(law, nomoto=(K, T), gear=gear, **kw).reset(heading=0.0)
    psi = r = delta = 0.0
    out = []
    for k in range(int(t_end / dt)):
        t = k * dt
        ref = rad(20.0) if t >= 100.0 else 0.0
        order = c.step(t, psi, r, ref, rudder=delta)
        delta += max(-rate * dt, min(rate * dt, max(-dmax, min(dmax, order)) - delta))
        psi, r = psi + r * dt, r + (K * delta - r) / T * dt
        out.append((t, psi))
    return np.array(out)


PLANTS = [(0.05, 80.0, 35.0, 2.33), (0.3, 25.0, 25.0, 5.0), (0.02, 300.0, 30.0, 1.5),
          (-0.05, -120.0, 35.0, 2.33), (-0.1, -400.0, 20.0, 3.0), (-0.3, -60.0, 35.0, 7.0)]


@pytest.mark.parametrize("law", LAWS)
def test_designed_from_K_T_alone_holds_a_20_deg_change_on_both_signs(law):
    held = 0
    for K, T, dmax_deg, rate_deg in PLANTS:
        gear = {"delta_max_deg": dmax_deg, "rate_max_deg_s": rate_deg, "T_sg": 1.0}
        try:
            log = _step(law, K, T, gear, rad(dmax_deg), rad(rate_deg))
        except InputError as err:     # every law designs these six (gain_shaping_pid's T < 0 by pole placement)
            raise AssertionError(f"{law} refused ({K}, {T}): {err}") from None
        tail = log[log[:, 0] >= 3000.0, 1]     # the slowest plant's integral pole: ~1 200 s
        assert np.all(np.abs(tail - rad(20.0)) < rad(1.0)), (law, K, T, math.degrees(np.max(np.abs(tail - rad(20.0)))))
        held += 1
    assert held == len(PLANTS)


def test_itae_pid_from_nomoto_alone_is_the_unscheduled_design():
    """No speed to schedule on: eq (2) is off and the record is the unscheduled design's (but V_m),
    for T of both signs (tests/test_conformance_matrix.py steps it on the random plants)."""
    import numpy as np

    from steerlab.control.itae_pid import I_SCHED, I_VM

    for K, T in ((0.05, 80.0), (-0.05, -300.0)):
        c = controller("itae_pid", nomoto=(K, T))
        assert c.params[I_SCHED] == 0.0
        with_speed = controller("itae_pid", nomoto=(K, T), speed_kn=10.0, schedule=False)
        np.testing.assert_array_equal(np.delete(c.params, I_VM), np.delete(with_speed.params, I_VM))
