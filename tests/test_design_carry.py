"""Designs that carry to a slow ship (issue 30): the integral's start, its freeze in course changes,
and r' behind the wave filter.

The B-481 at 0.97 kn (``omega_n`` = 0.0024 rad/s) is the case that showed each rule: its
asymmetry needs -2.1 deg of rudder, which an integral at Fossen's ``omega_n / 10`` learns in
~4 000 s; a course change's transient charged the integral and ran out as slowly; and behind the
wave filter the raw ``rdot`` state carried the whole wave-frequency yaw acceleration.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from steerlab.control import classic_autopilot as ca
from steerlab.control import pid
from steerlab.control import sliding_mode as sm
from steerlab.control.design_context import DesignContext
from steerlab.control.heading_integral import INTEGRAL_BAND, integral_step
from steerlab.control.van_leeuwen_design import design_model as vl_design_model
from steerlab.components.design import make_gear
from steerlab.ships.registry import get_ship
from steerlab.sim.scenario import scenario_from_dict
from steerlab.sim.setup import build

#: the B-481's straight-course rudder: K* delta0 = a0* (Table 1, ballast; degrees throughout)
B481_DELTA0 = math.radians(-3.1667 / 1.5)


def _setup(controller: dict, ship: str = "b481", speed_kn: float = 15.0):
    return build(scenario_from_dict({
        "name": "carry", "dt": 0.1, "duration": 10.0, "ship": {"model": ship, "speed_kn": speed_kn},
        "controller": controller, "guidance": {"psi0_deg": 0.0, "changes": []}}))


def test_the_design_context_knows_the_straight_course_rudder():
    spec = get_ship("b481")
    ctx = DesignContext(spec, 0.5, make_gear(None), 0.1, 0.1, spec.options(None))
    assert ctx.straight_rudder() == pytest.approx(B481_DELTA0, rel=1e-4)
    # HELM_RULE in one place: only a designed integral that exists starts there
    assert ctx.integral_start(True, 1e-3) == ctx.straight_rudder()
    assert ctx.integral_start(False, 1e-3) == 0.0 and ctx.integral_start(True, 0.0) == 0.0
    nomoto1 = get_ship("nomoto1")
    assert DesignContext(nomoto1, 5.0, make_gear(None), 0.1, 0.1, None).straight_rudder() == 0.0


@pytest.mark.parametrize("law,i_state,i_gain", [
    ("pid", pid.Z_INT, pid.C_KI), ("lq_pd", pid.Z_INT, pid.C_KI), ("gain_shaping_pid", pid.Z_INT, pid.C_KI),
    ("classic_autopilot", ca.Z_INT, ca.C_KI), ("sliding_mode", sm.Z_XI, sm.S_KI), ("asa", None, None)])
def test_a_designed_integral_starts_holding_the_straight_course_rudder(law, i_state, i_gain):
    s = _setup({"type": law})
    if law == "asa":                    # ASA: the mean of its offset Ki [rad], the next change's Ki0
        from steerlab.control.asa_layout import Z_KI, Z_KI_MEAN

        assert s.z0[Z_KI_MEAN] == pytest.approx(B481_DELTA0, rel=1e-4) and s.z0[Z_KI] == 0.0
        assert not np.any(_setup({"type": law}, "nomoto1", 10.0).z0[[Z_KI, Z_KI_MEAN]])
        assert not np.any(_setup({"type": law, "gains": "paper"}).z0[[Z_KI, Z_KI_MEAN]])
        return
    assert s.pc[i_gain] > 0.0
    assert s.z0[i_state] * s.pc[i_gain] == pytest.approx(B481_DELTA0, rel=1e-4)
    # a symmetric ship: nothing to hold, the integral starts empty
    s = _setup({"type": law}, "nomoto1", 10.0)
    assert s.z0[i_state] == 0.0


@pytest.mark.parametrize("law", ["pid", "classic_autopilot", "lq_pd", "gain_shaping_pid", "sliding_mode"])
def test_the_paper_presets_start_and_run_the_integral_as_before(law):
    s = _setup({"type": law, "gains": "paper"})
    assert not np.any(s.z0[[pid.Z_INT] if "sliding" not in law else [sm.Z_XI]])
    if law in ("pid", "lq_pd", "gain_shaping_pid"):
        assert s.pc[pid.C_RBAND] == 0.0 and s.pc[pid.C_HELM0] == 0.0


@pytest.mark.parametrize("controller", [{"type": "pid", "Kp": 0.84, "Ki": 0.001, "Kd": 1.56},
                                        {"type": "lq_pd", "lam": 1.0, "Ki": 0.001},
                                        {"type": "classic_autopilot", "Ki": 0.001}])
def test_a_given_integral_gain_is_used_as_given(controller):
    """The integral's start and freeze belong to the designed integral: a PID whose Ki the user
    gives (the berthing and Zwierzewicz reproductions give all three gains) runs as before."""
    s = _setup(controller)
    assert not np.any(s.z0)
    if controller["type"] != "classic_autopilot":
        assert s.pc[pid.C_RBAND] == 0.0 and s.pc[pid.C_HELM0] == 0.0


def _pid_params(r_band: float) -> np.ndarray:
    return pid.PID(Kp=1.0, Ki=0.01, Kd=10.0, u_max=math.radians(35.0), r_band=r_band).pack()


@pytest.mark.parametrize("e_deg,r,r_band,charges", [
    (10.0, -0.002, 0.001, False),    # a course change (the error closing faster than r_band): frozen
    (2.0, -0.002, 0.001, False),     # its final approach, near the course: frozen too
    (10.0, 0.0, 0.001, True),        # held 10 deg off by a yaw moment: integrates
    (10.0, -0.002, 0.0, True),       # r_band = 0 (the paper): never frozen
])
def test_the_pid_integral_is_frozen_in_course_changes(e_deg, r, r_band, charges):
    from steerlab.guidance.reference_vector import initial_reference, REF_PSI
    from steerlab.ships.state import IR

    x = np.zeros(7)
    x[IR] = r
    ref = initial_reference()
    ref[REF_PSI] = math.radians(e_deg)
    z = np.zeros(pid.N_STATE)
    pid.pid_update(z, _pid_params(r_band), 0.0, x, ref, 0.1)
    assert (z[pid.Z_INT] != 0.0) == charges
    if charges:
        assert z[pid.Z_INT] == pytest.approx(math.radians(e_deg) * 0.1)


def test_the_pid_family_design_sets_the_turn_detector_from_its_own_gains():
    """``r_band = omega_n 5 deg / 4`` with ``omega_n = 10 Ki / Kp`` (the family's ``Ki = Kp omega_n / 10``)."""
    from steerlab.control.law_design import law_bandwidth
    from steerlab.units import knots_to_ms

    s = _setup({"type": "pid"}, "nomoto1", 10.0)
    w = 10.0 * s.pc[pid.C_KI] / s.pc[pid.C_KP]
    spec = get_ship("nomoto1")
    ctx = DesignContext(spec, knots_to_ms(10.0), make_gear(None), 0.1, 0.1, spec.options(None))
    assert w == pytest.approx(law_bandwidth(ctx, "pid")[1])          # the shared bandwidth rule's
    assert s.pc[pid.C_RBAND] == pytest.approx(w * INTEGRAL_BAND / 4.0)
    assert s.pc[pid.C_HELM0] == 0.0


def test_the_heading_integral_waits_for_the_approach_to_end_near_the_course_too():
    r_band = 1e-3
    z = np.zeros(1)
    e = 0.5 * INTEGRAL_BAND                        # within 5 deg of the course ...
    integral_step(z, 0, 0.01, e, -2.0 * r_band, r_band, 0.0, 0.5, 0.1)   # ... still closing fast: off
    assert z[0] == 0.0
    integral_step(z, 0, 0.01, e, -0.5 * r_band, r_band, 0.0, 0.5, 0.1)   # held there: on
    assert z[0] == pytest.approx(0.1 * e)


def test_behind_the_wave_filter_the_van_leeuwen_laws_estimate_r_dot():
    spec = get_ship("b481")
    args = (spec, 7.75, make_gear(None), 0.1, 0.1, spec.options(None))
    i_direct = vl_design_model(DesignContext(*args), None, None)[2]
    i_filtered = vl_design_model(DesignContext(*args, measurement="wave-filtered"), None, None)[2]
    assert i_direct == spec.state_names.index("rdot") and i_filtered == -1.0


@pytest.mark.parametrize("law,label,sea", [("pid", "low", "calm"), ("backstepping_b", "low", "calm"),
                                           ("sliding_mode", "design", "sea5")])
def test_the_b481_cases_the_rules_carry_steer(law, label, sea):
    """Conformance cells that failed before the rules (docs/conformance.md of fd3f779)."""
    from steerlab.conformance.cases import Case
    from steerlab.conformance.matrix import run_case
    from steerlab.conformance.points import operating_points

    point = next(p for p in operating_points(get_ship("b481")) if p.label == label)
    out = run_case(Case("b481", law, point, sea))
    assert out.verdict == "steers", out.reason
