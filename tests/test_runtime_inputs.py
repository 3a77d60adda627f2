"""The autopilot's unauthenticated inputs (NMEA 0183, Signal K over UDP) and the rpm order:
range and plausibility checks with a reason per rejection, the signed ship state preferred
over an NMEA heading, per-source rate limits, and the runtime details of issue 15.

Real sockets on loopback where the behaviour is about the network; bounds on counts carry the
slack a loaded machine needs (datagrams the kernel drops, time spent sending) and say so.
"""

from __future__ import annotations

import asyncio
import math
import socket
import time

import pytest

from steerlab.runtime import nmea
from steerlab.runtime import protocol as P
from steerlab.runtime.autopilot import Autopilot, AutopilotConfig
from steerlab.runtime.rejection_report import rejections
from steerlab.runtime.ship_server import ShipServer
from steerlab.runtime.udp import open_udp
from steerlab.sim.scenario import scenario_from_dict
from test_runtime_e2e import KEY, SPEEDUP, _read_log, _session, controller  # noqa: F401  (fixture)


def _r(kind, fields):
    return nmea.render(kind, fields)


APB_T = ["A", "A", "0.10", "R", "N", "V", "V", "45.0", "T", "WP1", "44.0", "T", "50.0", "T"]


@pytest.mark.parametrize("line, reason", [
    (_r("THS", ["1e300", "A"]), "out_of_range"),                 # the THS heading 1e300
    (_r("THS", ["nan", "A"]), "bad_field"),
    (_r("THS", ["-1.0", "A"]), "out_of_range"),
    (_r("THS", ["10.0", "V"]), "invalid_status"),                # mode V: data not valid
    (_r("THS", ["10.0", "X"]), "bad_field"),                     # not a THS mode letter
    (_r("THS", ["", "A"]), "missing_field"),
    (_r("HDT", ["400.0", "T"]), "out_of_range"),
    (_r("HDT", ["10.0", "M"]), "bad_field"),
    (_r("HTC", ["V", "", "", "H", "N", "", "", "", "", "100000", "", "", "T"]), "out_of_range"),  # course 1e5
    (_r("HTC", ["V", "", "", "H", "N", "", "", "", "", "inf", "", "", "T"]), "bad_field"),
    (_r("HTC", ["A", "", "", "H", "N", "", "", "", "", "10.0", "", "", "T"]), "not_heading_mode"),  # override
    (_r("HTC", ["V", "", "", "M", "N", "", "", "", "", "10.0", "", "", "T"]), "not_heading_mode"),  # manual
    (_r("HTC", ["V", "", "", "H", "N", "", "", "", "", "10.0", "", "", "M"]), "magnetic"),
    (_r("APB", ["A", "A", "0.10", "R", "N", "V", "V", "45.0", "M", "WP1", "44.0", "M", "50.0", "M"]), "magnetic"),
    (_r("APB", ["V", "A"] + APB_T[2:]), "invalid_status"),
    (_r("APB", ["A", "V"] + APB_T[2:]), "invalid_status"),
    (_r("APB", APB_T[:12] + ["361.0", "T"]), "out_of_range"),
    (_r("APB", APB_T[:2] + ["5000", "R", "N"] + APB_T[5:12] + ["", ""]), "out_of_range"),   # xte 5000 nmi
    (_r("APB", APB_T[:3] + ["X"] + APB_T[4:]), "bad_field"),
    (_r("RMB", ["V", "0.05", "L", "A", "B", "", "", "", "", "", "90.0", "", "V"]), "invalid_status"),
    (_r("RMB", ["A", "0.05", "L", "A", "B", "", "", "", "", "", "1e5", "", "V"]), "out_of_range"),
    (_r("XTE", ["V", "A", "0.1", "L", "N"]), "invalid_status"),
    ("$IIHDT,10.0,T*00\r\n", "malformed"),                       # bad checksum
])
def test_implausible_sentences_are_rejected_with_their_reason(line, reason):
    got = nmea.steering_inputs(line.encode())
    assert got["accepted"] == 0 and got["rejected"] == 1 and got["reasons"] == {reason: 1}, got["reasons"]
    assert got["heading"] is None and got["course"] is None


