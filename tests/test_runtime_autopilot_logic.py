"""Autopilot and ship-server safety logic without sockets: watchdog, safe action, alarms, route."""

from __future__ import annotations

import math

import numpy as np
import pytest

from steerlab.errors import InputError
from steerlab.runtime import protocol as P
from steerlab.runtime.alarms import LINK, OFF_COURSE, AlarmBoard
from steerlab.runtime.autopilot import Autopilot, AutopilotConfig
from steerlab.runtime.controller_runtime import ControllerRuntime
from steerlab.runtime.ship_server import order_in_effect
from steerlab.sim.scenario import scenario_from_dict

RUNTIME_SCENARIO = {
    "name": "runtime-test", "dt": 0.025, "duration": 60.0,
    "ship": {"model": "nomoto1", "speed_kn": 10.0, "options": {"K": 0.5, "T": 10.0}},
    "gear": {"rate_max_deg_s": 10.0, "T_sg": 0.5},
    "controller": {"type": "pid", "Kp": 2.0, "Kd": 8.0, "Ki": 0.0},
    "guidance": {"psi0_deg": 0.0},
}
H = 0.125


@pytest.fixture(scope="module")
def ctrl():
    return ControllerRuntime(scenario_from_dict(RUNTIME_SCENARIO), "pid", H)


def _ap(ctrl, **cfg):
    return Autopilot(ctrl, ("127.0.0.1", 9), AutopilotConfig(**cfg), heading=0.0)


def _feed(ap, t, psi=0.0, r=0.0):
    ap.latest = P.State(t, 0.0, 0.0, psi, r, 5.0, 0.0, 0.0, math.nan, 0.0, 0)
    ap.latest_t = t


def test_order_in_effect_holds_then_centres():
    assert order_in_effect(None, 0.3, 1.0, 3.0) == (0.0, P.STATUS_CMD_CENTRED)
    assert order_in_effect(0.5, 0.3, 1.0, 3.0) == (0.3, 0)
    assert order_in_effect(1.5, 0.3, 1.0, 3.0) == (0.3, P.STATUS_CMD_HOLD)
    assert order_in_effect(3.01, 0.3, 1.0, 3.0) == (0.0, P.STATUS_CMD_CENTRED)


def test_controller_runtime_is_the_registry_kernel(ctrl):
    from steerlab.control.pid import pid_update

    assert ctrl.kernel is pid_update and ctrl.h == H
    assert ctrl.setup.pc.tolist() == [2.0, 0.0, 8.0, math.radians(35.0), 0.0, 0.0]
    x = ctrl.measured_state(1.0, 2.0, 0.1, 5.0, 0.0, 0.01, 0.02)
    assert x.shape == (7,) and x[2] == 0.1 and x[-1] == 0.02
    # same number as the law written out: Kp e - Kd (r - r_ref)
    assert ctrl.update(0.0, x, np.array([0.2, 0.0])) == pytest.approx(2.0 * 0.1 - 8.0 * 0.01)
    with pytest.raises(InputError, match="controller.type"):
        ControllerRuntime(scenario_from_dict(RUNTIME_SCENARIO), "no-such-controller", H)


