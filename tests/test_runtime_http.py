"""HTTP/1.1 conformance of the runtime's HTTP endpoints (Signal K discovery + REST API, bridge page).

Real sockets on loopback. A keep-alive client (``http.client.HTTPConnection`` reused for every
request, as Node's default agent and ``@signalk/client`` do) must get every one of 100 sequential
requests answered: each response says ``Connection: close`` and carries ``Content-Length``, so
the client knows to reconnect. Methods other than GET get 405 with ``Allow: GET`` (with or
without a body), never silence.
"""

from __future__ import annotations

import asyncio
import http.client
import json
import socket

import pytest

from steerlab.runtime.signalk_ws import SignalKStreamServer
from steerlab.runtime.web import BridgeServer


class _StubAutopilot:
    def status(self):
        return {"t": 1.0, "mode": "standby", "heading": 0.5}

    def clock(self):
        return 0.0


def _servers(check):
    """Run ``check(sk_addr, web_addr)`` in a thread while both servers serve on loopback."""
    async def go():
        sk = await SignalKStreamServer().start()
        web = await BridgeServer(_StubAutopilot(), port=0).start()
        sk.publish({"navigation.headingTrue": 1.0}, wall=1_700_000_000.0)
        try:
            await asyncio.to_thread(check, sk.address, web.address)
        finally:
            await sk.close()
            await web.close()

    asyncio.run(go())


ENDPOINTS = (("sk", "/signalk"), ("sk", "/signalk/v1/api/"), ("sk", "/signalk/v1/api/vessels/self"),
             ("sk", "/signalk/v1/api/vessels/self/navigation/headingTrue"),
             ("web", "/status.json"), ("web", "/"), ("web", "/bridge.js"))


def test_one_keep_alive_client_gets_100_answers_from_each_endpoint():
    def check(sk, web):
        for which, path in ENDPOINTS:
            host, port = sk if which == "sk" else web
            conn = http.client.HTTPConnection(host, port, timeout=5)     # one client object, keep-alive
            try:
                for i in range(100):
                    conn.request("GET", path, headers={"Connection": "keep-alive"})
                    resp = conn.getresponse()
                    body = resp.read()
                    assert resp.status == 200, (path, i)
                    assert resp.getheader("Connection") == "keep-alive", path
                    assert int(resp.getheader("Content-Length")) == len(body) > 0, path
                    if path.endswith(".json") or "/signalk" in path:
                        json.loads(body)
            finally:
                conn.close()

    _servers(check)


def _raw(addr, data: bytes) -> bytes:
    """Send ``data`` on a fresh socket; everything the server answers until it closes."""
    with socket.create_connection(addr, timeout=5) as s:
        s.sendall(data)
        out = b""
        while chunk := s.recv(65536):
            out += chunk
    return out


def test_other_methods_get_405_with_allow_and_the_connection_closes():
    def check(sk, web):
        for addr, path in ((sk, "/signalk"), (sk, "/signalk/v1/api/vessels/self/navigation/headingTrue"),
                           (sk, "/signalk/v1/stream"), (web, "/status.json"), (web, "/")):
            host, port = addr
            for method, body in (("PUT", b'{"value": 1.0}'), ("POST", b'{"action": "engage"}'),
                                 ("DELETE", b""), ("HEAD", b"")):
                req = (f"{method} {path} HTTP/1.1\r\nHost: {host}:{port}\r\nContent-Type: application/json\r\n"
                       f"Content-Length: {len(body)}\r\n\r\n").encode() + body
                out = _raw(addr, req)           # returns: the server answered and closed
                head = out.split(b"\r\n\r\n", 1)[0].decode()
                assert head.startswith("HTTP/1.1 405 "), (method, path, head)
                lines = {ln.split(":", 1)[0].lower(): ln.split(":", 1)[1].strip() for ln in head.split("\r\n")[1:]}
                assert lines["allow"] == "GET" and lines["connection"] == "close"
                assert int(lines["content-length"]) == len(out.split(b"\r\n\r\n", 1)[1])
            # http.client's PUT too (a real client, not hand-made bytes)
            conn = http.client.HTTPConnection(host, port, timeout=5)
            conn.request("PUT", path, body=b"{}", headers={"Content-Type": "application/json"})
            resp = conn.getresponse()
            assert resp.status == 405 and resp.getheader("Allow") == "GET"
            resp.read()
            conn.close()

    _servers(check)