def test_good_sentences_are_accepted_and_others_ignored():
    lines = [_r("THS", ["359.99", "A"]), _r("HDT", ["360.0", "T"]), _r("APB", APB_T),
             _r("HTC", ["V", "", "", "H", "N", "", "", "", "", "123.4", "", "", "T"]),
             _r("XTE", ["A", "A", "0.1", "L", "N"]), _r("RSA", ["1.0", "A", "", "V"])]
    got = nmea.steering_inputs("".join(lines + [_r("VTG", ["10.0", "T", "", "M", "5.0", "N", "9.3", "K", "A"]),
                                                _r("GSV", ["1", "1", "00"])]).encode())
    # RSA is read (rudder feedback, issue 33), VTG too (speed over ground); GSV is valid but not used
    assert got["accepted"] == 7 and got["ignored"] == 1 and got["rejected"] == 0
    assert got["sog"] == pytest.approx(5.0 * 1852.0 / 3600.0)
    assert got["rudder"] == pytest.approx(math.radians(1.0))
    assert got["heading"] == 0.0                                 # 360 deg = north
    assert got["course"] == pytest.approx(math.radians(50.0)) and got["course_source"] == "APB"
    assert got["xte_m"] == pytest.approx(185.2)


def test_lines_past_32_per_datagram_are_counted_not_dropped():
    line = _r("HDT", ["10.0", "T"])
    got = nmea.steering_inputs((line * 40).encode())
    assert got["accepted"] == 32 and got["reasons"] == {"too_many_lines": 8} and got["rejected"] == 8


def test_not_ascii_is_one_rejection():
    got = nmea.steering_inputs(b"$IIHDT,\xff\xfe*00\r\n")
    assert got["reasons"] == {"not_ascii": 1} and got["rejected"] == 1


def _ap(controller, **cfg):  # noqa: F811
    return Autopilot(controller, ("127.0.0.1", 9), AutopilotConfig(**cfg), heading=0.0)


def test_rejections_are_counted_per_reason_and_shown_in_status(controller):  # noqa: F811
    ap = _ap(controller, input_rate=0.0)
    ap.on_nmea_datagram((_r("THS", ["1e300", "A"]) + _r("HDT", ["10.0", "T"]) + _r("GSV", ["1", "1", "00"])).encode(), t=0.0)
    ap.on_signalk_datagram(b'{"updates": [{"values": [{"path": "steering.autopilot.target.headingTrue", '
                           b'"value": 100.0}]}]}', t=0.0)
    ap.on_signalk_datagram(b'{"updates": [{"values": [{"path": "steering.autopilot.state", "value": "x"}]}]}', t=0.0)
    ap.on_signalk_datagram(b'not json', t=0.0)
    st = ap.status()
    assert st["nmea"] == {"accepted": 1, "ignored": 1, "out_of_range": 1}
    assert st["signalk"] == {"accepted": 0, "out_of_range": 1, "bad_field": 1, "malformed": 1}
    assert rejections(ap.nmea_counts) == {"out_of_range": 1}   # what the live rejection report prints
    ap.latest = P.State(0.0, 0.0, 0.0, 0.0, 0.0, 5.0, 0.0, 0.0, math.nan, 0.0, 0)
    row = ap.sample(0.0)                                       # and the CSV log, every sample
    assert row["nmea_rejected"] == 1 and row["signalk_rejected"] == 3
    assert ap.psi_set == 0.0 and ap.nmea_heading[0] == pytest.approx(math.radians(10.0))


def test_signed_state_heading_wins_over_nmea_unless_chosen(controller):  # noqa: F811
    for key, over, want in ((None, False, "nmea"), (KEY, False, "state"), (KEY, True, "nmea")):
        ap = Autopilot(controller, ("127.0.0.1", 9), AutopilotConfig(nmea_heading_over_signed=over),
                       heading=0.0, key=key)
        ap.latest = P.State(0.0, 0.0, 0.0, 0.0, 0.0, 5.0, 0.0, 0.0, math.nan, 0.0, 0)
        ap.latest_t = 0.0
        ap.on_nmea_datagram(_r("HDT", ["90.0", "T"]).encode(), t=0.0)
        assert ap.sample(0.0)["heading_source"] == want


def _spoof_heading(ctx):
    """An unauthenticated process on the autopilot's NMEA port: HDT 90 deg, 40 times a ship second."""
    async def spoof():
        ap = ctx["ap"]
        tr = await open_udp(ap.on_nmea_datagram, ("127.0.0.1", 0))
        port = tr.get_extra_info("sockname")[1]
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
            line = _r("HDT", ["90.0", "T"]).encode()
            try:
                while ap._stop is not None and not ap._stop.is_set():
                    s.sendto(line, ("127.0.0.1", port))
                    await asyncio.sleep(0.025 / SPEEDUP)
            finally:
                tr.close()
    ctx["spoofer"] = asyncio.get_running_loop().create_task(spoof())


