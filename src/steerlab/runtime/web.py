"""Bridge page: a live web page for the autopilot (HTTP + WebSocket on one port, no internet assets).

``GET /`` serves ``static/bridge.html`` (+ ``/bridge.js``, ``/bridge.css``, ``/favicon.svg``); ``GET /status.json``
the current status; the WebSocket at ``/ws`` pushes ``{"type": "status", ...}`` (SI units, see
:meth:`steerlab.runtime.autopilot.Autopilot.status`) every ``period`` seconds and accepts
actions as JSON::

    {"action": "engage"}  {"action": "standby"}  {"action": "adjust", "deg": +1 | -1 | +10 | -10}
    {"action": "ack"}     {"action": "ack", "alarm": "link"}

and answers each with ``{"type": "reply", "ok": true|false, "error": ...}``. A WebSocket whose
``Origin`` is not this page's own (cross-site request) is refused with 403; messages are at
most 4 KiB; unknown or malformed actions are answered ``ok: false`` and never crash the page.
"""

from __future__ import annotations

import asyncio
import json
import math
from http import HTTPStatus
from importlib import resources

from websockets.asyncio.server import serve
from websockets.datastructures import Headers
from websockets.http11 import Response

from steerlab.errors import InputError
from steerlab.runtime.http_conn import HttpConnection

STATIC = {"/": ("bridge.html", "text/html; charset=utf-8"),
          "/bridge.js": ("bridge.js", "text/javascript; charset=utf-8"),
          "/bridge.css": ("bridge.css", "text/css; charset=utf-8"),
          "/favicon.svg": ("favicon.svg", "image/svg+xml")}
ADJUST_STEPS = (-10.0, -1.0, 1.0, 10.0)


def _static(name: str) -> bytes:
    return resources.files("steerlab.runtime").joinpath("static", name).read_bytes()


def _json_safe(o):
    if isinstance(o, float) and not math.isfinite(o):
        return None
    if isinstance(o, dict):
        return {k: _json_safe(v) for k, v in o.items()}
    if isinstance(o, (list, tuple)):
        return [_json_safe(v) for v in o]
    return o


def _response(status: HTTPStatus, body: bytes, ctype: str) -> Response:
    headers = Headers([("Content-Type", ctype), ("Content-Length", str(len(body))),
                       ("Connection", "close"), ("Cache-Control", "no-store"), ("X-Content-Type-Options", "nosniff"),
                       ("Content-Security-Policy", "default-src 'self'; connect-src 'self'")])
    return Response(status.value, status.phrase, headers, body)


def same_origin(request) -> bool:
    """False for a browser's cross-site WebSocket (an ``Origin`` that is not this host's)."""
    origin = request.headers.get("Origin")
    host = request.headers.get("Host", "")
    return origin is None or origin in (f"http://{host}", f"https://{host}")


def handle_action(ap, msg, t: float) -> dict:
    """Apply one page action to the autopilot; the reply (never raises)."""
    try:
        m = json.loads(msg) if isinstance(msg, (str, bytes)) else msg
    except (ValueError, TypeError):
        return {"type": "reply", "ok": False, "error": "not JSON"}
    if not isinstance(m, dict):
        return {"type": "reply", "ok": False, "error": "expected an object"}
    action = m.get("action")
    if action == "engage":
        ap.engage(t)
    elif action == "standby":
        ap.standby(t)
    elif action == "adjust":
        d = m.get("deg")
        if not isinstance(d, (int, float)) or isinstance(d, bool) or float(d) not in ADJUST_STEPS:
            return {"type": "reply", "ok": False, "error": f"deg must be one of {ADJUST_STEPS}"}
        ap.adjust(float(d), t)
    elif action == "ack":
        name = m.get("alarm")
        if name is not None and not isinstance(name, str):
            return {"type": "reply", "ok": False, "error": "alarm must be a name"}
        ap.acknowledge(t, name)
    else:
        return {"type": "reply", "ok": False, "error": f"unknown action {action!r}"}
    return {"type": "reply", "ok": True, "action": action}


class BridgeServer:
    """Serves the bridge page of ``autopilot`` on ``(host, port)``."""

    def __init__(self, autopilot, host: str = "127.0.0.1", port: int = 8080, period: float = 0.2):
        self.ap = autopilot
        self.host, self.port = host, port
        self.period = period
        self.server = None
        self.clients = 0

    def _process_request(self, connection, request):
        path = request.path.split("?", 1)[0]
        if path == "/ws":
            if not same_origin(request):
                return _response(HTTPStatus.FORBIDDEN, b"cross-origin WebSocket refused\n", "text/plain")
            return None
        if path == "/status.json":
            body = json.dumps(_json_safe(self.ap.status())).encode()
            return _response(HTTPStatus.OK, body, "application/json")
        if path in STATIC:
            name, ctype = STATIC[path]
            return _response(HTTPStatus.OK, _static(name), ctype)
        return _response(HTTPStatus.NOT_FOUND, b"not found\n", "text/plain")

    async def _handler(self, ws):
        self.clients += 1

        async def push():
            while True:
                await ws.send(json.dumps(_json_safe({"type": "status", **self.ap.status()})))
                await asyncio.sleep(self.period)

        pusher = asyncio.create_task(push())
        try:
            async for msg in ws:
                await ws.send(json.dumps(handle_action(self.ap, msg, self.ap.clock())))
        except Exception:
            pass
        finally:
            pusher.cancel()
            self.clients -= 1

    @property
    def address(self):
        return self.server.sockets[0].getsockname()[:2] if self.server else None

    async def start(self) -> "BridgeServer":
        try:
            self.server = await serve(self._handler, self.host, self.port,
                                      process_request=self._process_request, max_size=4096,
                                      compression=None, server_header=None, create_connection=HttpConnection)
        except OSError as err:
            raise InputError("--web", f"cannot bind {self.host}:{self.port}: {err.strerror}") from None
        return self

    async def close(self) -> None:
        if self.server is not None:
            self.server.close()
            await self.server.wait_closed()
