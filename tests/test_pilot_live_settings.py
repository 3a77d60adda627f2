"""Run-time steering modes, live gains and profiles, the state file and the signed Signal K link,
without sockets: the autopilot's own logic (``sample``), the design path, and the link format
checked against the plug-in's JavaScript implementation under node."""

from __future__ import annotations

import json
import math
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from steerlab.errors import InputError
from steerlab.runtime import nmea
from steerlab.runtime import protocol as P
from steerlab.runtime.autopilot import Autopilot, AutopilotConfig
from steerlab.runtime.controller_runtime import ControllerRuntime
from steerlab.runtime.controller_settings import ControllerSettings, load_profiles
from steerlab.runtime.pilot_state import StateKeeper, read_state, resume
from steerlab.runtime.signalk import GAINS, MODE, PROFILE, apply_commands, autopilot_delta_json, parse_delta
from steerlab.runtime.signalk_link import DeltaSigner, SignedDeltaFilter
from steerlab.sim.scenario import scenario_from_dict
from test_runtime_autopilot_logic import H, RUNTIME_SCENARIO

PLUGIN = Path(__file__).resolve().parents[1] / "integrations" / "signalk-plugin-steerlab"
PROFILES = """
[calm]
Kp = 1.5
Kd = 6.0

[rough]
Kp = 2.5
Kd = 10.0
Ki = 0.004
"""


def _runtime(**controller):
    d = {**RUNTIME_SCENARIO, "controller": {**RUNTIME_SCENARIO["controller"], **controller}}
    return ControllerRuntime(scenario_from_dict(d), "pid", H)


def _state(t):
    """A ship swinging about north (psi [rad], r [rad/s] vary every sample)."""
    return P.State(t, 5.0 * t, 0.3 * t, 0.2 * math.sin(0.3 * t), 0.06 * math.cos(0.3 * t), 5.0, 0.1, 0.05,
                   math.nan, 0.0, 0)


def _step(ap, t):
    ap.latest, ap.latest_t = _state(t), t
    ap.sample(t)
    return ap.cmd_sent


def _ap(ctrl, profiles=None, **kw):
    return Autopilot(ctrl, ("127.0.0.1", 9), AutopilotConfig(), heading=kw.pop("heading", 0.1),
                     settings=ControllerSettings(ctrl.settings, profiles), **kw)


def test_a_gain_changed_at_run_time_steers_as_a_fresh_controller_with_that_gain():
    ap = _ap(_runtime())
    ts = [k * H for k in range(200)]
    for t in ts[:80]:
        _step(ap, t)
    unchanged = _ap(_runtime())                     # the same history, no change
    for t in ts[:80]:
        _step(unchanged, t)
    applied = ap.configure(ts[80], gains={"Kp": 3.0, "Ki": 0.01})
    assert applied["Kp"] == 3.0 and applied["Ki"] == 0.01 and applied["Kd"] == 8.0
    assert ap.ctrl.p.tolist()[:3] == [3.0, 0.01, 8.0]
    fresh = _ap(_runtime(Kp=3.0, Ki=0.01))         # built at start with those settings
    live = [_step(ap, t) for t in ts[80:]]
    new = [_step(fresh, t) for t in ts[80:]]
    old = [_step(unchanged, t) for t in ts[80:]]
    assert live == new                               # the same orders, bit for bit
    assert max(abs(a - b) for a, b in zip(live, old)) > math.radians(0.5)   # and the gain mattered
    assert ap.status()["gains"] == {"Kp": 3.0, "Ki": 0.01} and ap.status()["settings"]["Kp"] == 3.0


def test_a_profile_is_the_scenario_settings_with_the_profile_on_top(tmp_path):
    (tmp_path / "p.toml").write_text(PROFILES)
    profiles = load_profiles(tmp_path / "p.toml")
    ap = _ap(_runtime(), profiles)
    ap.configure(0.0, gains={"Kp": 9.0})
    ap.configure(0.0, profile="rough")              # a profile drops the gains given before
    assert ap.settings.profile == "rough" and ap.settings.gains == {}
    ref = _runtime(Kp=2.5, Kd=10.0, Ki=0.004)
    assert np.array_equal(ap.ctrl.p, ref.p)
    assert ap.status()["profiles"] == ["scenario", "calm", "rough"]
    ap.configure(0.0, profile="scenario")
    assert np.array_equal(ap.ctrl.p, _runtime().p)


@pytest.mark.parametrize("gains, field", [({"Kp": -1.0}, "controller.Kp"), ({"Kp": "x"}, "controller.Kp"),
                                          ({"nope": 1.0}, "controller.nope"), ({"type": "adrc"}, "gains.type"),
                                          ({"Kp": math.nan}, "gains.Kp"), ({}, "gains"), ([1], "gains")])
def test_a_bad_gain_is_one_error_naming_the_field_and_changes_nothing(gains, field):
    ap = _ap(_runtime())
    before = ap.ctrl.p.copy()
    with pytest.raises(InputError) as err:
        ap.configure(0.0, gains=gains)
    assert err.value.field == field
    assert np.array_equal(ap.ctrl.p, before) and ap.settings.gains == {}
    with pytest.raises(InputError, match="unknown profile"):
        ap.configure(0.0, profile="storm")


