"""Conformant HTTP/1.1 on the runtime's WebSocket ports (bridge page, Signal K stream and REST API).

The HTTP side of :func:`websockets.asyncio.server.serve` answers one GET and then closes the
connection. Here the connection's parser is replaced (:class:`HttpConnection`) so that:

* **persistent connections** (RFC 9112 section 9.3): a plain GET is answered by the server's
  ``responder`` (its ``process_request``) right in the parser and the connection stays open for
  the next request (``Connection: keep-alive``), unless the client asked ``Connection: close``
  or spoke HTTP/1.0 without ``keep-alive``; a WebSocket upgrade request, first or after any
  number of GETs on the same connection, goes to websockets' handshake as before;
* **pipelined requests** (section 9.3.2) are answered in the order they came, one response
  each, never a traceback; a client that pipelines without reading (its unread responses
  above :data:`MAX_UNREAD` bytes) is disconnected;
* **idle connections are closed**: a connection that has not completed a request for
  :data:`IDLE_TIMEOUT` seconds (an idle keep-alive client, a half-sent request) is closed, so
  idle sockets of a local process do not pile up (websockets' own 10-s ``open_timeout`` is
  off: it would cut a busy keep-alive connection);
* a request with a body (``PUT``/``POST`` with ``Content-Length``) has its body (at most
  :data:`MAX_BODY` bytes, else 413) read and discarded so the reply is not lost to a TCP reset;
* every method but ``GET`` is answered ``405 Method Not Allowed`` with ``Allow: GET``
  (RFC 9110 section 15.5.6): the endpoints are read-only over HTTP; changes go over the
  Signal K stream (PUT messages) or the bridge page's WebSocket.

Malformed requests get their 4xx/505 and the connection closes.

Use: ``serve(..., create_connection=http_connection(responder), open_timeout=None)``.
"""

from __future__ import annotations

import functools
import logging
import weakref
from http import HTTPStatus

from websockets.asyncio.server import ServerConnection
from websockets.datastructures import Headers
from websockets.exceptions import HeaderLineTooLong, RequestLineTooLong, TooManyHeaders
from websockets.http11 import Request, Response, parse_headers, parse_line
from websockets.protocol import CONNECTING, Protocol

MAX_BODY = 65536          #: largest request body read (and discarded) before answering [bytes]
IDLE_TIMEOUT = 10.0
"""Longest time [s] a connection may go without completing a request before it is closed
(until it becomes a WebSocket, whose pings then keep it)."""
MAX_UNREAD = 1 << 20
"""Most response bytes [bytes] a pipelining client may leave unread before it is disconnected."""
ALLOW = "GET"             #: the only method served
CLOSE_TIMEOUT = 2.0
"""Longest wait [s] for a client to close its side (a WebSocket's closing handshake, or the TCP
connection after an HTTP answer) when a connection or the server closes; then the connection
is dropped. websockets' default, 10 s, let one client that keeps its socket open after a 404
hold up the server's shutdown for 10 s."""


def plain(status: HTTPStatus, text: str, extra=()) -> Response:
    """A short ``text/plain`` response that closes the connection."""
    body = text.encode()
    headers = Headers([("Content-Type", "text/plain; charset=utf-8"), ("Content-Length", str(len(body))),
                       ("Connection", "close"), *extra])
    return Response(status.value, status.phrase, headers, body)


def method_not_allowed(method: str) -> Response:
    return plain(HTTPStatus.METHOD_NOT_ALLOWED, f"{method} not allowed here: read-only (Allow: {ALLOW})\n",
                 [("Allow", ALLOW)])


class _Refused(Exception):
    def __init__(self, response: Response):
        self.response = response


