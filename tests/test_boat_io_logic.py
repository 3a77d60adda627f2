"""From the simulator to a boat (issue 33), the pure parts: magnetic compasses and variation,
heading-source health, stream line splitting, the actuator line protocol, the actuator fault
monitor and the driver loading (entry-point group ``steerlab.actuators``). No sockets, no
clock: times are passed in."""

from __future__ import annotations

import math

import pytest

from steerlab.errors import InputError
from steerlab.runtime import nmea
from steerlab.runtime.actuator import (FEEDBACK_LOST, NO_MOVEMENT, OVER_CURRENT, ActuatorMonitor,
                                       load_actuator)
from steerlab.runtime.actuator_protocol import parse_feedback, parse_order, render_feedback, render_order
from steerlab.runtime.alarms import AlarmBoard
from steerlab.runtime.heading_health import (FRESH, IMPLAUSIBLE, STALE, UNSEEN, HeadingHealth, heading_alarm,
                                             select_heading)
from steerlab.runtime.line_splitter import LineSplitter, nmea_chunks
from steerlab.runtime.nmea_magnetic import check_variation_option, variation_in_effect


def _r(kind, fields, talker="II"):
    return nmea.render(kind, fields, talker)


def _deg(x):
    return math.degrees(x) % 360.0


# ---------------------------------------------------------------- magnetic headings and courses
def test_hdg_deviation_and_variation_make_the_true_heading():
    # IEC 61162-1 HDG: magnetic = sensor + deviation (E +); true = magnetic + variation (E +)
    got = nmea.steering_inputs(_r("HDG", ["101.1", "1.5", "E", "7.1", "W"], "HC").encode())
    assert got["accepted"] == 1 and _deg(got["heading"]) == pytest.approx(101.1 + 1.5 - 7.1)
    got = nmea.steering_inputs(_r("HDG", ["359.0", "", "", "3.0", "E"], "HC").encode())
    assert _deg(got["heading"]) == pytest.approx(2.0)                    # wraps through north
    # its own variation wins over the configured one
    got = nmea.steering_inputs(_r("HDG", ["100.0", "", "", "3.0", "E"], "HC").encode(), variation=math.radians(-10))
    assert _deg(got["heading"]) == pytest.approx(103.0)


def test_hdm_needs_a_variation_from_rmc_or_configuration():
    hdm = _r("HDM", ["120.0", "M"], "HC")
    assert nmea.steering_inputs(hdm.encode())["reasons"] == {"magnetic": 1}           # never uncorrected
    assert _deg(nmea.steering_inputs(hdm.encode(), variation=math.radians(4.0))["heading"]) == pytest.approx(124.0)
    rmc = _r("RMC", ["120000", "A", "5430.0000", "N", "01854.0000", "E", "5.0", "10.0", "281126", "6.5", "W"], "GP")
    got = nmea.steering_inputs((rmc + hdm).encode(), variation=math.radians(4.0))      # the RMC's comes first
    assert got["accepted"] == 2 and got["variation"] == pytest.approx(math.radians(-6.5))
    assert _deg(got["heading"]) == pytest.approx(113.5)


@pytest.mark.parametrize("line", [
    _r("HDG", ["100.0", "", "", "31.0", "W"], "HC"),
    _r("HDG", ["100.0", "45.0", "E", "1.0", "W"], "HC"),
    _r("RMC", ["120000", "A", "5430.0000", "N", "01854.0000", "E", "5.0", "10.0", "281126", "45.0", "W"], "GP"),
])
def test_a_variation_or_deviation_beyond_30_deg_is_one_rejection(line):
    got = nmea.steering_inputs(line.encode(), variation=math.radians(2.0))
    assert got["reasons"] == {"variation_out_of_range": 1} and got["heading"] is None and got["variation"] is None


def test_bad_variation_letters_are_bad_fields():
    got = nmea.steering_inputs(_r("HDG", ["100.0", "", "", "3.0", "X"], "HC").encode())
    assert got["reasons"] == {"bad_field": 1}


def test_magnetic_apb_and_htc_steer_with_the_variation_applied():
    apb_m = _r("APB", ["A", "A", "0.00", "R", "N", "V", "V", "45.0", "M", "WP1", "44.0", "M", "50.0", "M"])
    assert nmea.steering_inputs(apb_m.encode())["reasons"] == {"magnetic": 1}          # as before: no variation
    got = nmea.steering_inputs(apb_m.encode(), variation=math.radians(-5.0))
    assert got["accepted"] == 1 and got["course_source"] == "APB" and _deg(got["course"]) == pytest.approx(45.0)
    htc_m = _r("HTC", ["V", "", "", "H", "N", "", "", "", "", "10.0", "", "", "M"])
    assert _deg(nmea.steering_inputs(htc_m.encode(), variation=math.radians(3.0))["course"]) == pytest.approx(13.0)


