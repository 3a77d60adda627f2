"""From the simulator to a boat (issue 33), with real parts: a magnetic compass on a
pseudo-terminal steering the ship server, NMEA over TCP as client and server on loopback,
and a rudder drive on a pseudo-terminal (a separate process with first-order rudder dynamics)
whose injected faults put the autopilot in its safe state.

Ship and controller: the e2e tests' (``nomoto1`` K 0.5 1/s, T 10 s, PID), so the kernels are
shared. Assertions are on ship-time logs and counters; the only clock bounds are the generous
hang guards and the issue's "alarm within 2 s" (ship seconds after the last feedback, against a
1-s detection limit).
"""

from __future__ import annotations

import asyncio
import math
from collections import Counter
import os
import select
import subprocess
import sys

import pytest

from steerlab.runtime import nmea
from steerlab.runtime.actuator import FEEDBACK_LOST, ActuatorMonitor
from steerlab.runtime.actuator_serial import SerialActuator
from steerlab.runtime.alarms import ACTUATOR
from steerlab.runtime.autopilot import Autopilot, AutopilotConfig
from steerlab.runtime.heading_health import heading_alarm
from steerlab.runtime.nmea_streams import NmeaSerialInput, NmeaTcpClient, NmeaTcpServer
from steerlab.runtime.ship_server import ShipServer, ShipServerConfig
from steerlab.sim.scenario import scenario_from_dict
from test_runtime_e2e import SCENARIO, SPEEDUP, _read_log, controller  # noqa: F401  (fixture)

DEV_E, VAR_W = 1.5, 7.0          #: the compass's deviation (east) and the variation (west) [deg]


def _hdg_line(psi_true: float) -> bytes:
    """An HDG line of a compass whose sensor reads ``true - dev - var`` (dev 1.5 E, var 7.0 W)."""
    sensor = (math.degrees(psi_true) - DEV_E + VAR_W) % 360.0
    return nmea.render("HDG", [f"{sensor:.1f}", f"{DEV_E:.1f}", "E", f"{VAR_W:.1f}", "W"], "HC").encode()


async def _run(controller, log, duration, ap_kwargs, ap_cfg, tasks=(), speedup=SPEEDUP, heading=0.0):  # noqa: F811
    """Ship server + autopilot (+ ``tasks``: coroutines taking ``ctx``) for ``duration`` ship s."""
    server = ShipServer(scenario_from_dict(SCENARIO), ShipServerConfig(speedup=speedup, centre_after=2.0))
    srv = asyncio.create_task(server.run())
    while server.transport is None:
        await asyncio.sleep(0.001)
    ap = Autopilot(controller, server.address, ap_cfg, heading=heading, log_path=log, **ap_kwargs)
    ctx = {"server": server, "ap": ap}
    running = [asyncio.create_task(t(ctx)) for t in tasks]
    try:
        await asyncio.wait_for(ap.run(duration), timeout=duration / speedup + 120.0)  # hang guard (0: until stopped)
        for t in running:
            if t.done() and not t.cancelled() and t.exception() is not None:
                raise t.exception()
    finally:
        for t in running:
            t.cancel()
        server.stop()
        await srv
    return ctx


async def _port_open(ap):
    """Until the autopilot has the serial port open (pyserial empties the input buffer on
    opening: a line written before would be lost)."""
    while not ap.nmea_stream_inputs or not ap.nmea_stream_inputs[0].link.connected:
        await asyncio.sleep(0.005)