@pytest.mark.parametrize("safe", ["midships", "hold"])
def test_watchdog_alarm_and_safe_action_after_timeout(ctrl, safe):
    ap = _ap(ctrl, watchdog_timeout=1.0, safe_action=safe)
    t = 0.0
    for k in range(40):                      # 5 s with states: heading 5 deg off -> port rudder
        t = k * H
        _feed(ap, t, psi=math.radians(5.0))
        ap.sample(t)
    assert ap.mode == "auto" and ap.cmd_sent < 0
    held = ap.cmd_sent
    t_last = t
    rows = [ap.sample(t_last + k * H) for k in range(1, 17)]      # link lost for 2 s
    for row in rows:
        age = row["t"] - t_last
        if age <= 1.0:                                             # state held, still steering
            assert row["link_ok"] == 1 and row["mode"] == "auto" and "link" not in row["alarms"]
        else:                                                      # alarm + safe action
            assert row["link_ok"] == 0 and row["mode"] == "safe" and "link" in row["alarms"]
            assert row["delta_cmd_deg"] == (0.0 if safe == "midships" else pytest.approx(math.degrees(held)))
    assert ap.alarms.first_raised(LINK) == pytest.approx(t_last + 9 * H)   # first sample with age > 1 s
    _feed(ap, t_last + 2.5)                                        # link back: steering resumes
    assert ap.sample(t_last + 2.5)["mode"] == "auto" and not ap.alarms.active(LINK)
    assert ap.alarms.alarms[LINK].acknowledged is False            # stays listed until acknowledged
    ap.acknowledge(t_last + 3.0)
    assert LINK not in ap.alarms.alarms


def test_no_state_at_start_raises_link_alarm_after_timeout(ctrl):
    ap = _ap(ctrl, watchdog_timeout=0.5)
    assert ap.sample(0.25)["alarms"] == "" and ap.sample(0.625)["alarms"] == "link"
    assert ap.cmd_sent == 0.0 and ap.mode == "safe"


def test_off_course_alarm_armed_only_after_reaching_the_course(ctrl):
    ap = _ap(ctrl, off_course_limit=math.radians(10.0))
    ap.set_course(math.radians(30.0), 0.0)      # 30 deg away: turning, no alarm yet
    _feed(ap, 0.0)
    assert ap.sample(0.0)["alarms"] == ""
    _feed(ap, 1.0, psi=math.radians(26.0))       # within half the limit: armed
    assert ap.sample(1.0)["alarms"] == "" and ap.off_course_armed
    _feed(ap, 2.0, psi=math.radians(15.0))       # 15 deg off: alarm
    assert ap.sample(2.0)["alarms"] == OFF_COURSE
    ap.adjust(-10.0, 2.1)                        # new set course disarms it
    _feed(ap, 2.2, psi=math.radians(-5.0))
    assert ap.sample(2.2)["alarms"] == ""
    assert [w for _, n, w in ap.alarms.history] == ["raised", "cleared"]


def test_standby_sends_nothing_and_engage_resets_the_controller(ctrl):
    ap = Autopilot(ctrl, ("127.0.0.1", 9), AutopilotConfig(), heading=None, engaged=False)
    _feed(ap, 0.0, psi=math.radians(40.0))
    ap.sample(0.0)
    assert ap.mode == "standby" and ap.order() is None
    assert ap.psi_set == pytest.approx(math.radians(40.0))       # set course = heading at start
    ap.engage(0.1)
    ap.sample(0.125)
    body = ap.order()
    assert ap.mode == "auto" and body.mode == P.MODE_ENGAGED and body.delta_cmd == pytest.approx(0.0)


def test_alarm_board_semantics():
    b = AlarmBoard()
    b.set("x", True, 1.0, "m")
    b.set("x", True, 2.0, "m")                 # still active: not raised twice
    b.acknowledge(3.0)
    assert b.active("x") and b.alarms["x"].acknowledged
    b.set("x", False, 4.0)                     # acknowledged and cleared: gone
    assert "x" not in b.alarms
    assert [w for _, _, w in b.history] == ["raised", "acknowledged", "cleared"]


ROUTE_SCENARIO = {**RUNTIME_SCENARIO, "duration": 90.0,
                  "guidance": {"type": "los", "start": [0.0, 60.0],
                               "route": [[0.0, 0.0], [250.0, 0.0], [250.0, 300.0]], "lookahead_L": 1.0}}


def _route_file(tmp_path):
    f = tmp_path / "route.csv"
    f.write_text("x_n,y_e\n# a comment\n0,0\n250,0\n250,300\n")
    return f