def test_rsa_is_the_rudder_feedback_checked():
    assert nmea.steering_inputs(_r("RSA", ["-4.5", "A", "", "V"]).encode())["rudder"] == pytest.approx(math.radians(-4.5))
    assert nmea.steering_inputs(_r("RSA", ["4.5", "V", "", "V"]).encode())["reasons"] == {"invalid_status": 1}
    assert nmea.steering_inputs(_r("RSA", ["120", "A", "", "V"]).encode())["reasons"] == {"out_of_range": 1}


def test_variation_option_and_the_variation_in_effect():
    assert check_variation_option(-12.5) == -12.5 and check_variation_option(None) is None
    for bad in (30.5, -45.0, float("nan"), "east"):
        with pytest.raises(InputError, match=r"--variation: magnetic variation must be a number in \[-30, 30\]"):
            check_variation_option(bad)
    assert variation_in_effect((0.1, 100.0), math.nan, 200.0) == 0.1           # an RMC's, while held
    assert variation_in_effect((0.1, 100.0), 0.05, 100.0 + 601.0) == 0.05      # then the configured one
    assert variation_in_effect(None, math.nan, 0.0) is None


# ---------------------------------------------------------------- heading-source health
def test_a_heading_source_goes_fresh_stale_and_implausible_and_recovers():
    h = HeadingHealth("nmea", timeout=2.0, max_rate=math.radians(45.0))
    assert h.status(0.0) == UNSEEN
    for k in range(10):                                    # a 3 deg/s turn at 10 Hz: plausible
        assert h.observe(math.radians(0.3 * k), 0.1 * k)
    assert h.status(1.0) == FRESH and h.status(0.9 + 2.01) == STALE
    assert not h.observe(math.radians(90.0), 1.0)          # 87 deg in 0.1 s: beyond any ship
    assert h.status(1.0) == IMPLAUSIBLE and h.heading(1.0) is None
    assert not h.observe(math.radians(90.1), 1.1) and not h.observe(math.radians(90.2), 1.2)
    assert h.observe(math.radians(90.3), 1.3)              # 3 agreeing readings: the new value is taken
    assert h.status(1.3) == FRESH and _deg(h.heading(1.3)) == pytest.approx(90.3)
    assert h.counts == {"accepted": 11, "implausible": 3}
    assert not h.observe(float("nan"), 1.4)


def test_the_next_source_takes_over_with_an_alarm_naming_it():
    board = AlarmBoard()
    nmea_h = HeadingHealth("nmea", timeout=2.0)
    sources = {"nmea": nmea_h}
    assert select_heading(0.0, ("nmea", "state"), sources, 0.5, board) == (0.5, "state")   # unseen: no alarm
    assert not board.active(heading_alarm("nmea"))
    nmea_h.observe(1.0, 0.0)
    assert select_heading(1.0, ("nmea", "state"), sources, 0.5, board) == (1.0, "nmea")
    assert select_heading(3.0, ("nmea", "state"), sources, 0.5, board) == (0.5, "state")
    assert board.active("heading_nmea") and "steering by the state heading" in board.alarms["heading_nmea"].message
    nmea_h.observe(1.0, 3.1)
    assert select_heading(3.1, ("nmea", "state"), sources, 0.5, board) == (1.0, "nmea")
    assert not board.active("heading_nmea")
    nmea_h.observe(2.5, 3.2)                               # a jump: implausible, alarm again
    assert select_heading(3.2, ("nmea", "state"), sources, 0.5, board)[1] == "state"
    assert board.active("heading_nmea") and "implausible" in board.alarms["heading_nmea"].message


def test_without_any_other_heading_the_alarm_says_so():
    """On a boat there is no ship state to fall back on: the alarm said "steering by the state
    heading" all the same."""
    board = AlarmBoard()
    nmea_h = HeadingHealth("nmea", timeout=2.0)
    nmea_h.observe(1.0, 0.0)
    assert select_heading(3.0, ("nmea",), {"nmea": nmea_h}, None, board) == (None, "state")
    assert board.alarms["heading_nmea"].message.endswith(": no heading left to steer by")


def test_true_from_magnetic_never_gives_360():
    """3 deg magnetic with -3 deg variation (from radians) summed to -4e-16, which ``% 360``
    rounds to 360.0; that is north: 0."""
    from steerlab.runtime.nmea_magnetic import true_from_magnetic

    assert true_from_magnetic(3.0, math.degrees(math.radians(-3.0))) == 0.0
    assert true_from_magnetic(359.0, 2.0) == pytest.approx(1.0) and true_from_magnetic(10.0, -3.0) == 7.0


