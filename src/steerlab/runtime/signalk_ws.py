"""Signal K over WebSocket: the streaming API (``/signalk/v1/stream``) of the ship server and autopilot.

The part of the Signal K specification (1.7, "Streaming API", "Subscription Protocol",
"Request/Response") that an instrument display or a chart plotter needs:

``GET /signalk``
    Discovery: ``{"endpoints": {"v1": {"version": "1.7.0", "signalk-ws": "ws://HOST:PORT/signalk/v1/stream",
    "signalk-http": "http://HOST:PORT/signalk/v1/api/"}}, "server": {"id": "steerlab", "version": ...}}``.
``GET /signalk/v1/api/...``
    The read-only REST API over the latest values (:mod:`steerlab.runtime.signalk_rest`).
``WS /signalk/v1/stream[?subscribe=self|all|none][&sendCachedValues=true|false]``
    On connection a *hello* (``{"name", "version", "timestamp", "self": SELF_ID, "roles"}``, the
    self vessel's URN, :data:`steerlab.runtime.signalk.SELF_ID`; deltas use the alias ``vessels.self``),
    the cached values (unless ``sendCachedValues=false``), then every update as a delta message
    (:func:`steerlab.runtime.signalk.delta`, SI units; the same paths as over UDP), filtered by
    the client's subscriptions. ``subscribe=self`` (default) and ``all`` stream every path,
    ``none`` nothing until the client subscribes; another value is answered HTTP 501 as the
    specification asks.

Messages from the client (JSON, at most 64 KiB and 16 levels deep, at most ``msg_rate`` per
second per connection):

* ``{"context": "vessels.self" | SELF_ID | "vessels.*" | "*", "subscribe": [{"path": "navigation.*"}, ...]}``
  (a context pattern that matches the self vessel; another vessel's is refused) adds path
  patterns (``*`` matches any characters, matched in linear time by :class:`PathPattern`; at most
  :data:`MAX_PATTERNS` per client of at most :data:`MAX_PATH` characters); ``period``/``policy``
  are accepted and ignored (every update is sent as it is made: the "instant" policy).
* ``{"context": ..., "unsubscribe": [{"path": "*"}]}`` removes patterns (``*``: all).
* ``{"requestId": ..., "put": {"path": ..., "value": ...}}`` calls ``on_put(path, value)`` and is
  answered ``{"requestId", "state": "COMPLETED", "statusCode": 200 | 400 | 405 | 429, "message"}``;
  an endpoint without ``on_put`` (the ship server's: read-only) answers 405; more than
  ``put_rate`` PUTs per second on one connection are answered 429 and not applied.

Anything else is counted as ``rejected`` and otherwise ignored; nothing a client sends closes
the stream or raises. A request whose ``Host`` does not name this server (DNS rebinding) or a
WebSocket from a browser page of another origin is refused (403,
:class:`steerlab.runtime.access.AccessPolicy`), more
than ``max_clients`` connections take the slot of the client quiet longest, or are refused (503)
when every client spoke within the last second (:class:`~steerlab.runtime.client_slots.ClientSlots`), and a client that does not read (its write
buffer above ``max_buffer`` bytes) misses updates rather than growing the sender's memory.
"""

from __future__ import annotations

import json
import math
import time
from http import HTTPStatus

from websockets.asyncio.server import broadcast, serve

from steerlab.errors import InputError
from steerlab.runtime.access import AccessPolicy, parse_json
from steerlab.runtime.client_slots import ClientSlots
from steerlab.runtime.http_conn import CLOSE_TIMEOUT, close_plain_connections, http_connection, is_upgrade
from steerlab.runtime.path_glob import PathPattern
from steerlab.runtime.rate_limit import RateLimiter
from steerlab.runtime.signalk import MAX_DELTA_BYTES, SELF_ID, delta, is_self_context, iso_time
from steerlab.runtime.signalk_rest import API_PATH, api_get
from steerlab.runtime.web import _response