@pytest.mark.parametrize("over", [False, True])
def test_spoofed_nmea_heading_does_not_move_the_rudder_of_a_signed_link(controller, tmp_path, over):  # noqa: F811
    log = tmp_path / "ap.csv"
    ctx = asyncio.run(_session(controller, log, 8.0, [(2.0, _spoof_heading)], key=KEY,
                               ap_cfg=AutopilotConfig(speedup=SPEEDUP, watchdog_timeout=3.0, nmea_timeout=20.0,
                                                      nmea_heading_over_signed=over)))
    rows = [r for r in _read_log(log) if r["t"] > 3.0 and r["link_ok"]]
    ap = ctx["ap"]
    true_psi = math.degrees(ctx["server"].state().psi)              # the ship's own heading at the end
    # the spoofed lines arrived and parsed; one is enough, as a line stays fresh for the rest of
    # the session (nmea_timeout 20 s): how many arrive depends on how busy the machine is
    assert len(rows) >= 5 and ap.nmea_counts["accepted"] >= 1
    assert ap.nmea_heading is not None and math.degrees(ap.nmea_heading[0]) == pytest.approx(90.0)
    if not over:    # default: the signed state steers; course kept, rudder near midships (waves only)
        assert all(r["heading_source"] == "state" for r in rows)
        assert max(abs(r["psi_deg"]) for r in rows) < 2.0 and abs(true_psi) < 2.0
        assert max(abs(r["delta_cmd_deg"]) for r in rows) < 10.0
    else:           # the user's choice: the false heading steers (hard to port: 90 deg "off")
        assert all(r["heading_source"] == "nmea" and r["psi_deg"] == 90.0 for r in rows)
        assert min(r["delta_cmd_deg"] for r in rows) < -30.0 and true_psi < -10.0


def _flood(port: int, n: int, sock: socket.socket, payload: bytes) -> None:
    for _ in range(n):
        try:
            sock.sendto(payload, ("127.0.0.1", port))
        except BlockingIOError:
            pass


@pytest.mark.parametrize("which", ["nmea", "signalk"])
def test_udp_input_is_rate_limited_per_source(controller, which):  # noqa: F811
    ap = _ap(controller, input_rate=100.0, input_burst=100.0)     # per source, speedup 1
    on, counts = ((ap.on_nmea_datagram, ap.nmea_counts) if which == "nmea"
                  else (ap.on_signalk_datagram, ap.signalk_counts))
    payload = (_r("HDT", ["10.0", "T"]).encode() if which == "nmea" else
               b'{"updates": [{"values": [{"path": "steering.autopilot.target.headingTrue", "value": 0.5}]}]}')
    received = []

    async def go():
        tr = await open_udp(lambda d, a: (received.append(a), on(d, a)), ("127.0.0.1", 0))
        port = tr.get_extra_info("sockname")[1]
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as flooder, \
                socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as peer:
            flooder.setblocking(False)
            flooder.bind(("127.0.0.1", 0))
            peer.bind(("127.0.0.1", 0))
            t0 = time.monotonic()
            for _ in range(50):                      # 2 000 datagrams in bursts of 40
                _flood(port, 40, flooder, payload)
                await asyncio.sleep(0.001)
            await asyncio.sleep(0.05)                # the loop drains the socket
            elapsed = time.monotonic() - t0
            during_flood = dict(counts), len(received)
            for _ in range(10):                      # the legitimate peer, 10 datagrams, own bucket
                peer.sendto(payload, ("127.0.0.1", port))
                await asyncio.sleep(0.005)
            await asyncio.sleep(0.05)
            tr.close()
            return flooder.getsockname(), peer.getsockname(), elapsed, during_flood

    flooder, peer, elapsed, (flood_counts, n_flood) = asyncio.run(go())
    # loopback drops what the socket buffer cannot hold: at least a quarter arrives
    assert received[:n_flood].count(flooder) == n_flood > 500
    # the flooder got its burst plus the refill over the elapsed time (measured), no more
    assert flood_counts["accepted"] <= 100 + 100.0 * elapsed + 1
    assert flood_counts["rate_limited"] >= n_flood - 100 - 100.0 * elapsed - 1
    assert flood_counts["accepted"] + flood_counts["rate_limited"] == n_flood
    n_peer = received[n_flood:].count(peer)          # all of the peer's that arrived were used
    assert n_peer >= 5 and counts["accepted"] - flood_counts["accepted"] == n_peer
    assert counts["rate_limited"] == flood_counts["rate_limited"]