def test_runtime_route_guidance_equals_the_simulators_kernel(ctrl, tmp_path):
    """Parity: the runtime's guidance (and orders) for the simulator's recorded state sequence."""
    from steerlab.runtime.route import route_guidance
    from steerlab.sim.engine import simulate_readable

    sc = scenario_from_dict(ROUTE_SCENARIO)
    res = simulate_readable(sc)
    log = res.meta["guidance_log"]
    plan = route_guidance(scenario_from_dict(RUNTIME_SCENARIO), ctrl.setup.ship, ctrl.setup.ps,
                          _route_file(tmp_path), lookahead_L=1.0)
    assert plan.guide is res.meta["guidance"].guide                       # one kernel
    np.testing.assert_array_equal(plan.gd, res.meta["guidance"].gd)       # same record
    ap = Autopilot(ctrl, ("127.0.0.1", 9), AutopilotConfig(), route=plan)
    nc = int(round(H / res.dt))
    names = list(res.state_names)
    col = {n: res.states[:, names.index(n)] for n in ("x_n", "y_e", "psi", "u", "v", "r")}
    delta = res.states[:, -1]
    n_checked = 0
    for k in range(0, len(res.time), nc):
        t = k * res.dt
        ap.latest = P.State(t, col["x_n"][k], col["y_e"][k], col["psi"][k], col["r"][k], col["u"][k],
                            col["v"][k], delta[k], math.nan, 0.0, 0)
        ap.latest_t = t
        row = ap.sample(t)
        assert ap.ref[0] == res.psi_ref[k] and row["xte_m"] == log["xte"][k] and row["leg"] == log["leg"][k]
        assert ap.cmd_sent == res.delta_cmd[k]                            # same law, same orders
        n_checked += 1
    assert n_checked == 721 and {0.0, 1.0} <= set(log["leg"][::nc])      # the waypoint was passed
    assert abs(log["xte"][0]) == 60.0 and abs(log["xte"][-1]) < 2.0


def test_route_option_errors_name_the_field(ctrl, tmp_path):
    from steerlab.runtime.route import route_guidance

    sc = scenario_from_dict(RUNTIME_SCENARIO)
    f = tmp_path / "r.csv"
    f.write_text("x_n,y_e\n0,0\n")
    for path, kw, field in ((f, {}, "--route"), (tmp_path / "missing.csv", {}, "--route"),
                            (_route_file(tmp_path), {"accept_radius": -1.0}, "--accept-radius"),
                            (_route_file(tmp_path), {"lookahead_L": 0.0}, "--lookahead-L")):
        with pytest.raises(InputError) as err:
            route_guidance(sc, ctrl.setup.ship, ctrl.setup.ps, path, **kw)
        assert err.value.field == field


def test_route_is_the_only_course_source(ctrl, tmp_path):
    from steerlab.runtime.route import route_guidance

    plan = route_guidance(scenario_from_dict(RUNTIME_SCENARIO), ctrl.setup.ship, ctrl.setup.ps,
                          _route_file(tmp_path), lookahead_L=1.0)
    ap = Autopilot(ctrl, ("127.0.0.1", 9), AutopilotConfig(), route=plan)
    _feed(ap, 0.0)
    ap.sample(0.0)
    psi_set = ap.psi_set
    ap.adjust(10.0, 0.1)
    assert ap.psi_set == psi_set and ap.status()["route"] == [[0.0, 0.0], [250.0, 0.0], [250.0, 300.0]]


def test_missed_samples_are_skipped_keeping_the_phase(ctrl):
    ap = _ap(ctrl)
    assert ap._next_sample(4, 4.2) == 5 and ap.skipped == 0              # on time
    assert ap._next_sample(5, 5.99) == 6 and ap.skipped == 0             # a little late: run now
    assert ap._next_sample(6, 13.4) == 13 and ap.skipped == 6            # stall: 7..12 skipped
    assert ap._next_sample(13, 13.5) == 14 and ap.skipped == 6
