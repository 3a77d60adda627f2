"""Conformant HTTP/1.1 on the runtime's WebSocket ports (bridge page, Signal K stream and REST API).

The HTTP side of :func:`websockets.asyncio.server.serve` answers one GET and then closes the
connection. RFC 9112 section 9.6 lets a server do that if it says so: every response carries
``Connection: close`` (:func:`steerlab.runtime.web._response`), so a keep-alive client
(Python's ``http.client``, Node's default agent, ``@signalk/client``) opens a new connection for
its next request instead of failing with "socket hang up". Two more gaps are closed here:

* a request with a body (``PUT``/``POST`` with ``Content-Length``) used to get no answer at
  all (websockets drops it); its body (at most :data:`MAX_BODY` bytes, else 413) is now read
  and discarded so the reply is not lost to a TCP reset;
* every method but ``GET`` is answered ``405 Method Not Allowed`` with ``Allow: GET``
  (RFC 9110 section 15.5.6): the endpoints are read-only over HTTP; changes go over the
  Signal K stream (PUT messages) or the bridge page's WebSocket.

Use: ``serve(..., create_connection=HttpConnection)``.
"""

from __future__ import annotations

from http import HTTPStatus

from websockets.asyncio.server import ServerConnection
from websockets.datastructures import Headers
from websockets.exceptions import HeaderLineTooLong, RequestLineTooLong, TooManyHeaders
from websockets.http11 import Request, Response, parse_headers, parse_line
from websockets.protocol import CONNECTING, Protocol

MAX_BODY = 65536          #: largest request body read (and discarded) before answering [bytes]
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


def _parse(p):
    """Replaces ``ServerProtocol.parse``: the same, with :func:`_read_request` for the head."""
    if p.state is CONNECTING:
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
            p.send_eof()
            p.parser = p.discard()
            next(p.parser)
            yield
        p.events.append(request)
    yield from Protocol.parse(p)


class HttpConnection(ServerConnection):
    """A :class:`~websockets.asyncio.server.ServerConnection` with the HTTP fixes above."""

    def __init__(self, protocol, *args, **kwargs):
        protocol.parser = _parse(protocol)      # nothing received yet: safe to swap
        next(protocol.parser)
        super().__init__(protocol, *args, **kwargs)

    async def handshake(self, process_request=None, *args, **kwargs):
        def checked(connection, request):
            if request.method != "GET":
                return method_not_allowed(request.method)
            return None if process_request is None else process_request(connection, request)

        await super().handshake(checked, *args, **kwargs)