# ---------------------------------------------------------------- streams
def test_line_splitter_reassembles_and_bounds_lines():
    sp = LineSplitter(max_line=100)
    assert sp.feed(b"$IIHDT,1") == [] and sp.feed(b"0.0,T*00\r\n$A\n\n") == [b"$IIHDT,10.0,T*00", b"$A"]
    assert sp.feed(b"x" * 150) == [] and sp.counts["overlong"] == 1
    assert sp.feed(b"yyy\r\n$B\r\n") == [b"$B"]             # the rest of the overlong line is skipped
    chunks = list(nmea_chunks([b"$A"] * 40 + [b"\xff\xfe", b"$B"], max_lines=32))
    assert [c.count(b"\r\n") for c in chunks] == [32, 8, 1, 1] and chunks[2] == b"\xff\xfe\r\n"


# ---------------------------------------------------------------- the actuator
def test_actuator_protocol_round_trips_and_rejects_garbage():
    line = render_order(math.radians(-10.0), True)
    assert line == "$PSTLO,-10.0,E*23\r\n"                  # the example of docs/runtime.md
    assert parse_order(line) == (pytest.approx(math.radians(-10.0)), True)
    assert render_order(math.radians(-0.01), True) == "$PSTLO,0.0,E*3F\r\n"          # never -0.0
    assert parse_order(render_order(None, False)) == (None, False)
    fb = parse_feedback(render_feedback(math.radians(-4.2), "A", 3.1))
    assert fb.angle == pytest.approx(math.radians(-4.2)) and fb.status == "A" and fb.current == 3.1
    assert parse_feedback(render_feedback(None, "V")).angle is None
    for bad in (b"$PSTLF,1.0,A,*00\r\n", b"\xff\xfe", b"$PSTLF,100.0,A,*" + b"00", "$PSTLF,1.0,X,",
                render_feedback(0.1).replace("A", "Q"), render_order(0.1, True), "garbage"):
        assert parse_feedback(bad) is None
    assert parse_order(render_feedback(0.1)) is None


def test_actuator_monitor_faults():
    m = ActuatorMonitor(feedback_timeout=0.5, stall_time=2.0)
    assert m.faults(10.0) == {}                                       # standby: nothing expected
    m.ordered(math.radians(20.0), 0.0)
    assert m.faults(0.4) == {} and FEEDBACK_LOST in m.faults(0.6)     # never any feedback
    for k in range(30):                                               # feedback, the rudder moving
        t = 0.1 * k
        m.feedback(math.radians(min(20.0, 2.0 * t)), t)
        m.ordered(math.radians(20.0), t)
        assert m.faults(t) == {}
    m2 = ActuatorMonitor(feedback_timeout=0.5, stall_time=2.0)        # a jammed rudder
    for k in range(30):
        t = 0.1 * k
        m2.feedback(math.radians(3.0), t)
        m2.ordered(math.radians(20.0), t)
    assert NO_MOVEMENT in m2.faults(2.9) and FEEDBACK_LOST not in m2.faults(2.9)
    m2.ordered(None, 3.0)
    assert m2.faults(3.0) == {}                                       # standby ends it
    m2.report_over_current(True)
    assert OVER_CURRENT in m2.faults(3.0)


def test_actuator_drivers_load_by_name_and_from_the_entry_point_group(monkeypatch):
    from importlib import metadata

    assert load_actuator("sim").name == "sim"
    drive = load_actuator("serial:/dev/ttyUSB7:9600")
    assert (drive.path, drive.baud) == ("/dev/ttyUSB7", 9600)
    with pytest.raises(InputError, match="unknown actuator 'nope'; known: serial, sim"):
        load_actuator("nope")

    class FakeDrive:
        name = "fake"

        def __init__(self, arg):
            self.arg = arg

    ep = metadata.EntryPoint("fake", "test_boat_io_logic:FakeDrive", "steerlab.actuators")
    monkeypatch.setattr(metadata, "entry_points",
                        lambda group=None: [ep] if group == "steerlab.actuators" else [])
    monkeypatch.setattr(metadata.EntryPoint, "load", lambda self: FakeDrive)
    assert load_actuator("fake:port=3").arg == "port=3"


def test_cli_bad_boat_inputs_are_one_line_and_exit_2(capsys):
    from steerlab.cli import main

    for argv, want in ((["--variation", "45"], "--variation: magnetic variation must be a number in [-30, 30]"),
                       (["--nmea-serial", "/dev/no-such-tty:4800"], "--nmea-serial: no such device"),
                       (["--nmea-serial", "/dev/null:1234"], "--nmea-serial: baud rate must be one of"),
                       (["--actuator", "serial:/dev/no-such-tty"], "--actuator: no such device"),
                       (["--actuator", "warp"], "--actuator: unknown actuator 'warp'"),
                       (["--nmea-tcp", "127.0.0.1:0"], "--nmea-tcp: port must be in [1, 65535]")):
        assert main(["autopilot", "--connect", "127.0.0.1:47110", *argv]) == 2
        err = capsys.readouterr().err.strip()
        assert want in err and len(err.splitlines()) == 1, err