SIGNALK_VERSION = "1.7.0"
STREAM_PATH = "/signalk/v1/stream"
SUBSCRIBE_MODES = ("self", "all", "none")
CONTEXTS = ("vessels.self", "*")


MAX_PATH = 256
"""Longest subscription path pattern [characters]."""
MAX_PATTERNS = 64
"""Most path patterns one client may hold (a subscribe beyond is refused as a whole)."""


def path_pattern(pattern: str) -> PathPattern:
    """A Signal K path pattern (``*`` = any characters), matched in linear time (:class:`PathPattern`)."""
    return PathPattern(pattern)


class Subscriptions:
    """The path patterns one client subscribed to (at most :data:`MAX_PATTERNS`)."""

    def __init__(self, mode: str = "self"):
        self.patterns: dict[str, PathPattern] = {}
        self._wants: dict[str, bool] = {}      # path -> matched (the published paths are few)
        if mode in ("self", "all"):
            self.patterns["*"] = path_pattern("*")

    def wants(self, path: str) -> bool:
        hit = self._wants.get(path)
        if hit is None:
            hit = any(p.match(path) for p in self.patterns.values())
            if len(self._wants) >= 4 * MAX_PATTERNS:
                self._wants.clear()
            self._wants[path] = hit
        return hit

    def filter(self, values: dict) -> dict:
        return {p: v for p, v in values.items() if self.wants(p)}

    def apply(self, msg: dict) -> bool:
        """Apply a subscribe / unsubscribe message; False (and nothing changed) if it is not a valid one."""
        if not is_self_context(msg.get("context", "vessels.self")):
            return False
        for key, add in (("subscribe", True), ("unsubscribe", False)):
            items = msg.get(key)
            if items is None:
                continue
            if not isinstance(items, list) or len(items) > MAX_PATTERNS:
                return False
            paths = [item.get("path") if isinstance(item, dict) else None for item in items]
            if not all(isinstance(p, str) and 0 < len(p) <= MAX_PATH for p in paths):
                return False
            if add and len(self.patterns.keys() | set(paths)) > MAX_PATTERNS:
                return False
            self._wants.clear()
            for path in paths:
                if add:
                    self.patterns[path] = path_pattern(path)
                elif path == "*":
                    self.patterns.clear()
                else:
                    self.patterns.pop(path, None)
            return True
        return False


