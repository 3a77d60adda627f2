"""A boat with no ship-state datagram (issue 33): the autopilot measures heading, rate of turn,
position, speed and rudder from its sensors alone, each source with a health state, and a stale
or implausible one raises an alarm while the next source of the stated priority takes over.

End to end with real parts: the ship server stands for the boat's hull and water only; its
"sensors" write NMEA 0183 (HDG compass, ROT, RMC, VTG) on a pseudo-terminal read as a serial
port, and the rudder orders reach it through a drive of their own (a separate UDP socket, so no
ship state ever reaches the autopilot). Assertions on ship-time logs; clock bounds are hang
guards only.
"""

from __future__ import annotations

import asyncio
import math
import os
import time

import pytest

from steerlab.runtime import nmea
from steerlab.runtime import protocol as P
from steerlab.runtime.alarms import LINK, POSITION
from steerlab.runtime.autopilot import Autopilot, AutopilotConfig
from steerlab.runtime.boat_sensors import BoatSensors, HeadingRate, local_position
from steerlab.runtime.nmea_streams import NmeaSerialInput
from steerlab.runtime.route import route_guidance
from steerlab.runtime.ship_server import ShipServer, ShipServerConfig
from steerlab.runtime.source_health import source_alarm
from steerlab.runtime.udp import open_udp, send
from steerlab.sim.scenario import scenario_from_dict
from test_runtime_boat_io import _hdg_line, _port_open
from test_runtime_e2e import SCENARIO, SPEEDUP, _read_log, controller  # noqa: F401  (fixture)


class ShipRudder:
    """The boat's rudder drive for these tests: orders as COMMAND datagrams to the ship server
    from a socket of its own (the ship's states go there, never to the autopilot)."""

    name = "ship-rudder"

    def __init__(self, addr):
        self.addr, self.sender, self.tr = addr, P.Sender(None), None

    async def start(self, autopilot) -> None:
        self.tr = await open_udp(lambda d, a: None, ("127.0.0.1", 0))

    def order(self, command, t: float) -> None:
        if command is not None:
            send(self.tr, self.sender.pack(command, time.time()), self.addr)

    def rudder(self, t: float):
        return None

    def faults(self, t: float) -> dict:
        return {}

    async def close(self) -> None:
        if self.tr is not None:
            self.tr.close()


def _sensor_lines(state, with_nav: bool) -> bytes:
    """What the boat's sensors send: an HDG compass; with ``with_nav`` also ROT, RMC and VTG."""
    out = _hdg_line(state.psi)
    if with_nav:
        kinds = ("ROT", "RMC", "VTG")
        out += "".join(s for s in nmea.state_sentences(state) if s[3:6] in kinds).encode()
    return out


async def _boat(controller, log, duration, cfg, route=None, heading=None, with_nav=True, stop_at=None):  # noqa: F811
    server = ShipServer(scenario_from_dict(SCENARIO), ShipServerConfig(speedup=SPEEDUP, centre_after=2.0))
    srv = asyncio.create_task(server.run())
    while server.transport is None:
        await asyncio.sleep(0.001)
    master, slave = os.openpty()
    path = os.ttyname(slave)
    os.close(slave)
    ap = Autopilot(controller, None, cfg, heading=heading, route=route, log_path=log,
                   nmea_streams=[lambda cb: NmeaSerialInput(path, 4800, cb)], actuator=ShipRudder(server.address))
    truth = []

    async def sensors():
        await _port_open(ap)
        while stop_at is None or ap.clock() < stop_at:
            st = server.state()
            truth.append((ap.clock(), st))
            os.write(master, _sensor_lines(st, with_nav))
            await asyncio.sleep(0.1 / SPEEDUP)                # 10 Hz of ship time

    task = asyncio.create_task(sensors())
    try:
        await asyncio.wait_for(ap.run(duration), timeout=duration / SPEEDUP + 120.0)   # hang guard
        if task.done() and task.exception() is not None:
            raise task.exception()
    finally:
        task.cancel()
        server.stop()
        await srv
        os.close(master)
    return ap, server, truth


