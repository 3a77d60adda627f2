"""Off-course and link-loss alarms as Signal K notifications, end to end (issue 33): the ship
server, a lossy proxy on the ship link, steerlab's autopilot and a real signalk-server with the
steerlab plug-in (signed link), all on loopback. A yaw kick of 40 deg puts the ship off course:
``notifications.steering.autopilot.heading`` is raised, then cleared once the autopilot has
brought her back; cutting the ship link raises ``notifications.steering.autopilot.link``,
restoring it clears it. Skipped where signalk-server is not installed (``.ci/setup-signalk``).
"""

from __future__ import annotations

import asyncio
import math
import socket
import subprocess
import threading

from steerlab.runtime.autopilot import Autopilot, AutopilotConfig
from steerlab.runtime.lossy_proxy import LossyProxy
from steerlab.runtime.ship_server import ShipServer, ShipServerConfig
from steerlab.ships.state import IPSI
from steerlab.sim.scenario import scenario_from_dict
from test_runtime_e2e import SCENARIO, controller  # noqa: F401  (fixture)
from test_signalk_plugin import (API, _config_dir, _free_port, _notification, _on_loop, _request, _start_server,
                                 _until, needs_server)


SPEEDUP = 5.0
"""Half the e2e tests' speed-up: a stall of the loaded test machine counts less in ship time."""


class _Ship:
    """Ship server, a lossy proxy on its link and the autopilot in a background event loop."""

    def __init__(self, controller, command_port, status_port, key):  # noqa: F811
        self.loop = asyncio.new_event_loop()
        self.server = ShipServer(scenario_from_dict(SCENARIO), ShipServerConfig(speedup=SPEEDUP, centre_after=2.0),
                                 key=key)
        self.controller, self.ports, self.key = controller, (command_port, status_port), key
        self.ap = self.proxy = self.error = None
        self.thread = threading.Thread(target=self._run, daemon=True)

    def _run(self):
        async def main():
            srv = asyncio.create_task(self.server.run())
            while self.server.transport is None:
                await asyncio.sleep(0.001)
            self.proxy = await LossyProxy(self.server.address, seed=1).start()
            # the watchdog at 3 s of ship time (0.3 s wall) rides out a loaded machine's stalls
            self.ap = Autopilot(self.controller, self.proxy.address,
                                AutopilotConfig(speedup=SPEEDUP, watchdog_timeout=3.0), heading=0.0,
                                engaged=False, signalk_listen=("127.0.0.1", self.ports[0]),
                                signalk_to=("127.0.0.1", self.ports[1]), key=self.key)
            try:
                await self.ap.run(0.0)
            finally:
                self.proxy.close()
                self.server.stop()
                await srv

        try:
            self.loop.run_until_complete(main())
        except Exception as err:           # reported by the test
            self.error = err

    def stop(self):
        if self.ap is not None:
            self.loop.call_soon_threadsafe(self.ap.stop)
        self.thread.join(timeout=30)


def _state(port, name):
    return (_notification(port, name) or {}).get("state")


@needs_server
def test_off_course_and_link_loss_are_raised_and_cleared_as_notifications(controller, tmp_path):  # noqa: F811
    key = b"a shared key for the notification test"
    (tmp_path / "key").write_bytes(key + b"\n")
    command_port, status_port, http_port = _free_port(socket.SOCK_DGRAM), _free_port(socket.SOCK_DGRAM), _free_port()
    server, log = _start_server(tmp_path, _config_dir(tmp_path, command_port, status_port,
                                                      keyFile=str(tmp_path / "key")), http_port)
    sl = _Ship(controller, command_port, status_port, key)
    sl.thread.start()
    dev = f"{API}/steerlab"
    try:
        def listed():
            if server.poll() is not None:
                raise AssertionError("signalk-server exited: " + (tmp_path / "signalk-server.log").read_text()[-2000:])
            try:
                return _request(http_port, "GET", API)
            except OSError:
                return None
        _until(listed, 120.0, "signalk-server and the plugin")
        _until(lambda: _request(http_port, "GET", dev)[1].get("state") == "standby", 30.0, "steerlab on-line")
        assert _request(http_port, "POST", f"{dev}/engage")[0] == 200
        _until(lambda: sl.ap.mode == "auto" and sl.ap.off_course_armed, 30.0, "engaged, on course, alarm armed")
        # on course and reported so (a stall of a loaded machine may have swung her off a moment)
        _until(lambda: not sl.ap.alarms.active("off_course") and _state(http_port, "heading") in (None, "normal"),
               30.0, "on course, no off-course notification")

        # a 40-deg yaw kick: off course (limit 10 deg) -> the notification; back on course -> cleared
        _on_loop(sl, lambda: sl.server.x.__setitem__(IPSI, sl.server.x[IPSI] + math.radians(40.0)))
        _until(lambda: sl.ap.alarms.active("off_course"), 10.0, "steerlab's off-course alarm")
        _until(lambda: _state(http_port, "heading") == "alarm", 10.0, "the off-course notification")
        assert "off the set course" in _notification(http_port, "heading")["message"]
        _until(lambda: not sl.ap.alarms.active("off_course"), 60.0, "back on course")
        _until(lambda: _state(http_port, "heading") == "normal", 10.0, "the off-course notification cleared")

        # the ship link cut: the link alarm (safe state) -> the notification; restored -> cleared
        sl.proxy.cut = True
        _until(lambda: sl.ap.alarms.active("link") and sl.ap.mode == "safe", 10.0, "steerlab's link alarm")
        _until(lambda: _state(http_port, "link") == "alarm", 10.0, "the link-loss notification")
        assert "no valid ship state" in _notification(http_port, "link")["message"]
        sl.proxy.cut = False
        _until(lambda: not sl.ap.alarms.active("link"), 10.0, "the link back")
        _until(lambda: _state(http_port, "link") == "normal", 10.0, "the link-loss notification cleared")
        assert sl.error is None
    finally:
        sl.stop()
        server.terminate()                       # the process this test started, by its handle
        try:
            server.wait(timeout=20)
        except subprocess.TimeoutExpired:
            server.kill()
        log.close()