def test_oversized_bodies_and_bad_request_lines_are_answered_not_dropped():
    def check(sk, web):
        host, port = sk
        big = (f"POST /signalk HTTP/1.1\r\nHost: {host}:{port}\r\nContent-Length: 10000000\r\n\r\n").encode()
        assert _raw(sk, big).startswith(b"HTTP/1.1 413 ")
        assert _raw(sk, b"NONSENSE\r\n\r\n").startswith(b"HTTP/1.1 400 ")
        assert _raw(sk, b"GET / HTTP/2.0\r\n\r\n").startswith(b"HTTP/1.1 505 ")
        bad_len = f"PUT /signalk HTTP/1.1\r\nHost: {host}:{port}\r\nContent-Length: -3\r\n\r\n".encode()
        assert _raw(sk, bad_len).startswith(b"HTTP/1.1 400 ")
        # and the server still serves a GET afterwards
        conn = http.client.HTTPConnection(host, port, timeout=5)
        conn.request("GET", "/signalk")
        assert conn.getresponse().status == 200
        conn.close()

    _servers(check)


@pytest.mark.parametrize("path", ["/signalk/v1/stream", "/ws"])
def test_websocket_upgrade_still_works_through_the_http_layer(path):
    from websockets.asyncio.client import connect

    async def go():
        sk = await SignalKStreamServer().start()
        web = await BridgeServer(_StubAutopilot(), port=0).start()
        try:
            host, port = sk.address if path.startswith("/signalk") else web.address
            async with connect(f"ws://{host}:{port}{path}") as ws:
                first = json.loads(await asyncio.wait_for(ws.recv(), 5))
                assert ("self" in first) if path.startswith("/signalk") else first["type"] == "status"
        finally:
            await sk.close()
            await web.close()

    asyncio.run(go())


@pytest.mark.skipif(__import__("shutil").which("node") is None, reason="node not found (Node.js >= 19 for its keep-alive default agent)")
def test_node_keep_alive_agent_gets_100_answers_from_each_endpoint():
    """Node's default HTTP agent (keep-alive since Node 19; the one @signalk/client uses) and its
    fetch: 100 sequential GETs to each endpoint, none failing with "socket hang up"."""
    import subprocess

    script = r"""
const http = require('http');
const agent = new http.Agent({ keepAlive: true, maxSockets: 1 });
const get = (url) => new Promise((resolve, reject) => {
  http.get(url, { agent }, (res) => { let n = 0; res.on('data', (c) => { n += c.length });
    res.on('end', () => resolve([res.statusCode, n])) }).on('error', reject) });
(async () => {
  const out = {};
  for (const url of JSON.parse(process.argv[1])) {
    let ok = 0;
    for (let i = 0; i < 100; i++) { const [s, n] = await get(url); if (s === 200 && n > 0) ok++ }
    for (let i = 0; i < 20; i++) { const r = await fetch(url); await r.arrayBuffer(); if (r.status === 200) ok++ }
    out[url] = ok;
  }
  process.stdout.write(JSON.stringify(out));
})().catch((e) => { process.stdout.write(JSON.stringify({ error: String(e) })); });
"""

    def check(sk, web):
        urls = [f"http://{sk[0]}:{sk[1]}{p}" for w, p in ENDPOINTS if w == "sk"] + \
               [f"http://{web[0]}:{web[1]}{p}" for w, p in ENDPOINTS if w == "web"]
        res = subprocess.run(["node", "-e", script, json.dumps(urls)], capture_output=True, text=True, timeout=120)
        got = json.loads(res.stdout or "{}")
        assert got == {u: 120 for u in urls}, (got, res.stderr[-1000:])

    _servers(check)
