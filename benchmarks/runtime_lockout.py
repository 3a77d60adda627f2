"""Idle clients against the operator, and persistent HTTP connections (docs/reliability.md).

A hostile local process opens ``--idle`` TCP connections that send nothing and ``--idle``
WebSocket clients that never speak, on the bridge page's port and on the Signal K stream's
port; then the operator loads the page, opens its WebSocket and engages, and opens the Signal K
stream and PUTs. Prints what the attacker holds, what was evicted and how long the operator
took. Run twice: idle attackers and an operator without a token (the quiet-client eviction is
what saves it), then chatty attackers (every held slot speaks every 0.3 s; eviction cannot help)
and the operator with the run's token (its reserved slot, issue 35). Then ``--requests`` GETs of ``/status.json``: a new connection each, one kept-alive
connection, and all of them pipelined on one socket.

    python benchmarks/runtime_lockout.py [--idle 100] [--requests 1000]
"""

from __future__ import annotations

import argparse
import asyncio
import http.client
import json
import socket
import time

from websockets.asyncio.client import connect

from steerlab.runtime.signalk_ws import SignalKStreamServer
from steerlab.runtime.web import BridgeServer


class _Autopilot:
    mode = "standby"

    def status(self):
        return {"t": 1.0, "mode": self.mode, "heading": 0.5}

    def clock(self):
        return 0.0

    def engage(self, t):
        self.mode = "auto"


async def lockout(n_idle: int, chatty: bool = False) -> dict:
    from steerlab.runtime.operator_session import OperatorSession

    op = OperatorSession()
    sk = await SignalKStreamServer(on_put=lambda path, value: (200, None), operator=op).start()
    web = await BridgeServer(_Autopilot(), port=0, operator=op).start()
    tcp, wss, refused, chatter = [], [], 0, []

    async def chat(ws):
        try:
            while True:
                await ws.send(json.dumps({"action": "nothing"}))
                await asyncio.sleep(0.3)
        except Exception:
            pass

    try:
        for addr in (web.address, sk.address):
            for _ in range(n_idle):
                tcp.append((await asyncio.open_connection(*addr))[1])
        for (host, port), path in ((web.address, "/ws"), (sk.address, "/signalk/v1/stream")):
            for _ in range(n_idle):
                try:
                    wss.append(await connect(f"ws://{host}:{port}{path}", open_timeout=5))
                except Exception:
                    refused += 1
                    continue
                if chatty:
                    chatter.append(asyncio.create_task(chat(wss[-1])))
        await asyncio.sleep(1.1)
        q = f"?op={op.token}" if chatty else ""
        t0 = time.perf_counter()
        host, port = web.address
        conn = http.client.HTTPConnection(host, port, timeout=5)
        await asyncio.to_thread(conn.request, "GET", "/")
        page = (await asyncio.to_thread(conn.getresponse)).status
        t_page = time.perf_counter() - t0
        async with connect(f"ws://{host}:{port}/ws{q}", open_timeout=5) as ws:
            await ws.recv()
            await ws.send(json.dumps({"action": "engage"}))
            while (m := json.loads(await ws.recv()))["type"] != "reply":
                pass
        t_action = time.perf_counter() - t0
        host, port = sk.address
        t1 = time.perf_counter()
        async with connect(f"ws://{host}:{port}/signalk/v1/stream{q}", open_timeout=5) as ws:
            await ws.recv()
            await ws.send(json.dumps({"requestId": "op", "put": {"path": "steering.autopilot.state", "value": "auto"}}))
            while "requestId" not in (r := json.loads(await ws.recv())):
                pass
        t_put = time.perf_counter() - t1
        return {"attackers": "chatty (0.3 s), operator with token" if chatty else "idle, operator without token",
                "idle_tcp": len(tcp), "ws_tried": 2 * n_idle, "ws_refused_503": refused,
                "evicted": web.evicted + sk.slots.evicted, "page_status": page, "page_ms": 1e3 * t_page,
                "engage_ok": m["ok"], "page_and_engage_ms": 1e3 * t_action, "put_status": r["statusCode"],
                "stream_put_ms": 1e3 * t_put}
    finally:
        for t in chatter:
            t.cancel()
        for w in tcp:
            w.close()
        for ws in wss:
            ws.transport.abort()
        await sk.close()
        await web.close()


def requests(addr, n: int) -> dict:
    host, port = addr
    req = f"GET /status.json HTTP/1.1\r\nHost: {host}:{port}\r\n\r\n".encode()
    t0 = time.perf_counter()
    for _ in range(n):
        c = http.client.HTTPConnection(host, port, timeout=5)
        c.request("GET", "/status.json", headers={"Connection": "close"})
        c.getresponse().read()
        c.close()
    t_new = time.perf_counter() - t0
    c = http.client.HTTPConnection(host, port, timeout=5)
    t0 = time.perf_counter()
    for _ in range(n):
        c.request("GET", "/status.json")
        c.getresponse().read()
    t_keep = time.perf_counter() - t0
    c.close()
    with socket.create_connection(addr, timeout=10) as s:
        t0 = time.perf_counter()
        s.sendall(req * n)
        got, buf = 0, b""
        while got < n:
            buf += s.recv(1 << 16)
            got = buf.count(b"HTTP/1.1 200 ")
        t_pipe = time.perf_counter() - t0
    return {"n": n, "new_connection_ms": 1e3 * t_new / n, "keep_alive_ms": 1e3 * t_keep / n,
            "pipelined_ms": 1e3 * t_pipe / n, "pipelined_answered": got}


async def main(n_idle: int, n_req: int) -> None:
    print(json.dumps(await lockout(n_idle), indent=1))
    print(json.dumps(await lockout(n_idle, chatty=True), indent=1))
    web = await BridgeServer(_Autopilot(), port=0).start()
    try:
        print(json.dumps(await asyncio.to_thread(requests, web.address, n_req), indent=1))
    finally:
        await web.close()


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--idle", type=int, default=100)
    ap.add_argument("--requests", type=int, default=1000)
    a = ap.parse_args()
    asyncio.run(main(a.idle, a.requests))