@pytest.mark.parametrize("text, match", [("[calm]\nKp = -1", None), ("[scenario]\nKp = 1", "scenario"),
                                         ('["bad name"]\nKp = 1', "profile name"), ("calm = 3", "table"),
                                         ("[calm]\ntype = 'adrc'", "run time"), ("[calm", "TOML")])
def test_bad_profiles_files(tmp_path, text, match):
    (tmp_path / "p.toml").write_text(text)
    if match is None:      # a value out of range is found when the profile is chosen
        ap = _ap(_runtime(), load_profiles(tmp_path / "p.toml"))
        with pytest.raises(InputError, match="controller.Kp"):
            ap.configure(0.0, profile="calm")
        return
    with pytest.raises(InputError, match=match):
        load_profiles(tmp_path / "p.toml")


def test_modes_switch_at_run_time_and_a_course_that_does_not_apply_says_why():
    ap = _ap(_runtime(), nmea_listen=("127.0.0.1", 0), heading=0.0)
    assert ap.steering_mode == "plotter" and ap.available_modes() == ("compass", "plotter")
    _step(ap, 0.0)
    ap.on_nmea_datagram(_apb(40.0).encode(), t=0.1)
    _step(ap, 0.125)
    assert math.degrees(ap.psi_set) == pytest.approx(40.0) and ap.course_source == "APB"
    assert ap.course_refusal(0.2).startswith("mode plotter")
    assert "needs a route" in ap.set_mode("route", 0.2) and ap.steering_mode == "plotter"
    assert "must be one of" in ap.set_mode("wind", 0.2)
    assert ap.set_mode("compass", 0.25) is None and ap.course_refusal(0.25) is None
    ap.set_course(math.radians(10.0), 0.25)
    ap.on_nmea_datagram(_apb(60.0).encode(), t=0.3)   # the plotter speaks on; compass ignores it
    for k in range(3, 8):
        _step(ap, k * H)
    assert math.degrees(ap.psi_set) == pytest.approx(10.0) and ap.status()["steering_mode"] == "compass"
    assert ap.set_mode("plotter", 1.0) is None
    ap.on_nmea_datagram(_apb(60.0).encode(), t=1.0)
    _step(ap, 1.0)
    assert math.degrees(ap.psi_set) == pytest.approx(60.0)
    # the status delta the plug-in reads says the same
    values = parse_delta(autopilot_delta_json(ap))
    assert values[MODE] == "plotter" and values["steering.autopilot.steerlab.modes"] == ["compass", "plotter"]


def test_a_plotter_course_on_an_undeclared_nmea_input_switches_to_plotter_unless_a_mode_was_chosen():
    ap = _ap(_runtime(), heading=0.0)
    assert ap.steering_mode == "compass" and "needs a chart plotter" in ap.set_mode("plotter", 0.0)
    ap.on_nmea_datagram(_apb(30.0).encode(), t=0.0)
    _step(ap, 0.0)
    assert ap.steering_mode == "plotter" and math.degrees(ap.psi_set) == pytest.approx(30.0)
    chosen = _ap(_runtime(), heading=0.0)
    assert chosen.set_mode("compass", 0.0) is None
    chosen.on_nmea_datagram(_apb(30.0).encode(), t=0.0)
    _step(chosen, 0.0)
    assert chosen.steering_mode == "compass" and chosen.psi_set == 0.0 and "plotter" in chosen.available_modes()


def _apb(deg):
    return nmea.render("APB", ["A", "A", "0.00", "R", "N", "V", "V", f"{deg:.1f}", "T", "WP1",
                               f"{deg:.1f}", "T", f"{deg:.1f}", "T"])


def test_signal_k_commands_are_answered_with_steerlabs_own_verdict(tmp_path):
    (tmp_path / "p.toml").write_text(PROFILES)
    ap = _ap(_runtime(), load_profiles(tmp_path / "p.toml"))
    assert apply_commands(ap, {PROFILE: "rough", "steering.autopilot.steerlab.commandId": 7}, 0.0) == \
        ("accepted", {"id": 7, "code": 200, "message": ""})
    outcome, reply = apply_commands(ap, {GAINS: {"Kd": 1e9}, "steering.autopilot.steerlab.commandId": 8}, 0.0)
    assert outcome == "not_applied" and reply["code"] == 400 and "Kd" in reply["message"]
    outcome, reply = apply_commands(ap, {MODE: "route", "steering.autopilot.steerlab.commandId": 9}, 0.0)
    assert reply["code"] == 409 and "--route" in reply["message"]
    outcome, reply = apply_commands(ap, {MODE: "wind", "steering.autopilot.steerlab.commandId": 10}, 0.0)
    assert reply["code"] == 400 and "mode must be one of" in reply["message"]
    for bad in (-1e308, 7.0):
        outcome, reply = apply_commands(ap, {"steering.autopilot.target.headingTrue": bad,
                                             "steering.autopilot.steerlab.commandId": 11}, 0.0)
        assert outcome == "out_of_range" and reply["code"] == 400
    assert ap.settings.profile == "rough" and ap.psi_set == pytest.approx(0.1)