def test_hdg_compass_on_a_pty_steers_the_ship_to_the_set_course(controller, tmp_path):  # noqa: F811
    """A compass sending HDG only (deviation 1.5 E, variation 7 W in its own fields) on a
    pseudo-terminal: the autopilot steers by it (source ``nmea``) and the ship's TRUE heading
    settles on the set course; had the deviation or variation been ignored it would settle
    1.5, 5.5 or 7 deg off."""
    master, slave = os.openpty()
    path = os.ttyname(slave)
    os.close(slave)          # the port is opened by path, as a device; closed, its node goes with the master
    true_track = []

    async def compass(ctx):
        server, ap = ctx["server"], ctx["ap"]
        await _port_open(ap)
        while True:
            psi = server.state().psi
            true_track.append((ap.clock(), math.degrees(psi)))
            os.write(master, _hdg_line(psi))
            await asyncio.sleep(0.1 / SPEEDUP)                # 10 Hz of ship time

    # 5 s of ship time (0.5 s wall) before the compass counts as stale: a loaded machine's stalls
    cfg = AutopilotConfig(speedup=SPEEDUP, watchdog_timeout=3.0, nmea_timeout=5.0)
    try:
        ctx = asyncio.run(_run(controller, tmp_path / "ap.csv", 40.0,
                               {"nmea_streams": [lambda cb: NmeaSerialInput(path, 4800, cb)]}, cfg,
                               [compass], heading=math.radians(30.0)))
    finally:
        os.close(master)
    ap = ctx["ap"]
    rows = _read_log(tmp_path / "ap.csv")
    steered = [r for r in rows if r["t"] > 2.0 and r["link_ok"]]
    by_compass = sum(r["heading_source"] == "nmea" for r in steered)
    assert by_compass >= 0.9 * len(steered), (by_compass, len(steered))
    written = len(true_track)
    assert written > 30 and ap.nmea_counts["accepted"] >= written - 5          # every line read, but the last
    assert ap.nmea_counts.get("malformed", 0) == 0
    end = [psi for t, psi in true_track if t >= 30.0]
    assert len(end) >= 5 and max(abs(psi - 30.0) for psi in end) < 1.5, max(abs(psi - 30.0) for psi in end)
    # the compass heading the autopilot read is the true one (not the sensor's magnetic reading)
    assert ap.heading_health["nmea"].good is not None
    assert abs(math.degrees(ap.heading_health["nmea"].good[0]) - true_track[-1][1]) < 2.0


def test_garbage_and_a_vanishing_compass_are_counted_and_the_state_heading_takes_over(controller, tmp_path):  # noqa: F811
    """Garbage bytes, an endless line and an RMC with a 45-deg variation on the compass line
    are counted, never raise; then the device vanishes (the pty's other side closes): one line,
    the ``lost`` counter, the ``heading_nmea`` alarm, and the state heading steers on."""
    master, slave = os.openpty()
    path = os.ttyname(slave)
    os.close(slave)          # the port is opened by path, as a device; closed, its node goes with the master
    log_lines = []
    marks = {}

    async def compass(ctx):
        server, ap = ctx["server"], ctx["ap"]
        await _port_open(ap)
        marks["rounds"] = 0
        for k in range(40):
            os.write(master, _hdg_line(server.state().psi))
            if k % 10 == 3:
                marks["rounds"] += 1
                os.write(master, b"\x00\xff\xfe$HCHDG,1*ZZ\r\n$HCHDG,garbage*ZZ\r\n%!~#\r\n" + bytes(range(128, 160)) + b"\r\n")
            if k == 5:
                os.write(master, b"A" * 5000)                                          # no line end
                os.write(master, b"\r\n")
                os.write(master, nmea.render("RMC", ["120000", "A", "5430.0000", "N", "01854.0000", "E", "5.0",
                                                     "10.0", "281126", "45.0", "W"], "GP").encode())
            await asyncio.sleep(0.1 / SPEEDUP)
        while ap.nmea_counts["accepted"] + ap.nmea_counts["variation_out_of_range"] < 41:
            await asyncio.sleep(0.002)                   # the last lines read (the hang guard bounds it)
        marks["rejected_before_loss"] = dict(ap.nmea_counts)
        marks["t_gone"] = ap.clock()
        os.close(master)                                 # the device vanishes
        marks["closed"] = True
        while not ap.alarms.active(heading_alarm("nmea")):
            await asyncio.sleep(0.01)
        t_alarm = ap.clock()
        while ap.clock() < t_alarm + 3.0:                # 3 s of ship time steered by the state heading
            await asyncio.sleep(0.01)
        ap.stop()

    cfg = AutopilotConfig(speedup=SPEEDUP, watchdog_timeout=3.0, nmea_timeout=3.0)
    stream = {}

    def make(cb):
        stream["s"] = NmeaSerialInput(path, 4800, cb, log=log_lines.append, reopen_period=0.2)
        return stream["s"]

    try:
        ctx = asyncio.run(_run(controller, tmp_path / "ap.csv", 0.0, {"nmea_streams": [make]}, cfg, [compass]))
    finally:
        if not marks.get("closed"):
            os.close(master)
    ap = ctx["ap"]
    counts = marks["rejected_before_loss"]
    n = marks["rounds"]                              # 2 non-ASCII and 2 malformed lines a round
    assert n == 4 and counts["malformed"] == 2 * n and counts["not_ascii"] == 2 * n
    assert counts["variation_out_of_range"] == 1 and counts["accepted"] == 40
    assert stream["s"].counts["lost"] == 1 and stream["s"].counts["overlong"] >= 1
    assert sum("lost" in ln for ln in log_lines) == 1 and all("\n" not in ln for ln in log_lines)
    raised = [t for t, n, w in ap.alarms.history if n == heading_alarm("nmea") and w == "raised"]
    assert raised and raised[-1] >= marks["t_gone"]
    rows = _read_log(tmp_path / "ap.csv")
    late = [r for r in rows if r["t"] > raised[-1]]
    assert late and all(r["heading_source"] == "state" and r["mode"] == "auto" for r in late)
    assert all("heading_nmea" in r["alarms"] for r in late)