# ------------------------------------------------------------------ runtime details of issue 15
def _capella():
    return scenario_from_dict({"name": "capella-rpm", "dt": 0.05, "duration": 10.0,
                               "ship": {"model": "capella-nomoto-10deg", "speed_kn": 10.0,
                                        "options": {"rpm": 150.0}},
                               "controller": {"type": "pid"}})


def test_capella_rpm_orders_over_udp_no_traceback_and_applied():
    """Capella (indexed by propeller rate) with rpm orders: applied through [ship.options] rpm,
    out of range refused and counted once per order value, never an exception in the loop."""
    errors = []

    async def go():
        loop = asyncio.get_running_loop()
        loop.set_exception_handler(lambda lp, ctx: errors.append(ctx))
        server = ShipServer(_capella())
        ps0 = server.ps.copy()
        srv = asyncio.create_task(server.run())
        while server.transport is None:
            await asyncio.sleep(0.001)
        sender = P.Sender()
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
            for rpm in [180.0] * 5 + [500.0] * 5 + [0.0] * 5:
                s.sendto(sender.pack(P.Command(0.0, rpm), time.time()), server.address)
                await asyncio.sleep(0.01)
                if rpm == 180.0:
                    ps180 = server.ps.copy()
        await asyncio.sleep(0.05)
        server.stop()
        await srv
        return server, ps0, ps180

    server, ps0, ps180 = asyncio.run(go())
    assert errors == [] and server.stats.commands == 15
    assert dict(server.rpm_counts) == {"accepted": 1, "refused": 2}
    assert server.rpm == 180.0 and server.state().rpm == 180.0 and not (ps180 == ps0).all()
    assert "rpm order 0 refused: ship.options.rpm" in server.rpm_error and "110" in server.rpm_error


def test_rpm_order_zero_is_applied_to_a_ship_with_a_propeller():
    d = {"name": "esso-rpm", "dt": 0.1, "duration": 10.0, "ship": {"model": "esso", "speed_kn": 16.0},
         "controller": {"type": "pid"}}
    server = ShipServer(scenario_from_dict(d))
    before = server.ps.copy()
    server.apply_command(P.Command(0.0, 0.0))
    assert server.rpm == 0.0 and server.rpm_counts["accepted"] == 1 and not (server.ps == before).all()
    assert AutopilotConfig(rpm_cmd=0.0).validate().rpm_cmd == 0.0       # --rpm 0 is a valid order


def test_off_course_alarm_does_not_trip_on_a_change_equal_to_its_limit(controller):  # noqa: F811
    """Heading 0.05 deg to port but swinging to starboard; course changed by exactly the 10 deg
    limit to port: the old rule armed at once (9.95 deg <= 10) and the swing tripped it."""
    from test_runtime_autopilot_logic import _feed

    ap = _ap(controller, off_course_limit=math.radians(10.0))
    _feed(ap, 0.0, psi=math.radians(-0.05), r=math.radians(0.5))
    ap.sample(0.0)
    ap.adjust(-10.0, 0.1)
    for k, psi in enumerate([-0.05, 0.05, 0.1, 0.0, -2.0, -5.0, -8.0, -10.0]):
        t = 0.125 * (k + 1)
        _feed(ap, t, psi=math.radians(psi))
        assert ap.sample(t)["alarms"] == "", (k, psi)
    assert ap.off_course_armed
    _feed(ap, 2.0, psi=math.radians(-21.0))                       # a real excursion still trips it
    assert ap.sample(2.0)["alarms"] == "off_course"


