"""Bridge page: a live web page for the autopilot (HTTP + WebSocket on one port, no internet assets).

``GET /`` serves ``static/bridge.html`` (+ ``/bridge.js``, ``/bridge.css``, ``/favicon.svg``); ``GET /status.json``
the current status; the WebSocket at ``/ws`` pushes ``{"type": "status", ...}`` (SI units, see
:meth:`steerlab.runtime.autopilot.Autopilot.status`) every ``period`` seconds and accepts
actions as JSON::

    {"action": "engage"}  {"action": "standby"}  {"action": "adjust", "deg": +1 | -1 | +10 | -10}
    {"action": "ack"}     {"action": "ack", "alarm": "link"}
    {"action": "mode", "mode": "compass" | "route" | "plotter"}     (steerlab.runtime.steering_modes)
    {"action": "profile", "profile": "rough"}  {"action": "gains", "gains": {"Kp": 2.5}}
                                              (steerlab.runtime.controller_settings)

and answers each with ``{"type": "reply", "ok": true|false, "error": ...}``. Requests whose
``Host`` does not name this server (DNS rebinding) and WebSockets from another site's page are
refused with 403 (:class:`steerlab.runtime.access.AccessPolicy`; ``--allow-origin`` adds
origins); messages are at most 4 KiB and 16 levels deep; at most ``action_rate`` actions per
second per connection are applied, the excess is answered
``ok: false`` ("rate limited") and not applied; unknown or malformed actions are answered
``ok: false`` and never crash the page.
"""

from __future__ import annotations

import asyncio
import json
import math
import time
from http import HTTPStatus
from importlib import resources

from websockets.asyncio.server import serve
from websockets.datastructures import Headers
from websockets.http11 import Response

from steerlab.errors import InputError
from steerlab.runtime.access import AccessPolicy, parse_json
from steerlab.runtime.client_slots import ClientSlots
from steerlab.runtime.http_conn import CLOSE_TIMEOUT, close_plain_connections, http_connection, is_upgrade
from steerlab.runtime.rate_limit import RateLimiter

STATIC = {"/": ("bridge.html", "text/html; charset=utf-8"),
          "/bridge.js": ("bridge.js", "text/javascript; charset=utf-8"),
          "/bridge.css": ("bridge.css", "text/css; charset=utf-8"),
          "/favicon.svg": ("favicon.svg", "image/svg+xml")}
ADJUST_STEPS = (-10.0, -1.0, 1.0, 10.0)
MAX_MESSAGE = 4096


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


def same_origin(request, policy: AccessPolicy | None = None) -> bool:
    """False for a request a browser page of another site (or a DNS-rebinding page) made.

    ``policy`` defaults to a loopback server's (:class:`~steerlab.runtime.access.AccessPolicy`).
    """
    return (policy or AccessPolicy()).refusal(request, websocket=True) is None


def handle_action(ap, msg, t: float) -> dict:
    """Apply one page action to the autopilot; the reply (never raises)."""
    if isinstance(msg, (str, bytes)):
        m, why = parse_json(msg, MAX_MESSAGE)
        if why is not None:
            return {"type": "reply", "ok": False, "error": why}
    else:
        m = msg
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
        refusal = ap.course_refusal(t)          # a route or a chart plotter sets the course
        if refusal is not None:
            return {"type": "reply", "ok": False, "error": refusal}
        ap.adjust(float(d), t)
    elif action == "mode":
        why = ap.set_mode(m.get("mode"), t)
        if why is not None:
            return {"type": "reply", "ok": False, "error": why}
    elif action in ("profile", "gains"):
        from steerlab.errors import InputError

        try:
            if action == "profile":
                if not isinstance(m.get("profile"), str):
                    return {"type": "reply", "ok": False,
                            "error": f"profile must be a name, one of {', '.join(ap.settings.names())}"}
                ap.configure(t, profile=m["profile"])
            else:
                ap.configure(t, gains=m.get("gains"))
        except InputError as err:
            return {"type": "reply", "ok": False, "error": str(err)}
    elif action == "ack":
        name = m.get("alarm")
        if name is not None and not isinstance(name, str):
            return {"type": "reply", "ok": False, "error": "alarm must be a name"}
        ap.acknowledge(t, name)
    else:
        return {"type": "reply", "ok": False, "error": f"unknown action {action!r}"}
    return {"type": "reply", "ok": True, "action": action}


