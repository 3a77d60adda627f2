"""A real signalk-server as the autopilot's sensor source (issue 33): serve-ship's NMEA 0183
(HDT, THS, ROT, RSA, RMC, VTG over UDP) goes into signalk-server's own NMEA parser, and the
autopilot subscribes to the server's stream (``--signalk-input``) for heading, position, rate
of turn and rudder angle; with no NMEA heading of its own, the Signal K heading steers the ship
to its set course. Skipped where signalk-server is not installed (``.ci/setup-signalk``).
"""

from __future__ import annotations

import asyncio
import json
import math
import os
import subprocess
import urllib.request

from steerlab.runtime.autopilot import Autopilot, AutopilotConfig
from steerlab.runtime.nmea import DEFAULT_ORIGIN
from steerlab.runtime.ship_server import ShipServer, ShipServerConfig
from steerlab.sim.scenario import scenario_from_dict
from test_runtime_e2e import SCENARIO, _read_log, controller  # noqa: F401  (fixture)
from test_signalk_plugin import SERVER_BIN, _free_port, _until, needs_server

SPEED = 2.0
"""A gentler speed-up than the e2e tests': the heading passes through node (UDP, its NMEA
parser, the stream) at 8 datagrams per wall second, and its delay on a loaded machine counts
SPEED times in ship time (at 5x the PID steered by a heading seconds old and swung)."""


def _config(tmp, udp_port):
    cfg = tmp / "signalk"
    cfg.mkdir()
    (cfg / "settings.json").write_text(json.dumps({
        "interfaces": {"tcp": False, "nmea-tcp": False, "appstore": False, "mfd_webapp": False, "wasm": False,
                       "plugins": False},
        "mdns": False, "ssl": False,
        "pipedProviders": [{"id": "steerlab-nmea", "enabled": True, "pipeElements": [
            {"type": "providers/udp", "options": {"port": udp_port}},
            {"type": "providers/nmea0183-signalk",
             "optionMappings": [{"fromAppProperty": "selfId", "toOption": "selfId"},
                                {"fromAppProperty": "selfType", "toOption": "selfType"}]}]}]}))
    return cfg


@needs_server
def test_a_signalk_server_feeding_heading_and_position_steers_the_ship(controller, tmp_path):  # noqa: F811
    import socket

    udp_port, http_port = _free_port(socket.SOCK_DGRAM), _free_port()
    env = {**os.environ, "PORT": str(http_port), "SIGNALK_DISABLE_SERVER_UPDATES": "1"}
    log = open(tmp_path / "signalk-server.log", "wb")
    server = subprocess.Popen(["node", str(SERVER_BIN), "-c", str(_config(tmp_path, udp_port))], env=env,
                              stdout=log, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL)

    def up():
        if server.poll() is not None:
            raise AssertionError("signalk-server exited: " + (tmp_path / "signalk-server.log").read_text()[-2000:])
        try:
            with urllib.request.urlopen(f"http://127.0.0.1:{http_port}/signalk", timeout=5) as r:
                return r.status == 200
        except OSError:
            return False

    async def main():
        ship = ShipServer(scenario_from_dict(SCENARIO), ShipServerConfig(speedup=SPEED, centre_after=2.0, nmea_period=0.25),
                          nmea_to=("127.0.0.1", udp_port))
        srv = asyncio.create_task(ship.run())
        while ship.transport is None:
            await asyncio.sleep(0.005)
        ap = Autopilot(controller, ship.address,
                       AutopilotConfig(speedup=SPEED, watchdog_timeout=3.0, nmea_timeout=3.0),
                       heading=math.radians(30.0), log_path=tmp_path / "ap.csv",
                       signalk_input=("127.0.0.1", http_port))
        try:
            await asyncio.wait_for(ap.run(40.0), timeout=40.0 / SPEED + 60.0)     # hang guard
        finally:
            ship.stop()
            await srv
        return ap

    try:
        _until(up, 120.0, "signalk-server")
        ap = asyncio.run(main())
    finally:
        server.terminate()                       # the process this test started, by its handle
        try:
            server.wait(timeout=30)
        except subprocess.TimeoutExpired:
            server.kill()
        log.close()
    rows = _read_log(tmp_path / "ap.csv")
    steered = [r for r in rows if r["t"] > 5.0 and r["link_ok"]]
    by_signalk = sum(r["heading_source"] == "signalk" for r in steered)
    assert by_signalk >= 0.9 * len(steered), (by_signalk, len(steered), dict(ap.signalk_source.counts))
    end = [r for r in rows if r["t"] >= 30.0 and r["heading_source"] == "signalk"]
    assert len(end) >= 10 and max(abs(r["psi_deg"] - 30.0) for r in end) < 1.5
    lat, lon = ap.signalk_nav["navigation.position"]             # RMC, through the server's parser
    assert abs(lat - DEFAULT_ORIGIN[0]) < 0.05 and abs(lon - DEFAULT_ORIGIN[1]) < 0.05
    assert "steering.rudderAngle" in ap.signalk_nav and "navigation.rateOfTurn" in ap.signalk_nav
