"""Bridge page: HTTP + WebSocket protocol against a running ship server and autopilot.

No headless browser is installed here (no chromium, no playwright), so the page's own
JavaScript is not executed; this test drives the same HTTP and WebSocket protocol the page
uses, with a real ``websockets`` client.
"""

from __future__ import annotations

import asyncio
import json
import math

import pytest
from websockets.asyncio.client import connect
from websockets.exceptions import InvalidStatus

from steerlab.runtime.web import BridgeServer, handle_action
from test_runtime_e2e import _course_change, _session, controller  # noqa: F401  (fixture)


async def _http_get(host, port, path, headers=""):
    reader, writer = await asyncio.open_connection(host, port)
    writer.write(f"GET {path} HTTP/1.1\r\nHost: {host}:{port}\r\n{headers}\r\n".encode())
    await writer.drain()
    head = (await reader.readuntil(b"\r\n\r\n")).decode()
    length = int(next(ln.split(":")[1] for ln in head.split("\r\n") if ln.lower().startswith("content-length")))
    body = await reader.readexactly(length)
    writer.close()
    return int(head.split()[1]), head, body


def test_bridge_page_http_and_websocket(controller, tmp_path):  # noqa: F811
    out = {}

    async def use_page(ctx):
        ap = ctx["ap"]
        bridge = await BridgeServer(ap, "127.0.0.1", 0, period=0.05).start()
        host, port = bridge.address
        try:
            status, head, html = await _http_get(host, port, "/")
            assert status == 200 and "text/html" in head and b"compass" in html
            for asset in (b"/bridge.js", b"/bridge.css"):
                assert asset in html
                st, _, body = await _http_get(host, port, asset.decode())
                assert st == 200 and body
            assert b"http" not in html.replace(b"http://www.w3.org", b"")   # no internet assets
            assert (await _http_get(host, port, "/nope"))[0] == 404
            st, _, body = await _http_get(host, port, "/status.json")
            assert st == 200 and json.loads(body)["controller"] == "pid"
            with pytest.raises(InvalidStatus):                            # cross-site WebSocket refused
                await connect(f"ws://{host}:{port}/ws", origin="http://evil.example")
            async with connect(f"ws://{host}:{port}/ws", origin=f"http://{host}:{port}") as ws:
                msg = json.loads(await ws.recv())
                assert msg["type"] == "status" and msg["link_ok"] and msg["mode"] == "auto"
                assert {"heading", "set_course", "rudder", "rudder_cmd", "yaw_rate", "position",
                        "alarms"} <= set(msg)

                async def action(a):
                    await ws.send(json.dumps(a))
                    while True:
                        m = json.loads(await ws.recv())
                        if m["type"] == "reply":
                            return m

                before = ap.psi_set
                assert (await action({"action": "adjust", "deg": 10}))["ok"]
                assert (await action({"action": "adjust", "deg": -1}))["ok"]
                assert math.degrees(ap.psi_set - before) == pytest.approx(9.0)
                assert not (await action({"action": "adjust", "deg": 45}))["ok"]
                assert not (await action({"action": "selfdestruct"}))["ok"]
                await ws.send("not json")
                assert json.loads(await ws.recv())["type"] in ("reply", "status")
                assert (await action({"action": "standby"}))["ok"]
                await asyncio.sleep(0.05)
                while (m := json.loads(await ws.recv()))["type"] != "status" or m["mode"] != "standby":
                    pass
                assert ap.order() is None                                  # standby: no rudder orders
                assert (await action({"action": "engage"}))["ok"]
                ap.alarms.set("link", True, ap.clock(), "test alarm")
                ap.alarms.set("link", False, ap.clock())
                assert (await action({"action": "ack"}))["ok"] and not ap.alarms.alarms
                out["ok"] = True
        finally:
            await bridge.close()

    asyncio.run(_session(controller, tmp_path / "ap.csv", 60.0, [(2.0, use_page), (2.0, lambda c: c["ap"].stop())]))
    assert out.get("ok")


def test_handle_action_never_raises():
    class Fake:
        psi_set = 0.0

        def __getattr__(self, name):
            return lambda *a, **k: None

    for msg in ("", "[]", "null", '{"action": 3}', '{"action": "adjust"}', '{"action": "adjust", "deg": true}',
                '{"action": "ack", "alarm": 5}', b"\xff", '{"action": "adjust", "deg": 1e400}'):
        assert handle_action(Fake(), msg, 0.0)["ok"] is False
    assert handle_action(Fake(), '{"action": "adjust", "deg": -10}', 0.0)["ok"] is True