def _read_request(reader):
    """Generator: the request head (any method; a body up to MAX_BODY is read and dropped)."""
    line = yield from parse_line(reader.read_line, RequestLineTooLong)
    try:
        raw_method, raw_path, raw_protocol = bytes(line).split(b" ", 2)
    except ValueError:
        raise _Refused(plain(HTTPStatus.BAD_REQUEST, "invalid HTTP request line\n")) from None
    if raw_protocol not in (b"HTTP/1.1", b"HTTP/1.0"):
        raise _Refused(plain(HTTPStatus.HTTP_VERSION_NOT_SUPPORTED, "HTTP/1.1 or HTTP/1.0 only\n"))
    try:
        method, path = raw_method.decode("ascii"), raw_path.decode("ascii")
    except UnicodeDecodeError:
        raise _Refused(plain(HTTPStatus.BAD_REQUEST, "request line must be ASCII\n")) from None
    headers = yield from parse_headers(reader.read_line)
    if "Transfer-Encoding" in headers:
        # a chunked body cannot be skipped cheaply: answer and close
        raise _Refused(method_not_allowed(method) if method != "GET" else
                       plain(HTTPStatus.BAD_REQUEST, "a GET has no body\n"))
    lengths = set(headers.get_all("Content-Length")) or {"0"}
    if len(lengths) != 1 or not next(iter(lengths)).isdigit():
        raise _Refused(plain(HTTPStatus.BAD_REQUEST, "invalid Content-Length\n"))
    n = int(next(iter(lengths)))
    if n > MAX_BODY:
        raise _Refused(plain(HTTPStatus.CONTENT_TOO_LARGE if hasattr(HTTPStatus, "CONTENT_TOO_LARGE")
                             else HTTPStatus.REQUEST_ENTITY_TOO_LARGE, f"body over {MAX_BODY} bytes\n"))
    if n:
        yield from reader.read_exact(n)
    request = Request(path, headers)
    request.method = method          # set, not passed: older websockets' Request has no such field
    request.protocol = raw_protocol.decode("ascii")
    return request


def is_upgrade(request) -> bool:
    """True for a WebSocket opening request (``Upgrade: websocket``)."""
    return any("websocket" in v.lower() for v in request.headers.get_all("Upgrade"))


def keeps_alive(request) -> bool:
    """Whether the connection stays open after answering ``request`` (RFC 9112 section 9.3)."""
    tokens = {t.strip().lower() for v in request.headers.get_all("Connection") for t in v.split(",")}
    if getattr(request, "protocol", "HTTP/1.1") == "HTTP/1.0":
        return "keep-alive" in tokens
    return "close" not in tokens


def _with_connection(response: Response, keep: bool) -> Response:
    headers = Headers([(k, v) for k, v in response.headers.raw_items() if k.lower() not in ("connection", "keep-alive")])
    headers["Connection"] = "keep-alive" if keep else "close"
    if keep:
        headers["Keep-Alive"] = f"timeout={IDLE_TIMEOUT:g}"
    return Response(response.status_code, response.reason_phrase, headers, response.body)


def _close(p):
    """Send EOF after what is written and ignore anything more from the client."""
    p.send_eof()
    p.parser = p.discard()
    next(p.parser)


def _parse(p, conn):
    """Replaces ``ServerProtocol.parse``: requests answered in order until a WebSocket upgrade
    (handed to websockets) or a close."""
    while p.state is CONNECTING:
        try:
            request = yield from _read_request(p.reader)
        except _Refused as r:
            p.send_response(r.response)
            yield
        except RequestLineTooLong:
            p.send_response(plain(HTTPStatus.REQUEST_URI_TOO_LONG, "request line too long\n"))
            yield
        except (HeaderLineTooLong, TooManyHeaders):
            p.send_response(plain(HTTPStatus.REQUEST_HEADER_FIELDS_TOO_LARGE, "header fields too large\n"))
            yield
        except Exception:            # EOF or garbage: close without a word, as websockets does
            _close(p)
            yield
        conn.request_done()
        response = None if is_upgrade(request) else conn.answer(request)
        if response is None:          # a WebSocket opening (or a GET of the stream path): websockets' handshake
            conn.upgrading()
            p.events.append(request)
            break
        keep = request.method == "GET" and keeps_alive(request) and conn.transport_room()
        p.writes.append(_with_connection(response, keep).serialize())
        if not keep:
            _close(p)
            yield
    yield from Protocol.parse(p)