async def _tcp_lines(writer, lines, n=20):
    for _ in range(n):
        writer.write(lines)
        await writer.drain()
        await asyncio.sleep(0.005)


def test_nmea_over_tcp_as_server_and_as_client(controller):  # noqa: F811
    """NMEA on real loopback TCP sockets: talkers connecting to the autopilot's port, and the
    autopilot connecting to a talker (and reconnecting after the talker closed)."""
    ap = Autopilot(controller, ("127.0.0.1", 9), AutopilotConfig(input_rate=0.0), heading=0.0)
    line = nmea.render("HDT", ["123.4", "T"]).encode() + nmea.render("HDM", ["120.0", "M"]).encode()

    async def main():
        srv = await NmeaTcpServer("127.0.0.1", 0, lambda d, a: ap.on_nmea_datagram(d, a, t=0.0)).start()
        host, port = srv.address
        r, w = await asyncio.open_connection(host, port)
        w.write(line[:7])                                # split mid-line: reassembled
        await w.drain()
        await asyncio.sleep(0.02)
        w.write(line[7:])
        await w.drain()
        await _tcp_lines(w, line)
        w.close()
        for _ in range(400):
            if ap.nmea_counts["accepted"] >= 21:
                break
            await asyncio.sleep(0.01)
        await srv.close()
        got_server = dict(ap.nmea_counts)

        # the autopilot as client of a talker that hangs up once
        sessions = []

        async def talker(reader, writer):
            sessions.append(writer)
            await _tcp_lines(writer, nmea.render("HDT", ["200.0", "T"]).encode(), 5)
            writer.close()

        talk = await asyncio.start_server(talker, "127.0.0.1", 0)
        client = await NmeaTcpClient("127.0.0.1", talk.sockets[0].getsockname()[1],
                                     lambda d, a: ap.on_nmea_datagram(d, a, t=1.0), reconnect_period=0.05,
                                     log=lambda s: None).start()
        for _ in range(400):
            if client.counts["connected"] >= 2:
                break
            await asyncio.sleep(0.01)
        await client.close()
        talk.close()
        return got_server, client.counts

    got_server, client_counts = asyncio.run(asyncio.wait_for(main(), 60.0))
    # 21 HDT accepted; each HDM rejected: no variation known (never steered by uncorrected)
    assert got_server["accepted"] == 21 and got_server["magnetic"] == 21
    assert client_counts["connected"] >= 2 and client_counts["disconnected"] >= 1
    assert ap.nmea_heading[0] == pytest.approx(math.radians(200.0))


