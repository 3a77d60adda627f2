"""Which local address the autopilot sends from: loopback for a loopback ship (IPv4 or IPv6).

Before, any ``--connect`` host other than ``127.0.0.1``/``localhost`` (``127.0.0.2``, ``[::1]``)
made the autopilot bind ``0.0.0.0`` (its state port reachable from the network), and an IPv6
ship could not be reached at all (an IPv4 socket cannot send to ``::1``).
"""

from __future__ import annotations

import asyncio
import csv
import re
import socket
import time

import pytest

from steerlab.runtime.autopilot import Autopilot, AutopilotConfig
from steerlab.runtime.ship_server import ShipServer, ShipServerConfig
from steerlab.runtime.udp import local_bind_for
from steerlab.sim.scenario import scenario_from_dict
from test_runtime_e2e import SCENARIO, SPEEDUP, controller  # noqa: F401  (fixture)


@pytest.mark.parametrize("host, bind", [
    ("127.0.0.1", "127.0.0.1"), ("127.0.0.2", "127.0.0.1"), ("localhost", "127.0.0.1"), ("::1", "::1"),
    ("192.168.1.20", "0.0.0.0"), ("fe80::1", "::"), ("ship.lan", "0.0.0.0"),
])
def test_local_bind_for(host, bind):
    assert local_bind_for(host) == (bind, 0)


def _ipv6_loopback() -> bool:
    try:
        with socket.socket(socket.AF_INET6, socket.SOCK_DGRAM) as s:
            s.bind(("::1", 0))
        return True
    except OSError:
        return False


@pytest.mark.parametrize("ship_host, connect_host", [("::1", "::1"), ("127.0.0.2", "127.0.0.2")])
def test_autopilot_steers_a_ship_on_another_loopback_address(controller, ship_host, connect_host,  # noqa: F811
                                                             tmp_path):
    if ":" in ship_host and not _ipv6_loopback():
        pytest.skip("no IPv6 loopback here")

    async def go():
        server = ShipServer(scenario_from_dict(SCENARIO), ShipServerConfig(speedup=SPEEDUP), bind=(ship_host, 0))
        srv = asyncio.create_task(server.run())
        while server.transport is None:
            await asyncio.sleep(0.001)
            if srv.done():
                srv.result()
        ap = Autopilot(controller, (connect_host, server.address[1]),
                       AutopilotConfig(speedup=SPEEDUP, watchdog_timeout=3.0), heading=0.0,
                       log_path=tmp_path / "ap.csv")
        try:
            await ap.run(3.0)
        finally:
            server.stop()
            await srv
        return server, ap

    server, ap = asyncio.run(go())
    local = ap.transport.get_extra_info("sockname")[0]
    assert local in ("::1", "127.0.0.1")                                   # never the wildcard
    assert ap.filter.counts["accepted"] > 20 and server.stats.commands > 10
    with open(tmp_path / "ap.csv", newline="") as f:                    # the log's wall clock: to the ms
        walls = [r["wall"] for r in csv.DictReader(f)]
    assert all(re.fullmatch(r"\d{10}\.\d{3}", w) for w in walls) and abs(float(walls[-1]) - time.time()) < 60