def test_compass_gnss_and_rate_sensor_alone_steer_a_route(controller, tmp_path):  # noqa: F811
    """No ship state: HDG + ROT + RMC + VTG on a serial port; the route (250 m north, then
    300 m east) is followed by RMC positions, the PID's yaw rate is the ROT sentence's and the
    speed VTG/RMC's, and the autopilot's position is the ship's true one."""
    f = tmp_path / "route.csv"
    f.write_text("x_n,y_e\n0,0\n250,0\n250,300\n")
    plan = route_guidance(scenario_from_dict(SCENARIO), controller.setup.ship, controller.setup.ps, str(f),
                          lookahead_L=1.0)
    cfg = AutopilotConfig(speedup=SPEEDUP, watchdog_timeout=3.0, nmea_timeout=10.0)   # 1 s wall: a loaded machine stalls
    ap, server, truth = asyncio.run(_boat(controller, tmp_path / "ap.csv", 110.0, cfg, route=plan))
    rows = _read_log(tmp_path / "ap.csv")
    steered = [r for r in rows if r["t"] > 2.0]
    bad = [(r["t"], r["mode"], r["alarms"]) for r in steered if not (r["link_ok"] and r["mode"] == "auto")]
    assert len(bad) <= 0.05 * len(steered), bad[:5]     # a loaded machine's stall may cost a few samples
    assert all(math.isnan(r["t_sim"]) for r in rows)                       # never a ship state
    assert ap.measured["sources"] == {"position": "nmea", "speed": "nmea", "rate": "nmea", "rudder": "order"}
    legs = {r["leg"] for r in steered}
    assert 1 in legs                                                         # the waypoint was passed
    if truth[0][1].x_n < 150.0:          # the ship server runs from its own start: on a loaded
        assert 0 in legs                 # machine the autopilot can start near the waypoint
    end = server.state()
    assert abs(end.x_n - 250.0) < 10.0 and end.y_e > 150.0, (end.x_n, end.y_e)   # on the second leg
    assert abs(rows[-1]["xte_m"]) < 10.0
    # the position the autopilot steered by is the ship's (RMC: 0.2 m quantisation, 0.1 s of lag)
    t_last, st_last = truth[-1]
    assert math.hypot(rows[-1]["x_n"] - st_last.x_n, rows[-1]["y_e"] - st_last.y_e) < 5.0
    assert rows[-1]["u"] == pytest.approx(math.hypot(st_last.u, st_last.v), abs=0.05)
    active = [a["name"] for a in ap.alarms.snapshot() if a["active"]]
    assert ap.nmea_counts["accepted"] >= 4 * 100 and not [n for n in active if n != "off_course"], active


def test_compass_alone_steers_by_the_derived_yaw_rate_and_its_loss_is_the_link_alarm(controller, tmp_path):  # noqa: F811
    """HDG only: the yaw rate is the filtered derivative of the compass heading, the speed the
    design speed; the ship settles on the set course. The compass then goes silent: its alarm,
    the link alarm (no fresh heading from any sensor) and the safe state (midships)."""
    cfg = AutopilotConfig(speedup=SPEEDUP, watchdog_timeout=1.0, nmea_timeout=2.0)
    ap, server, truth = asyncio.run(_boat(controller, tmp_path / "ap.csv", 50.0, cfg, heading=math.radians(30.0),
                                          with_nav=False, stop_at=40.0))
    rows = _read_log(tmp_path / "ap.csv")
    end = [math.degrees(st.psi) for t, st in truth if 30.0 <= t < 40.0]
    assert len(end) >= 20 and max(abs(p - 30.0) for p in end) < 1.5
    # the yaw rate it steered by follows the ship's (the derivative of a 0.1-deg compass)
    import bisect

    times = [t for t, _ in truth]
    def ship_r(t):
        return math.degrees(truth[min(bisect.bisect(times, t), len(truth) - 1)][1].r)

    turn = [r for r in rows if 1.0 <= r["t"] < 15.0]     # the turn to 30 deg: |r| up to a few deg/s
    err = sum(abs(r["r_deg_s"] - ship_r(r["t"])) for r in turn) / len(turn)
    size = sum(abs(ship_r(r["t"])) for r in turn) / len(turn)
    assert len(turn) > 80 and size > 0.5 and err < 0.5 * size, (err, size)   # lags by tau = 1 s; 0 would give err = size
    assert ap.measured["sources"]["rate"] == "heading" and ap.measured["sources"]["speed"] == "design"
    assert all(r["u"] == pytest.approx(controller.design_speed) for r in rows if r["link_ok"])
    raised = ap.alarms.first_raised(LINK)
    assert raised is not None and 40.0 < raised <= 40.0 + 2.0 + 1.0 + 0.5
    after = [r for r in rows if r["t"] >= raised]
    assert after and all(r["mode"] == "safe" and r["delta_cmd_deg"] == 0.0 for r in after)
    assert ap.alarms.active("heading_nmea")
    # no ship state on a boat: the alarm does not claim a heading it does not have, and the page's
    # status shows no frozen measurement (it kept the last sample's rudder, yaw rate and speed)
    assert ap.alarms.alarms["heading_nmea"].message.endswith("no heading left to steer by")
    status = ap.status()
    assert not status["link_ok"] and status["yaw_rate"] is None and status["speed"] is None
    assert status["rudder"] == status["actuator"]["rudder"]        # the drive's own feedback, live