def _emulator(master: int, *args) -> subprocess.Popen:
    """The drive process on the pty's master side, once it serves (its start-up imports
    steerlab: seconds on a loaded machine; 120 s hang guard)."""
    proc = subprocess.Popen([sys.executable, "-m", "steerlab.runtime.actuator_emulator", "--fd", str(master),
                             "--time-constant", "0.3", "--rate", "15", *args],
                            pass_fds=(master,), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    ready = select.select([proc.stdout], [], [], 120.0)[0] and proc.stdout.readline()
    if not ready or "ready" not in ready:
        proc.kill()
        raise AssertionError(f"the actuator emulator did not start: {proc.communicate(timeout=30)}")
    return proc


def _actuator_session(controller, tmp_path, emulator_args, duration, tasks=()):  # noqa: F811
    master, slave = os.openpty()
    path = os.ttyname(slave)
    os.close(slave)          # the port is opened by path, as a device; closed, its node goes with the master
    proc = _emulator(master, *emulator_args)
    os.close(master)                             # the emulator holds the drive's side
    drive = SerialActuator(f"{path}:38400", ActuatorMonitor(feedback_timeout=1.0, stall_time=2.0),
                           log=lambda s: None)
    cfg = AutopilotConfig(speedup=1.0, watchdog_timeout=3.0)
    try:
        ctx = asyncio.run(_run(controller, tmp_path / "ap.csv", duration, {"actuator": drive}, cfg,
                               [t for t in tasks], speedup=1.0, heading=math.radians(40.0)))
    finally:
        proc.kill()                              # the process this test started, by its handle
        out, err = proc.communicate(timeout=30)
    ctx["emulator_out"] = out
    return ctx, _read_log(tmp_path / "ap.csv"), drive


def test_actuator_losing_feedback_mid_turn_gives_alarm_and_safe_state(controller, tmp_path):  # noqa: F811
    """The drive on a pty follows the orders (first-order, rate-limited rudder) until the rudder
    passes 8 deg on its way to a 40-deg course change, then sends no more feedback: the
    ``actuator`` alarm within 2 s of the last feedback, midships ordered, disengaged, and it
    stays so (no re-engagement by itself)."""
    ctx, rows, drive = _actuator_session(controller, tmp_path, ["--lose-feedback-above", "8"], 7.0)
    ap = ctx["ap"]
    assert "fault injected: feedback lost" in ctx["emulator_out"]
    assert drive.counts["feedback"] >= 2 and drive.counts.get("malformed", 0) == 0
    last_feedback = drive.monitor.angle[1]
    assert math.degrees(abs(drive.monitor.angle[0])) > 5.0          # it was turning when lost
    raised = ap.alarms.first_raised(ACTUATOR)
    assert raised is not None and 0.0 < raised - last_feedback <= 2.0, (raised, last_feedback)
    assert FEEDBACK_LOST in drive.faults(ap.clock())
    before = [r for r in rows if r["t"] < last_feedback]
    assert any(r["mode"] == "auto" and abs(r["delta_cmd_deg"]) > 5.0 for r in before)   # it was steering
    after = [r for r in rows if r["t"] >= raised]
    assert after and all(r["mode"] == "safe" and r["delta_cmd_deg"] == 0.0 and "actuator" in r["alarms"]
                         for r in after)
    assert not ap.engaged and not ap.want_engaged


def test_actuator_device_vanishing_gives_alarm_and_safe_state(controller, tmp_path):  # noqa: F811
    """The drive process dies (its pty side closes): ``device_lost`` and ``feedback_lost``,
    the alarm, midships ordered, disengaged; the port is retried, nothing raises."""
    marks = {}

    async def kill_drive(ctx):
        ap = ctx["ap"]
        while ap.clock() < 2.0:
            await asyncio.sleep(0.01)
        marks["t_kill"] = ap.clock()
        marks["proc"].kill()

    master, slave = os.openpty()
    path = os.ttyname(slave)
    os.close(slave)          # the port is opened by path, as a device; closed, its node goes with the master
    proc = marks["proc"] = _emulator(master)
    os.close(master)
    drive = SerialActuator(f"{path}:38400", ActuatorMonitor(feedback_timeout=1.0), log=lambda s: None)
    try:
        ctx = asyncio.run(_run(controller, tmp_path / "ap.csv", 5.0, {"actuator": drive},
                               AutopilotConfig(speedup=1.0, watchdog_timeout=3.0), [kill_drive], speedup=1.0,
                               heading=math.radians(40.0)))
    finally:
        proc.kill()
        proc.communicate(timeout=30)
    ap = ctx["ap"]
    raised = ap.alarms.first_raised(ACTUATOR)
    assert raised is not None and raised >= marks["t_kill"]
    rows = _read_log(tmp_path / "ap.csv")
    assert all(r["mode"] == "safe" and r["delta_cmd_deg"] == 0.0 for r in rows if r["t"] >= raised)
    assert not ap.engaged


def test_an_implausible_compass_hands_over_to_the_state_heading_with_an_alarm(controller):  # noqa: F811
    """The autopilot's own wiring of the heading health: a compass that jumps 90 deg is not
    steered by (counted ``implausible``), the state heading takes over with the alarm, and the
    compass steers again once its readings agree; a fresh RSA is the measured rudder angle."""
    from steerlab.runtime import protocol as P

    ap = Autopilot(controller, ("127.0.0.1", 9), AutopilotConfig(input_rate=0.0), heading=0.0)
    ap.latest = P.State(0.0, 0.0, 0.0, math.radians(1.0), 0.0, 5.0, 0.0, 0.0, math.nan, 0.0, 0)
    ap.latest_t = 0.0
    for k in range(5):
        ap.on_nmea_datagram(_hdg_line(math.radians(2.0)), t=0.1 * k)
    row = ap.sample(0.5)
    assert row["heading_source"] == "nmea" and row["psi_deg"] == pytest.approx(2.0, abs=0.06)
    ap.latest_t = 0.6
    ap.on_nmea_datagram(_hdg_line(math.radians(92.0)), t=0.6)
    row = ap.sample(0.625)
    assert row["heading_source"] == "state" and "heading_nmea" in row["alarms"]
    assert ap.nmea_counts["implausible"] == 1 and row["nmea_rejected"] == 1
    for k in range(3):
        ap.on_nmea_datagram(_hdg_line(math.radians(92.0)), t=0.7 + 0.1 * k)
    ap.latest_t = 0.9
    ap.on_nmea_datagram(nmea.render("RSA", ["-3.0", "A", "", "V"]).encode(), t=0.9)
    row = ap.sample(1.0)
    assert row["heading_source"] == "nmea" and row["psi_deg"] == pytest.approx(92.0, abs=0.06)
    assert "heading_nmea" not in row["alarms"]
    assert ap.ctrl.x[-1] == pytest.approx(math.radians(-3.0))       # the RSA angle, not the state's 0
    st = ap.status()
    assert st["heading_sources"] == {"nmea": "fresh", "signalk": "unseen"}
    assert st["rudder_feedback"] == pytest.approx(math.radians(-3.0))
    assert st["actuator"]["name"] == "sim" and st["actuator"]["faults"] == {}


def test_signalk_magnetic_heading_needs_and_takes_the_variation(controller):  # noqa: F811
    from steerlab.runtime.signalk_input import input_values

    ap = Autopilot(controller, ("127.0.0.1", 9), AutopilotConfig(), heading=0.0)
    counts = Counter()
    ap.on_signalk_values(input_values({"navigation.headingMagnetic": 1.0}, counts), t=0.0)
    assert ap.signalk_counts["magnetic"] == 1 and ap.heading_health["signalk"].last is None   # never uncorrected
    bad = {"navigation.magneticVariation": math.radians(40.0), "navigation.headingTrue": 7.0,
           "navigation.position": {"latitude": 95.0, "longitude": 0.0}, "steering.rudderAngle": "x"}
    assert input_values(bad, counts) == {}
    assert counts == {"accepted": 1, "variation_out_of_range": 1, "out_of_range": 2, "bad_field": 1}
    ap.on_signalk_values(input_values({"navigation.magneticVariation": math.radians(-4.0),
                                       "navigation.headingMagnetic": math.radians(100.0),
                                       "navigation.position": {"latitude": 54.5, "longitude": 18.9}}, counts), t=0.1)
    assert math.degrees(ap.heading_health["signalk"].good[0]) == pytest.approx(96.0)
    assert ap.signalk_nav["navigation.position"] == (54.5, 18.9)


def test_a_signalk_server_feeding_the_heading_steers_the_ship(controller, tmp_path):  # noqa: F811
    """serve-ship's Signal K stream (a real WebSocket) as the autopilot's heading source: with
    no NMEA heading, the ``signalk`` source steers (priority nmea > signalk > state) and the
    ship reaches the set course."""
    async def main():
        server = ShipServer(scenario_from_dict(SCENARIO), ShipServerConfig(speedup=SPEEDUP, centre_after=2.0),
                            signalk_ws=("127.0.0.1", 0))
        srv = asyncio.create_task(server.run())
        while server.signalk_stream is None:
            await asyncio.sleep(0.005)
        ap = Autopilot(controller, server.address,
                       AutopilotConfig(speedup=SPEEDUP, watchdog_timeout=3.0, nmea_timeout=3.0),
                       heading=math.radians(30.0), log_path=tmp_path / "ap.csv",
                       signalk_input=tuple(server.signalk_stream.address))
        try:
            await asyncio.wait_for(ap.run(40.0), timeout=40.0 / SPEEDUP + 60.0)
        finally:
            server.stop()
            await srv
        return ap

    ap = asyncio.run(main())
    rows = _read_log(tmp_path / "ap.csv")
    steered = [r for r in rows if r["t"] > 3.0 and r["link_ok"]]
    by_signalk = sum(r["heading_source"] == "signalk" for r in steered)
    assert by_signalk >= 0.9 * len(steered), (by_signalk, len(steered))
    assert ap.signalk_source.counts["accepted"] > 20
    end = [r for r in rows if r["t"] >= 30.0 and r["heading_source"] == "signalk"]
    assert len(end) >= 10 and max(abs(r["psi_deg"] - 30.0) for r in end) < 1.5