class HttpConnection(ServerConnection):
    """A :class:`~websockets.asyncio.server.ServerConnection` with the HTTP fixes above.

    ``responder(connection, request)`` answers a plain request (a websockets ``Response``), or
    returns None to hand it to the WebSocket handshake; ``idle_timeout`` [s]: see
    :data:`IDLE_TIMEOUT`.
    """

    _live: "weakref.WeakSet[HttpConnection]" = weakref.WeakSet()   # connections not (yet) WebSockets

    def __init__(self, protocol, *args, responder=None, idle_timeout: float | None = None, **kwargs):
        self.responder = responder
        HttpConnection._live.add(self)
        self.idle_timeout = IDLE_TIMEOUT if idle_timeout is None else idle_timeout
        self._idle = None
        protocol.parser = _parse(protocol, self)      # nothing received yet: safe to swap
        next(protocol.parser)
        super().__init__(protocol, *args, **kwargs)

    # ------------------------------------------------------------ the plain-HTTP side
    def answer(self, request) -> Response | None:
        """The response to a plain request, or None for websockets' handshake."""
        if request.method != "GET":
            return method_not_allowed(request.method)
        if self.responder is None:
            return None
        try:
            return self.responder(self, request)
        except Exception:              # a responder bug: 500 for this request, the server goes on
            logging.getLogger(__name__).debug("responder failed", exc_info=True)
            return plain(HTTPStatus.INTERNAL_SERVER_ERROR, "internal error\n")

    def transport_room(self) -> bool:
        """False once the client has left more than :data:`MAX_UNREAD` bytes unread."""
        transport = getattr(self, "transport", None)
        return transport is None or transport.get_write_buffer_size() <= MAX_UNREAD

    # ------------------------------------------------------------ idle timeout
    def connection_made(self, transport) -> None:
        super().connection_made(transport)
        self._arm()

    def _arm(self) -> None:
        if self._idle is not None:
            self._idle.cancel()
        if self.idle_timeout:
            self._idle = self.loop.call_later(self.idle_timeout, self._idle_close)

    def _idle_close(self) -> None:
        self._idle = None
        if self.protocol.state is CONNECTING and self.transport is not None:
            self.transport.abort()     # idle or stalled before a complete request: its slot is freed

    def request_done(self) -> None:
        if getattr(self, "loop", None) is not None:
            self._arm()

    def upgrading(self) -> None:
        HttpConnection._live.discard(self)
        if self._idle is not None:
            self._idle.cancel()
            self._idle = None

    def connection_lost(self, exc) -> None:
        if self._idle is not None:
            self._idle.cancel()
            self._idle = None
        super().connection_lost(exc)

    async def handshake(self, process_request=None, *args, **kwargs):
        def checked(connection, request):
            if request.method != "GET":
                return method_not_allowed(request.method)
            return None if process_request is None else process_request(connection, request)

        await super().handshake(checked, *args, **kwargs)


def close_plain_connections(server) -> int:
    """Abort the keep-alive HTTP connections of ``server`` (a websockets server) that are not
    WebSockets: websockets' own close waits for their handshake, which a kept-alive connection
    never starts. Call right after ``server.close()``; returns how many were aborted."""
    n = 0
    for conn in list(HttpConnection._live):
        if getattr(conn, "server", None) is server and conn.protocol.state is CONNECTING \
                and getattr(conn, "transport", None) is not None:
            conn.transport.abort()
            n += 1
    return n


def http_connection(responder, idle_timeout: float | None = None):
    """The ``create_connection`` factory of a server whose plain requests ``responder`` answers."""
    return functools.partial(HttpConnection, responder=responder, idle_timeout=idle_timeout)