class BridgeServer:
    """Serves the bridge page of ``autopilot`` on ``(host, port)``.

    ``allow_origins``: browser origins allowed besides loopback pages; ``action_rate``: actions
    applied per second per connection (bursts of twice that; no shared limit, so a flooding page
    cannot lock the operator out); ``max_clients`` pages at most, a new page taking the slot of
    the one quiet longest when full (:class:`~steerlab.runtime.client_slots.ClientSlots`);
    ``operator``: the run's :class:`~steerlab.runtime.operator_session.OperatorSession` (default:
    the autopilot's ``operator``, else a new one) whose token gives a page a reserved slot.
    """

    def __init__(self, autopilot, host: str = "127.0.0.1", port: int = 8080, period: float = 0.2,
                 allow_origins=(), action_rate: float = 5.0, max_clients: int = 8, operator=None):
        self.ap = autopilot
        self.host, self.port = host, port
        self.period = period
        self.server = None
        self.max_clients = max_clients
        self.slots = ClientSlots(max_clients)
        self.access = AccessPolicy(host, allow_origins)
        self.action_rate = action_rate
        self.limiter = RateLimiter(action_rate, 2 * action_rate, max_sources=4 * max_clients)
        if operator is None:
            from steerlab.runtime.operator_session import OperatorSession

            operator = getattr(autopilot, "operator", None)
            if not isinstance(operator, OperatorSession):     # an autopilot without a session of its own
                operator = OperatorSession()
        self.operator = operator
        self.counts = {"refused_http": 0, "rate_limited": 0, "refused_full": 0, "operator": 0,
                       "operator_refused": 0}

    @property
    def clients(self) -> int:
        """Bridge pages connected now."""
        return len(self.slots)

    @property
    def evicted(self) -> int:
        """Quiet pages closed to make room for a new one (docs/reliability.md)."""
        return self.slots.evicted

    def _process_request(self, connection, request):
        path = request.path.split("?", 1)[0]
        why = self.access.refusal(request, websocket=path == "/ws")
        if why is not None:
            self.counts["refused_http"] += 1
            return _response(HTTPStatus.FORBIDDEN, why.encode() + b"\n", "text/plain")
        if path == "/ws":
            if not is_upgrade(request):
                return _response(HTTPStatus.UPGRADE_REQUIRED, b"a WebSocket: send Upgrade: websocket\n", "text/plain")
            op = self.operator.check(request)
            if op is None:
                self.counts["operator_refused"] += 1
                return _response(HTTPStatus.FORBIDDEN, b"wrong operator token\n", "text/plain")
            if not self.slots.make_room(op):    # full and every page spoke within the last second
                self.counts["refused_full"] += 1
                return _response(HTTPStatus.SERVICE_UNAVAILABLE,
                                 b"too many bridge pages; the operator's address (with #op=) has a reserved slot\n",
                                 "text/plain")
            self.counts["operator"] += int(op)
            self.slots.add(connection, op)
            return None
        if path == "/status.json":
            body = json.dumps(_json_safe(self.ap.status())).encode()
            return _response(HTTPStatus.OK, body, "application/json")
        if path in STATIC:
            name, ctype = STATIC[path]
            return _response(HTTPStatus.OK, _static(name), ctype)
        return _response(HTTPStatus.NOT_FOUND, b"not found\n", "text/plain")

    async def _handler(self, ws):
        async def push():
            while True:
                await ws.send(json.dumps(_json_safe({"type": "status", **self.ap.status()})))
                await asyncio.sleep(self.period)

        pusher = asyncio.create_task(push())
        try:
            async for msg in ws:
                self.slots.touch(ws)
                await ws.send(json.dumps(self.action(ws, msg)))
        except Exception:
            pass
        finally:
            pusher.cancel()
            self.slots.remove(ws)

    def action(self, source, msg) -> dict:
        """The reply to one message of connection ``source``: applied unless over the rate limit."""
        now = time.monotonic()
        if not self.limiter.allow(id(source), now):
            self.counts["rate_limited"] += 1
            return {"type": "reply", "ok": False,
                    "error": f"rate limited: at most {self.action_rate:g} actions per second; not applied"}
        return handle_action(self.ap, msg, self.ap.clock())

    @property
    def address(self):
        return self.server.sockets[0].getsockname()[:2] if self.server else None

    async def start(self) -> "BridgeServer":
        try:
            self.server = await serve(self._handler, self.host, self.port,
                                      process_request=self._process_request, max_size=4096,
                                      compression=None, server_header=None, open_timeout=None,
                                      create_connection=http_connection(self._process_request),
                                      close_timeout=CLOSE_TIMEOUT)
        except OSError as err:
            raise InputError("--web", f"cannot bind {self.host}:{self.port}: {err.strerror}") from None
        return self

    async def close(self) -> None:
        if self.server is not None:
            self.server.close()
            close_plain_connections(self.server)
            await self.server.wait_closed()