class _Drive:
    name = "test-drive"

    def rudder(self, t):
        return None

    def faults(self, t):
        return {}


def _boat_ap(controller, heading=0.0, **kw):  # noqa: F811
    return Autopilot(controller, None, AutopilotConfig(nmea_timeout=1.0, watchdog_timeout=1.0), heading=heading,
                     actuator=_Drive(), **kw)


def _lines(*sentences) -> bytes:
    return "".join(nmea.render(k, f) for k, f in sentences).encode()


def _rmc(x_n, y_e, sog_kn=10.0):
    st = P.State(0.0, x_n, y_e, 0.0, 0.0, sog_kn * 1852.0 / 3600.0, 0.0, 0.0, math.nan, 0.0, 0)
    return next(s for s in nmea.state_sentences(st) if s[3:6] == "RMC")


def test_every_source_has_a_health_and_the_next_one_takes_over(controller):  # noqa: F811
    """Rate of turn: ROT, then Signal K, then the heading's derivative; position: RMC, then
    Signal K after an implausible jump (1 km in 0.1 s), back once RMC agrees again; speed out of
    range is implausible; each bad source raises its alarm naming the one that took over."""
    ap = _boat_ap(controller)
    sk_pos = nmea.geo_position(10.0, 20.0, nmea.DEFAULT_ORIGIN)
    t = 0.0
    for k in range(8):                                   # 0.0 .. 0.7 s: everything fresh
        t = 0.1 * k
        ap.on_nmea_datagram(_lines(("HDT", ["10.0", "T"]), ("ROT", ["30.0", "A"])) + _rmc(100.0, 0.0).encode(), t=t)
        ap.on_signalk_values({"navigation.rateOfTurn": math.radians(0.2), "navigation.position": sk_pos,
                              "navigation.speedOverGround": 4.0}, t=t)
        ap.sample(t)
    m = ap.measured
    assert m["sources"]["rate"] == "nmea" and m["r"] == pytest.approx(math.radians(0.5))
    assert m["sources"]["position"] == "nmea" and (m["x_n"], m["y_e"]) == pytest.approx((100.0, 0.0), abs=0.3)
    assert m["sources"]["speed"] == "nmea" and m["u"] == pytest.approx(10.0 * 1852 / 3600, abs=0.01)
    # an RMC 1 km away 0.1 s later: implausible, Signal K's position takes over, alarm raised
    t = 0.8
    ap.on_nmea_datagram(_lines(("HDT", ["10.0", "T"])) + _rmc(1100.0, 0.0).encode(), t=t)
    ap.on_signalk_values({"navigation.position": sk_pos}, t=t)
    ap.sample(t)
    assert ap.measured["sources"]["position"] == "signalk"
    assert (ap.measured["x_n"], ap.measured["y_e"]) == pytest.approx((10.0, 20.0), abs=0.01)
    assert ap.alarms.active(source_alarm("position", "nmea"))
    assert "using the signalk position" in ap.alarms.alarms[source_alarm("position", "nmea")].message
    assert ap.nmea_counts["implausible"] >= 1
    # ROT stops; after its timeout (1 s) Signal K's rate takes over, with the alarm
    for k in range(9, 22):
        t = 0.1 * k
        ap.on_nmea_datagram(_lines(("HDT", ["10.0", "T"])) + _rmc(1100.0 + 0.5 * (k - 8), 0.0).encode(), t=t)
        ap.on_signalk_values({"navigation.rateOfTurn": math.radians(0.2), "navigation.position": sk_pos}, t=t)
        ap.sample(t)
    assert ap.measured["sources"]["rate"] == "signalk" and ap.alarms.active(source_alarm("rate", "nmea"))
    # three agreeing RMC fixes ended the implausible spell: RMC again, its alarm cleared
    assert ap.measured["sources"]["position"] == "nmea" and not ap.alarms.active(source_alarm("position", "nmea"))
    # Signal K goes silent too: the yaw rate is the heading's derivative (a steady heading: 0)
    for k in range(22, 40):
        t = 0.1 * k
        ap.on_nmea_datagram(_lines(("HDT", ["10.0", "T"])), t=t)
        ap.sample(t)
    assert ap.measured["sources"]["rate"] == "heading" and ap.measured["r"] == pytest.approx(0.0, abs=1e-9)
    assert ap.alarms.active(source_alarm("rate", "signalk"))
    # no fresh position any more: in route mode that would hold the course (alarm), not here
    assert ap.measured["x_n"] is None and not ap.alarms.active(POSITION)
    assert ap.measured["sources"]["speed"] == "design"
    st = ap.status()
    assert st["sensor_sources"]["rate"] == {"nmea": "stale", "signalk": "stale"}


