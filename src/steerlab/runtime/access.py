"""Who may use the runtime's web endpoints (bridge page, Signal K): Host and Origin allowlists, bounded JSON.

DNS rebinding: a page of ``http://evil.example:8080`` whose name later resolves to 127.0.0.1 is,
for the browser, *same-origin* with itself, so an ``Origin == "http://" + Host`` check passes
(both name ``evil.example``). Two rules close this (the defence the WHATWG Fetch standard's
"private network access" notes and every local dev server use):

* **Host allowlist** (every HTTP request and WebSocket handshake): the ``Host`` header must name
  this server by a loopback literal (127.0.0.0/8, ``[::1]``), ``localhost``, the bound address
  (any IP literal when bound to the wildcard 0.0.0.0 / ::), or a host of an origin given with
  ``--allow-origin``. A rebinding page's requests carry its own domain name and are refused (403).
* **Origin allowlist** (WebSocket handshakes): a request without ``Origin`` is not from a
  browser page and is allowed; otherwise the origin's host must be a loopback literal or
  ``localhost``, the origin must be one given with ``--allow-origin`` (``http[s]://HOST[:PORT]``),
  or it must equal ``http[s]://`` + the (already allowed) ``Host`` (the page served by this server
  over a LAN address). ``Origin: null`` (sandboxed frames, ``file:``) is refused.

:func:`parse_json` parses a client message with bounded size and nesting depth, and says why
not in one short line instead of raising (``RecursionError`` ended the connection before).
"""

from __future__ import annotations

import ipaddress
import json
from urllib.parse import urlsplit

from steerlab.errors import InputError

MAX_JSON_DEPTH = 16
"""Deepest nesting of arrays/objects accepted in a client message (legitimate ones use <= 4)."""


def _literal(host: str):
    try:
        return ipaddress.ip_address(host.strip("[]"))
    except ValueError:
        return None


def is_loopback_name(host: str) -> bool:
    """True for ``localhost`` and loopback IP literals (127.0.0.0/8, ::1; brackets allowed)."""
    host = host.lower().rstrip(".")
    if host == "localhost":
        return True
    ip = _literal(host)
    return ip is not None and ip.is_loopback


def split_host(value: str) -> str:
    """The host name of a ``Host`` header value (``"[::1]:8080"`` -> ``"::1"``), lower-case."""
    v = value.strip().lower()
    if v.startswith("["):
        return v[1:v.find("]")] if "]" in v else v[1:]
    head, sep, port = v.rpartition(":")
    if sep and port.isdigit() and ":" not in head:
        v = head
    return v.rstrip(".")


def normalise_origin(text: str, field: str = "--allow-origin") -> str:
    """``scheme://host[:port]`` (lower-case, no path) of an allowed-origin option; InputError if not one."""
    s = str(text).strip()
    try:
        u = urlsplit(s)
        port = u.port
    except ValueError:
        u, port = None, None
    if u is None or u.scheme not in ("http", "https") or not u.hostname or u.path not in ("", "/") \
            or u.query or u.fragment or u.username or len(s) > 255:
        raise InputError(field, f"expected http://HOST[:PORT] or https://HOST[:PORT], got {s[:80]!r}")
    host = f"[{u.hostname}]" if ":" in u.hostname else u.hostname
    return f"{u.scheme}://{host}" + (f":{port}" if port is not None else "")


class AccessPolicy:
    """Host / Origin allowlist of one server bound to ``bind_host``.

    Parameters
    ----------
    bind_host : str
        The address the server listens on (``"127.0.0.1"``, ``"::1"``, ``"0.0.0.0"``, a name).
    allow_origins : sequence of str
        Extra browser origins (``http[s]://HOST[:PORT]``) allowed to open a WebSocket; their
        hosts are also allowed in ``Host``.
    """

    def __init__(self, bind_host: str = "127.0.0.1", allow_origins=()):
        self.bind_host = str(bind_host).lower().strip("[]")
        ip = _literal(self.bind_host)
        self.wildcard = ip is not None and ip.is_unspecified
        self.origins = frozenset(normalise_origin(o) for o in allow_origins)
        self.hosts = frozenset(split_host(urlsplit(o).netloc) for o in self.origins) | {self.bind_host}

    def host_ok(self, host: str | None) -> bool:
        """Whether a request's ``Host`` header names this server (None: not sent, not a browser)."""
        if host is None:
            return True
        name = split_host(host)
        if is_loopback_name(name) or name in self.hosts:
            return True
        return self.wildcard and _literal(name) is not None

    def origin_ok(self, origin: str | None, host: str | None) -> bool:
        """Whether a WebSocket handshake's ``Origin`` may connect (None: not a browser page)."""
        if origin is None:
            return True
        o = origin.strip().lower()
        try:
            u = urlsplit(o)
            u.port
        except ValueError:
            return False
        if u.scheme not in ("http", "https") or not u.hostname:
            return False                           # "null", file:, chrome-extension: ...
        if is_loopback_name(u.hostname):
            return True
        try:
            if normalise_origin(o) in self.origins:
                return True
        except InputError:
            return False
        return host is not None and self.host_ok(host) and u.netloc == host.strip().lower()

    def refusal(self, request, websocket: bool) -> str | None:
        """Why ``request`` (a websockets ``Request``) is refused, or None if it is allowed."""
        host = request.headers.get("Host")
        if not self.host_ok(host):
            return "Host not allowed (DNS rebinding?); use a loopback address or --allow-origin"
        if websocket and not self.origin_ok(request.headers.get("Origin"), host):
            return "cross-origin WebSocket refused; allow the page with --allow-origin"
        return None


def parse_json(msg, max_bytes: int, max_depth: int = MAX_JSON_DEPTH):
    """``(value, None)`` for a JSON text of at most ``max_bytes`` and ``max_depth`` levels, else ``(None, why)``.

    Bounded: the C parser's own recursion limit ends absurd nesting (``RecursionError`` is caught),
    and the depth of what it returns is measured iteratively only when the text has more
    brackets than ``max_depth`` (so ordinary messages cost one ``str.count``).
    """
    if isinstance(msg, (bytes, bytearray, memoryview)):
        if len(msg) > max_bytes:
            return None, f"message longer than {max_bytes} bytes"
        try:
            msg = bytes(msg).decode("utf-8")
        except UnicodeDecodeError:
            return None, "not UTF-8"
    if not isinstance(msg, str):
        return None, "not text"
    if len(msg) > max_bytes:
        return None, f"message longer than {max_bytes} bytes"
    try:
        value = json.loads(msg)
    except RecursionError:
        return None, f"nested deeper than {max_depth} levels"
    except (ValueError, TypeError):
        return None, "not JSON"
    if msg.count("[") + msg.count("{") > max_depth and _depth_exceeds(value, max_depth):
        return None, f"nested deeper than {max_depth} levels"
    return value, None


def _depth_exceeds(value, max_depth: int) -> bool:
    stack = [(value, 1)]
    while stack:
        v, d = stack.pop()
        if isinstance(v, dict):
            v = v.values()
        elif not isinstance(v, list):
            continue
        if d > max_depth:
            return True
        stack.extend((c, d + 1) for c in v if isinstance(c, (dict, list)))
    return False