def test_warning_for_network_wide_nmea_and_signalk_listen(tmp_path, capsys):
    from runtime_scenario import runtime_scenario_toml
    from steerlab.cli import build_parser
    from steerlab.commands.autopilot import build_autopilot

    sc = tmp_path / "s.toml"
    sc.write_text(runtime_scenario_toml("warn", 10.0))
    base = ["autopilot", "--connect", "127.0.0.1:47110", "--scenario", str(sc), "--log", str(tmp_path / "l.csv")]
    for extra, warned in ((["--nmea-listen", "0.0.0.0:10111"], "--nmea-listen on 0.0.0.0"),
                          (["--signalk-listen", "0.0.0.0:10112"], "--signalk-listen on 0.0.0.0"),
                          (["--nmea-listen", "127.0.0.1:10111"], None)):
        build_autopilot(build_parser().parse_args(base + extra))
        err = capsys.readouterr().err
        if warned:
            assert warned in err and "without authentication" in err
        else:
            assert "warning" not in err


@pytest.mark.parametrize("connect, host, bind", [("127.0.0.2:47110", "127.0.0.2", "127.0.0.1"),
                                                 ("[::1]:47110", "::1", "::1"),
                                                 ("localhost:47110", "localhost", "127.0.0.1")])
def test_cli_connect_to_a_loopback_ship_binds_loopback_of_its_family(tmp_path, connect, host, bind):
    """``--connect 127.0.0.2`` or ``[::1]`` sends from loopback of the same family, never 0.0.0.0
    (the socket-level run over both is ``test_runtime_bind.py``)."""
    from runtime_scenario import runtime_scenario_toml
    from steerlab.cli import build_parser
    from steerlab.commands.autopilot import build_autopilot

    sc = tmp_path / "s.toml"
    sc.write_text(runtime_scenario_toml("bind", 10.0))
    ap, _ = build_autopilot(build_parser().parse_args(
        ["autopilot", "--connect", connect, "--scenario", str(sc), "--log", str(tmp_path / "l.csv")]))
    assert ap.connect == (host, 47110) and ap.bind == (bind, 0)


@pytest.mark.parametrize("argv, flag", [
    (["autopilot-command", "--to", "999.1.1.1:10111", "--key-file", "examples/data/demo-link.key", "--heading", "10"],
     "--to"),
    (["autopilot", "--connect", "999.1.1.1:47110", "--controller", "pid", "--heading", "10", "--duration", "3"],
     "--connect"),
    (["autopilot", "--connect", "127.0.0.1:47110", "--controller", "nosuch", "--heading", "10", "--duration", "1"],
     "--controller"),
], ids=["autopilot-command", "autopilot", "autopilot-controller"])
def test_a_host_that_does_not_resolve_is_one_line_naming_the_flag(argv, flag, capsys, monkeypatch):
    """``autopilot-command --to 999.1.1.1:...`` ended in a socket.gaierror traceback (exit 1);
    ``autopilot --connect`` with it sat in the safe state for the whole run and exited 0."""
    from pathlib import Path

    from steerlab.cli import main

    monkeypatch.chdir(Path(__file__).resolve().parent.parent)        # examples/data/demo-link.key
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    what = "unknown type 'nosuch'" if flag == "--controller" else "cannot resolve host '999.1.1.1'"
    assert err.startswith(f"steerlab: error: {flag}: {what}") and len(err.splitlines()) == 1


def test_plotter_mode_with_any_nmea_input_as_the_autopilot_starts_in_it(tmp_path):
    """``--mode plotter`` was refused at the command line unless ``--nmea-listen`` was given,
    although the autopilot starts in plotter mode with any NMEA input (``--nmea-tcp`` too) and a
    plotter's APB/RMB arrive on any of them."""
    from runtime_scenario import runtime_scenario_toml
    from steerlab.cli import build_parser
    from steerlab.commands.autopilot import build_autopilot

    sc = tmp_path / "s.toml"
    sc.write_text(runtime_scenario_toml("plotter", 10.0))
    base = ["autopilot", "--connect", "127.0.0.1:47110", "--scenario", str(sc), "--log", str(tmp_path / "l.csv")]
    for extra in (["--nmea-tcp", "127.0.0.1:10110"], ["--nmea-listen", "127.0.0.1:10111"]):
        ap, _ = build_autopilot(build_parser().parse_args(base + extra + ["--mode", "plotter"]))
        assert ap.steering_mode == "plotter"
        default, _ = build_autopilot(build_parser().parse_args(base + extra))
        assert default.steering_mode == "plotter"                 # the start mode the same input implies
    from steerlab.errors import InputError

    with pytest.raises(InputError) as e:
        build_autopilot(build_parser().parse_args(base + ["--mode", "plotter"]))
    assert e.value.field == "--mode" and "--nmea-tcp" in e.value.message and "--nmea-listen" in e.value.message
