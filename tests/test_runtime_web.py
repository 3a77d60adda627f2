"""Bridge page: HTTP + WebSocket protocol against a running ship server and autopilot.

The first test drives the HTTP and WebSocket protocol the page uses with a real ``websockets``
client; the second runs the page's own ``bridge.js`` in Node.js (if installed) with a stub DOM
against the live page. The page in a real browser: ``test_runtime_browser.py``.
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
                while (m := json.loads(await ws.recv()))["type"] != "reply":    # status pushes between
                    pass
                assert not m["ok"]                                         # its error reply, consumed
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


def test_course_buttons_while_a_route_steers_are_refused_with_the_reason():
    adjusted = []

    class Following:
        def course_refusal(self, t):
            return "following a route (--route): the route is the only course source; target not applied"

        def adjust(self, d, t):
            adjusted.append(d)

    reply = handle_action(Following(), '{"action": "adjust", "deg": 10}', 0.0)
    assert reply["ok"] is False and "--route" in reply["error"] and adjusted == []


_NODE_HARNESS = r"""
// Runs the page's own bridge.js in Node with a stub DOM and Node's real WebSocket client.
const [port, srcPath] = process.argv.slice(2);
const src = require("fs").readFileSync(srcPath, "utf8");
function el(id) {
  return { id, attrs: {}, children: [], dataset: {}, className: "", textContent: "",
           setAttribute(k, v) { this.attrs[k] = String(v); }, appendChild(c) { this.children.push(c); return c; } };
}
const els = {};
const buttons = [-10, -1, 1, 10].map((d) => { const b = el("adj" + d); b.dataset.adjust = String(d); return b; });
global.document = { getElementById: (id) => els[id] || (els[id] = el(id)), createElementNS: (ns, t) => el(t),
                    createElement: (t) => el(t), querySelectorAll: () => buttons };
global.location = { protocol: "http:", host: "127.0.0.1:" + port, hash: process.argv[4] || "" };
const RealWS = WebSocket;
let statuses = 0;
global.WebSocket = function (url) { const s = new RealWS(url); s.addEventListener("message", () => statuses++); return s; };
eval(src);
const wait = (ms) => new Promise((r) => setTimeout(r, ms));
async function until(what, pred) {   // poll, bounded: a loaded machine is slow, never wrong
  for (let i = 0; i < 500; i++) { if (pred()) return; await wait(20); }
  console.error("timed out waiting for " + what); process.exit(3);
}
const E = (id) => document.getElementById(id);
const snap = () => ({ mode: E("mode").textContent, link: E("link").textContent, heading: E("heading").textContent,
  set_course: E("set-course").textContent, rudder: E("rudder-angle").textContent,
  needle: E("ship-needle").attrs.transform, track: E("track-line").attrs.points,
  reply: E("reply").textContent, counts: E("counts").textContent, ticks: E("ticks").children.length });
(async () => {
  await until("status", () => statuses > 5 && E("track-line").attrs.points && E("track-line").attrs.points.split(" ").length > 2);
  const first = snap();
  buttons[3].onclick();            // +10 deg
  await until("+10 reply", () => E("reply").textContent === "ok: adjust");
  E("standby").onclick();
  await until("standby", () => E("mode").textContent === "standby" && E("reply").textContent === "ok: standby");
  const standby = snap();
  E("engage").onclick();
  await until("engage", () => E("reply").textContent === "ok: engage" && E("mode").textContent === "auto");
  console.log(JSON.stringify({ first, standby, engaged: snap(), statuses }));
  process.exit(0);
})();
"""


def _node_with_websocket():
    import shutil
    import subprocess

    node = shutil.which("node")
    if node is None:
        return None
    try:
        out = subprocess.run([node, "--experimental-websocket", "-e", "console.log(typeof WebSocket)"],
                             capture_output=True, text=True, timeout=30).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return None
    return node if out == "function" else None


def test_bridge_js_runs_against_the_live_page(controller, tmp_path):  # noqa: F811
    """The page's JavaScript (not a browser: Node + stub DOM) renders status and sends actions."""
    node = _node_with_websocket()
    if node is None:
        pytest.skip("Node.js with a WebSocket client is not available")
    from importlib import resources

    harness = tmp_path / "harness.js"
    harness.write_text(_NODE_HARNESS)
    js = resources.files("steerlab.runtime").joinpath("static", "bridge.js")
    out = {}

    async def run_page(ctx):
        ap = ctx["ap"]
        bridge = await BridgeServer(ap, "127.0.0.1", 0, period=0.05).start()
        before = ap.psi_set
        try:
            proc = await asyncio.create_subprocess_exec(
                node, "--experimental-websocket", str(harness), str(bridge.address[1]), str(js),
                f"#op={bridge.operator.token}",             # the operator's address (issue 35)
                stdout=asyncio.subprocess.PIPE, stderr=asyncio.subprocess.PIPE)
            stdout, stderr = await asyncio.wait_for(proc.communicate(), 60)
            assert proc.returncode == 0, stderr.decode()
            out.update(json.loads(stdout), d_set=math.degrees(ap.psi_set - before), mode=ap.mode,
                       operator=bridge.counts["operator"], public=len(bridge.slots.last))
        finally:
            await bridge.close()
            ap.stop()

    asyncio.run(_session(controller, tmp_path / "ap.csv", 600.0, [(2.0, run_page)]))
    first, standby, engaged = out["first"], out["standby"], out["engaged"]
    assert out["statuses"] > 5 and first["ticks"] == 36 + 12
    assert first["mode"] == "auto" and first["link"] == "link OK"
    assert first["heading"].endswith("\u00b0") and first["set_course"] == "0.0\u00b0"
    assert first["needle"].startswith("rotate(") and len(first["track"].split()) > 2
    assert first["counts"].startswith("states accepted")
    assert out["d_set"] == pytest.approx(10.0)                      # the +10 button reached the autopilot
    assert standby["mode"] == "standby" and standby["reply"] == "ok: standby"
    assert standby["set_course"] == "10.0\u00b0"
    assert engaged["reply"] == "ok: engage" and out["mode"] == "auto"
    assert out["operator"] == 1 and out["public"] == 0      # the page presented its token: a reserved slot