class SignalKStreamServer:
    """Serves the Signal K stream on ``(host, port)``; :meth:`publish` sends an update.

    Parameters
    ----------
    on_put : callable ``(path, value) -> (status_code, message)`` or None
        Applies a PUT request (None: read-only, every PUT is answered 405).
    field : str
        CLI option named in errors (binding failures).
    msg_rate : float
        Messages accepted per second per connection (bursts of twice that; the excess is dropped).
    put_rate : float
        PUT requests applied per second per connection (bursts of twice that); the excess is
        answered 429 and not applied. No limit is shared between connections, so a flooding
        client cannot lock the operator out (``max_clients`` bounds the total).
    allow_origins : sequence of str
        Browser origins allowed besides loopback pages (:class:`~steerlab.runtime.access.AccessPolicy`).
    """

    def __init__(self, host: str = "127.0.0.1", port: int = 0, on_put=None, field: str = "--signalk-ws",
                 name: str = "steerlab", max_clients: int = 8, max_buffer: int = 256 * 1024,
                 msg_rate: float = 20.0, put_rate: float = 5.0, allow_origins=(), operator=None):
        self.host, self.port = host, port
        self.on_put = on_put
        self.field = field
        self.name = name
        self.max_clients = max_clients
        self.max_buffer = max_buffer
        self.limiter = RateLimiter(msg_rate, 2 * msg_rate, max_sources=4 * max_clients)
        self.put_rate = put_rate
        self.put_limiter = RateLimiter(put_rate, 2 * put_rate, max_sources=4 * max_clients)
        self.access = AccessPolicy(host, allow_origins)
        self.cache: dict = {}
        self.cache_time: dict = {}       # path -> wall time of its last value [s]
        self.clients: dict = {}          # connection -> Subscriptions
        self.slots = ClientSlots(max_clients)
        self.counts = {"clients": 0, "sent": 0, "skipped_slow": 0, "subscriptions": 0, "put_ok": 0,
                       "put_refused": 0, "rejected": 0, "rate_limited": 0, "put_rate_limited": 0, "refused_http": 0,
                       "refused_full": 0, "operator": 0, "operator_refused": 0}
        if operator is None:
            from steerlab.runtime.operator_session import OperatorSession

            operator = OperatorSession()
        self.operator = operator
        self.server = None

    # ------------------------------------------------------------ HTTP side
    def _process_request(self, connection, request):
        path, _, query = request.path.partition("?")
        why = self.access.refusal(request, websocket=path == STREAM_PATH)
        if why is not None:
            self.counts["refused_http"] += 1
            return _response(HTTPStatus.FORBIDDEN, why.encode() + b"\n", "text/plain")
        if path in ("/signalk", "/signalk/"):
            host = request.headers.get("Host") or "%s:%d" % tuple(self.address)
            body = {"endpoints": {"v1": {"version": SIGNALK_VERSION, "signalk-ws": f"ws://{host}{STREAM_PATH}",
                                         "signalk-http": f"http://{host}{API_PATH}/"}},
                    "server": {"id": self.name, "version": _steerlab_version()}}
            return _response(HTTPStatus.OK, json.dumps(body).encode(), "application/json")
        if path == API_PATH or path.startswith(API_PATH + "/"):
            status, body = api_get(path, self.cache, self.cache_time, SIGNALK_VERSION)
            if body is None:
                return _response(status, b"no such Signal K path\n", "text/plain")
            return _response(status, json.dumps(body).encode(), "application/json")
        if path != STREAM_PATH:
            return _response(HTTPStatus.NOT_FOUND, b"not found\n", "text/plain")
        opts = _query(query)
        if opts.get("subscribe", "self") not in SUBSCRIBE_MODES or \
                opts.get("sendCachedValues", "true") not in ("true", "false"):
            return _response(HTTPStatus.NOT_IMPLEMENTED, b"subscribe must be self, all or none\n", "text/plain")
        if not is_upgrade(request):
            return _response(HTTPStatus.UPGRADE_REQUIRED, b"the Signal K stream is a WebSocket: send Upgrade: websocket\n",
                             "text/plain")
        op = self.operator.check(request)
        if op is None:
            self.counts["operator_refused"] += 1
            return _response(HTTPStatus.FORBIDDEN, b"wrong operator token\n", "text/plain")
        if not self.slots.make_room(op):        # full, and every client spoke within the last second
            self.counts["refused_full"] += 1
            return _response(HTTPStatus.SERVICE_UNAVAILABLE,
                             b"too many Signal K clients; the operator's token (?op= or Bearer) has a reserved slot\n",
                             "text/plain")
        self.counts["operator"] += int(op)
        self.slots.add(connection, op)
        return None

    # ------------------------------------------------------------ a connection
    async def _handler(self, ws):
        opts = _query(ws.request.path.partition("?")[2])
        subs = Subscriptions(opts.get("subscribe", "self"))
        self.counts["clients"] += 1
        try:
            await ws.send(json.dumps({"name": self.name, "version": SIGNALK_VERSION, "timestamp": iso_time(time.time()),
                                      "self": SELF_ID, "roles": ["master", "main"]}))
            self.clients[ws] = subs
            if opts.get("sendCachedValues", "true") == "true":
                self._send(ws, subs, self.cache)
            async for msg in ws:
                self.slots.touch(ws)
                reply = self.handle_message(ws, subs, msg)
                if reply is not None:
                    await ws.send(json.dumps(reply))
        except Exception:        # a broken connection ends this client only
            pass
        finally:
            self.clients.pop(ws, None)
            self.slots.remove(ws)

    def handle_message(self, source, subs: Subscriptions, msg):
        """Apply one client message; the reply to send (or None). Never raises."""
        if not self.limiter.allow(id(source), time.monotonic()):
            self.counts["rate_limited"] += 1
            return None
        m, _ = parse_json(msg, MAX_DELTA_BYTES)
        if not isinstance(m, dict):
            self.counts["rejected"] += 1
            return None
        if "put" in m:
            return self._put(m, source)
        if ("subscribe" in m or "unsubscribe" in m) and subs.apply(m):
            self.counts["subscriptions"] += 1
            return None
        self.counts["rejected"] += 1
        return None

    def _put(self, m: dict, source=None) -> dict:
        rid = m.get("requestId")
        rid = rid if isinstance(rid, str) and len(rid) <= 128 else None
        put = m.get("put")
        if not isinstance(put, dict) or not isinstance(put.get("path"), str) or "value" not in put:
            code, text = 400, "expected put: {path, value}"
        elif self.on_put is None:
            code, text = 405, "this endpoint is read-only"
        elif not self.put_limiter.allow(id(source), time.monotonic()):
            self.counts["put_rate_limited"] += 1
            code, text = 429, f"rate limited: at most {self.put_rate:g} PUTs per second; not applied"
        else:
            try:
                code, text = self.on_put(put["path"], put["value"])
            except Exception as err:     # a handler bug must not end the stream
                code, text = 502, f"{type(err).__name__}"
        self.counts["put_ok" if code == 200 else "put_refused"] += 1
        reply = {"requestId": rid, "state": "COMPLETED", "statusCode": code}
        if text:
            reply["message"] = text
        return reply

    # ------------------------------------------------------------ updates
    def _send(self, ws, subs: Subscriptions, values: dict, wall: float | None = None) -> None:
        vals = subs.filter(values)
        if not vals:
            return
        transport = getattr(ws, "transport", None)
        if transport is not None and transport.get_write_buffer_size() > self.max_buffer:
            self.counts["skipped_slow"] += 1
            return
        broadcast([ws], json.dumps(delta(vals, wall)))
        self.counts["sent"] += 1

    def publish(self, values: dict, wall: float | None = None) -> None:
        """Send ``{path: value}`` (None values left out) to every subscribed client."""
        values = {p: v for p, v in values.items()
                  if v is not None and not (isinstance(v, float) and not math.isfinite(v))}
        self.cache.update(values)
        now = time.time() if wall is None else wall
        self.cache_time.update((p, now) for p in values)
        for ws, subs in list(self.clients.items()):
            self._send(ws, subs, values, wall)

    # ------------------------------------------------------------ lifecycle
    @property
    def address(self):
        return self.server.sockets[0].getsockname()[:2] if self.server else None

    async def start(self) -> "SignalKStreamServer":
        try:
            self.server = await serve(self._handler, self.host, self.port, process_request=self._process_request,
                                      max_size=MAX_DELTA_BYTES, compression=None, server_header=None,
                                      open_timeout=None, create_connection=http_connection(self._process_request),
                                      close_timeout=CLOSE_TIMEOUT)
        except OSError as err:
            raise InputError(self.field, f"cannot bind {self.host}:{self.port}: {err.strerror}") from None
        return self

    async def close(self) -> None:
        if self.server is not None:
            self.server.close()
            close_plain_connections(self.server)
            await self.server.wait_closed()


def _query(q: str) -> dict:
    from urllib.parse import parse_qsl

    return dict(parse_qsl(q)[:8])


def _steerlab_version() -> str:
    try:
        from steerlab import __version__
    except ImportError:
        return "unknown"
    return __version__