def test_the_state_file_resumes_set_course_mode_and_profile(tmp_path):
    (tmp_path / "p.toml").write_text(PROFILES)
    profiles = load_profiles(tmp_path / "p.toml")
    path = tmp_path / "pilot.json"
    ap = _ap(_runtime(), profiles, nmea_listen=("127.0.0.1", 0))
    ap.set_mode("compass", 0.0)
    ap.configure(0.0, profile="calm")
    ap.configure(0.0, gains={"Ki": 0.002})
    ap.set_course(math.radians(123.0), 0.0)
    keeper = StateKeeper(path)
    assert keeper.update(ap, wall=0.0) and not keeper.update(ap, wall=5.0)    # unchanged: not rewritten
    doc, why = read_state(path)
    assert why is None and doc["profile"] == "calm" and doc["gains"] == {"Ki": 0.002}
    # a restart: a new autopilot (standby, no course) resumes from the file
    ap2 = _ap(_runtime(), profiles, nmea_listen=("127.0.0.1", 0), heading=None, engaged=False)
    assert ap2.steering_mode == "plotter"
    assert resume(ap2, doc) == []
    assert ap2.steering_mode == "compass" and ap2.settings.profile == "calm" and ap2.settings.gains == {"Ki": 0.002}
    assert np.array_equal(ap2.ctrl.p, _runtime(Kp=1.5, Kd=6.0, Ki=0.002).p)
    _step(ap2, 0.0)
    assert math.degrees(ap2.psi_set) == pytest.approx(123.0) and ap2.status()["course_source"] == "resumed"
    # the command line's course wins; a bad file is not used, with a reason
    ap3 = _ap(_runtime(), profiles, heading=0.5)
    assert resume(ap3, doc, keep_course=True) == [] and ap3.psi_set == pytest.approx(0.5)
    for text in ("{", "[]", json.dumps({**doc, "set_course": 1e308}), json.dumps({**doc, "version": 9})):
        path.write_text(text)
        assert read_state(path)[0] is None and read_state(path)[1]
    assert read_state(tmp_path / "missing.json") == (None, None)


def test_signed_link_refuses_forged_stale_and_replayed_datagrams():
    key = b"k" * 20
    signer = DeltaSigner(key, session=5)
    filt = SignedDeltaFilter(key, max_age=3.0)
    good = signer.sign('{"updates": []}', 1000.0)
    assert filt.accept(good, 1000.5) == ('{"updates": []}', "ok")
    assert filt.accept(good, 1000.5)[1] == "replayed"
    assert filt.accept(b'{"updates": []}', 1000.5)[1] == "unauthenticated"
    assert filt.accept(DeltaSigner(b"x" * 20).sign("{}", 1000.0), 1000.0)[1] == "bad_mac"
    assert filt.accept(signer.sign("{}", 990.0), 1000.0)[1] == "stale"
    forged = bytearray(signer.sign('{"a": 1}', 1000.0))
    forged[-3] ^= 1
    assert filt.accept(bytes(forged), 1000.0)[1] == "bad_mac"
    assert filt.counts == {"accepted": 1, "replayed": 1, "unauthenticated": 1, "bad_mac": 2, "stale": 1}


@pytest.mark.skipif(shutil.which("node") is None, reason="node not found (install Node.js >= 20)")
def test_the_plugin_and_steerlab_sign_and_verify_the_same_datagrams(tmp_path):
    """Parity of the two implementations of the signed link: node verifies what Python signs
    and Python verifies what node signs; both refuse the same tampered datagram."""
    import time

    key = b"a shared key for the parity test"
    now = time.time()
    py = DeltaSigner(key).sign('{"context": "vessels.self", "updates": []}', now)
    script = (
        "const p = require(process.argv[1]); const key = Buffer.from(process.argv[2]);"
        "const d = Buffer.from(process.argv[3], 'hex'); const bad = Buffer.from(d); bad[bad.length - 2] ^= 1;"
        "const s = new Map(); const ok = p.verifyDatagram(key, d, s, 3000, Date.now());"
        "const no = p.verifyDatagram(key, bad, new Map(), 3000, Date.now());"
        "const again = p.verifyDatagram(key, d, s, 3000, Date.now());"
        "const mine = p.signDatagram(key, { session: 3, seq: 0 }, '{\"x\": 1}');"
        "process.stdout.write(JSON.stringify({ ok, no, again, mine: mine.toString('hex') }))")
    res = subprocess.run(["node", "-e", script, str(PLUGIN / "index.js"), key.decode(), py.hex()],
                         capture_output=True, text=True, timeout=60)
    assert res.returncode == 0, res.stderr[-2000:]
    out = json.loads(res.stdout)
    assert out["ok"] == {"text": '{"context": "vessels.self", "updates": []}'}
    assert out["no"] == {"reason": "bad_mac"} and out["again"] == {"reason": "replayed"}
    assert SignedDeltaFilter(key).accept(bytes.fromhex(out["mine"]), time.time()) == ('{"x": 1}', "ok")