def test_implausible_and_out_of_range_readings_are_counted_never_raise(controller):  # noqa: F811
    ap = _boat_ap(controller)
    bad = [("ROT", ["9999", "A"]), ("ROT", ["1.0", "V"]), ("ROT", ["x", "A"]), ("VTG", ["", "T", "", "M", "99", "N", "", "K", "A"]),
           ("GGA", ["120000", "4807.038", "N", "01131.000", "E", "0", "08", "0.9", "545.4", "M", "46.9", "M", "", ""]),
           ("GGA", ["120000", "4807.038", "X", "01131.000", "E", "1", "08", "0.9", "545.4", "M", "46.9", "M", "", ""]),
           ("GGA", ["120000", "9107.038", "N", "01131.000", "E", "1", "08", "0.9", "545.4", "M", "46.9", "M", "", ""])]
    ap.on_nmea_datagram(_lines(*bad), t=0.0)
    assert ap.nmea_counts == {"accepted": 0, "out_of_range": 3, "invalid_status": 2, "bad_field": 2}
    ap.on_signalk_values({"navigation.speedOverGround": 45.0}, t=0.0)      # checked, but faster than a boat
    assert ap.signalk_counts["implausible"] == 1
    row = ap.sample(0.0)
    assert row["mode"] == "safe" and row["link_ok"] == 0 and ap.cmd_sent == 0.0   # no heading: midships


def test_heading_rate_filter_follows_a_steady_turn_and_restarts_after_a_gap():
    f = HeadingRate(tau=1.0, max_gap=1.0)
    r = math.radians(3.0)
    for k in range(200):                                 # 3 deg/s through north, 0.1-deg quantised
        psi = math.radians(round(math.degrees(r * 0.125 * k - 1.0), 1))
        f.update(psi, 0.125 * k)
    assert f.value == pytest.approx(r, abs=math.radians(0.1))
    f.update(0.0, 200 * 0.125 + 5.0)                     # a 5-s gap: not a rate
    assert f.value is None


def test_local_position_inverts_the_nmea_position():
    for x, y in ((0.0, 0.0), (1852.0, -926.0), (-20_000.0, 35_000.0)):
        lat, lon = nmea.geo_position(x, y, (-33.9, 151.2))
        assert local_position(lat, lon, (-33.9, 151.2)) == pytest.approx((x, y), abs=1e-6)
    # across the antimeridian
    assert local_position(0.0, -179.999, (0.0, 179.999))[1] == pytest.approx(222.4, abs=0.5)


def test_a_sim_actuator_needs_a_ship_server(controller):  # noqa: F811
    from steerlab.errors import InputError

    with pytest.raises(InputError, match="--connect"):
        Autopilot(controller, None, AutopilotConfig())
    assert BoatSensors(1.0, (0.0, 0.0)).status(0.0)["chosen"] == {}


def test_the_cli_on_a_boat_compass_on_a_pty_and_a_drive_on_another(tmp_path):
    """``steerlab autopilot`` without ``--connect``: a compass (HDG, turning at 1 deg/s) on one
    pseudo-terminal, the drive emulator (first-order rudder) on another. The autopilot steers
    by the compass, orders the drive, reads the rudder angle back from it; then the compass
    stops: link alarm, midships. Real processes throughout."""
    import csv
    import subprocess
    import sys

    from test_runtime_boat_io import _emulator

    d_master, d_slave = os.openpty()
    drive_path = os.ttyname(d_slave)
    os.close(d_slave)
    drive = _emulator(d_master)
    os.close(d_master)
    c_master, c_slave = os.openpty()
    compass_path = os.ttyname(c_slave)
    os.close(c_slave)
    log = tmp_path / "ap.csv"
    proc = subprocess.Popen([sys.executable, "-m", "steerlab", "autopilot", "--nmea-serial", compass_path,
                             "--actuator", f"serial:{drive_path}:38400", "--heading", "30", "--duration", "12",
                             "--log", str(log), "--watchdog", "1", "--report-every", "0"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        t0 = time.monotonic()
        deadline = t0 + 120.0                                   # hang guard: the start-up imports and loads kernels
        started = None
        while proc.poll() is None and time.monotonic() < deadline:
            if started is None and log.exists() and log.stat().st_size > 200:
                started = time.monotonic()                      # sampling: the compass speaks for 6 s
            if started is not None and time.monotonic() - started > 6.0:
                break
            psi = math.radians(10.0 + (time.monotonic() - t0))
            try:
                os.write(c_master, _hdg_line(psi))
            except OSError:
                break
            time.sleep(0.1)
        out, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
        drive.kill()
        drive.communicate(timeout=30)
        os.close(c_master)
    assert proc.returncode == 0, err[-2000:]
    assert "sensors only" in err and "Traceback" not in err
    with open(log, newline="") as f:
        rows = list(csv.DictReader(f))
    steered = [r for r in rows if r["link_ok"] == "1"]
    assert len(steered) > 10 and all(r["heading_source"] == "nmea" and r["mode"] == "auto" for r in steered)
    assert all(r["t_sim"] == "nan" for r in rows)
    # the drive answered: the rudder angle it reports moves with the orders (not stuck at 0)
    assert max(abs(float(r["delta_deg"])) for r in steered) > 1.0
    assert all(r["delta_cmd_deg"] != "nan" for r in steered)
    # the compass stopped before the end: the link alarm and midships
    tail = rows[-3:]
    assert all(r["link_ok"] == "0" and r["mode"] == "safe" and float(r["delta_cmd_deg"]) == 0.0
               and "link" in r["alarms"] for r in tail), tail


def test_on_a_boat_a_state_datagram_is_refused_and_counted(controller):  # noqa: F811
    """Without a ship server any STATE datagram is some local process's forgery: never a
    measurement (it would otherwise outrank the sensors for position, speed and rate)."""
    ap = _boat_ap(controller)
    forged = P.Sender(None).pack(P.State(0.0, 5000.0, 0.0, 1.0, 0.3, 9.0, 0.0, 0.0, math.nan, 0.0, 0), time.time())
    ap.on_state_datagram(forged, ("127.0.0.1", 4000), t=0.0)
    ap.on_nmea_datagram(_lines(("HDT", ["10.0", "T"])) + _rmc(100.0, 0.0).encode(), t=0.0)
    ap.sample(0.0)
    assert ap.latest is None and ap.filter.counts["no_ship_server"] == 1
    assert ap.measured["sources"]["position"] == "nmea" and ap.measured["x_n"] == pytest.approx(100.0, abs=0.3)
    assert ap.steered[1] == "nmea"


def test_route_mode_without_a_position_holds_its_reference_with_an_alarm(controller, tmp_path):  # noqa: F811
    f = tmp_path / "route.csv"
    f.write_text("x_n,y_e\n0,0\n250,0\n250,300\n")
    plan = route_guidance(scenario_from_dict(SCENARIO), controller.setup.ship, controller.setup.ps, str(f),
                          lookahead_L=1.0)
    ap = _boat_ap(controller, heading=None, route=plan)
    for k in range(4):                                   # a compass, no GNSS
        ap.on_nmea_datagram(_lines(("HDT", ["20.0", "T"])), t=0.1 * k)
        ap.sample(0.1 * k)
    assert ap.alarms.active(POSITION) and ap.mode == "auto"
    assert math.degrees(ap.psi_set) == pytest.approx(20.0) and ap.ref[1] == 0.0     # held, not turning
    for k in range(4, 8):                                # the GNSS comes: the route steers, alarm cleared
        ap.on_nmea_datagram(_lines(("HDT", ["20.0", "T"])) + _rmc(10.0, 30.0).encode(), t=0.1 * k)
        row = ap.sample(0.1 * k)
    assert not ap.alarms.active(POSITION) and ap.course_source == "route" and row["leg"] == 0
    assert abs(row["xte_m"]) == pytest.approx(30.0, abs=0.5)        # 30 m east of the first leg
