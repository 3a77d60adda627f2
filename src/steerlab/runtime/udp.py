"""asyncio UDP endpoints and ``HOST:PORT`` parsing for the runtime (loopback by default)."""

from __future__ import annotations

import asyncio
import ipaddress

from steerlab.errors import InputError

LOOPBACK = "127.0.0.1"


def parse_hostport(text: str, field: str, default_host: str = LOOPBACK) -> tuple[str, int]:
    """``"HOST:PORT"``, ``":PORT"`` or ``"PORT"`` -> ``(host, port)``; port 0 = any free port."""
    s = str(text).strip()
    host, sep, port = s.rpartition(":")
    if not sep:
        host, port = "", s
    host = host.strip("[]") or default_host
    try:
        p = int(port)
    except ValueError:
        raise InputError(field, f"expected HOST:PORT with PORT in [0, 65535], got {text!r}") from None
    if not 0 <= p <= 65535:
        raise InputError(field, f"port must be in [0, 65535], got {p}")
    if not host or any(c.isspace() for c in host):
        raise InputError(field, f"bad host in {text!r}")
    return host, p


def check_resolvable(host: str, port: int, field: str) -> None:
    """:class:`InputError` naming ``field`` if ``host`` does not resolve to an address (a typo in
    a peer's name or address: ``999.1.1.1``), before any socket is made; a peer that resolves
    but does not answer is the link's alarm, not this."""
    import socket

    try:
        socket.getaddrinfo(host, port, type=socket.SOCK_DGRAM)
    except socket.gaierror as err:
        raise InputError(field, f"cannot resolve host {host!r}: {err.strerror}") from None
    except UnicodeError:
        raise InputError(field, f"bad host {host!r}") from None


def is_loopback(host: str) -> bool:
    """True for 127.0.0.0/8, ::1 and ``localhost``."""
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def local_bind_for(remote_host: str) -> tuple[str, int]:
    """The local address to send to ``remote_host`` from: loopback for a loopback peer (of the
    same family: ``127.0.0.1`` for 127.0.0.0/8 and ``localhost``, ``::1`` for ``::1``), else the
    wildcard of the peer's family (``0.0.0.0`` or ``::``); port 0 (any free one)."""
    try:
        ip = ipaddress.ip_address(remote_host)
    except ValueError:
        return (LOOPBACK if remote_host == "localhost" else "0.0.0.0"), 0
    if ip.version == 6:
        return ("::1" if ip.is_loopback else "::"), 0
    return (LOOPBACK if ip.is_loopback else "0.0.0.0"), 0


class _Protocol(asyncio.DatagramProtocol):
    def __init__(self, on_datagram):
        self.on_datagram = on_datagram
        self.errors = 0

    def datagram_received(self, data, addr):
        self.on_datagram(data, addr)

    def error_received(self, exc):   # e.g. ICMP port unreachable when a peer is gone
        self.errors += 1


async def open_udp(on_datagram, local_addr=(LOOPBACK, 0), remote_addr=None):
    """A bound UDP transport calling ``on_datagram(data, addr)`` for each datagram received."""
    loop = asyncio.get_running_loop()
    transport, _ = await loop.create_datagram_endpoint(
        lambda: _Protocol(on_datagram), local_addr=local_addr, remote_addr=remote_addr)
    return transport


def send(transport, data: bytes, addr) -> None:
    """Fire and forget (a closed transport or unreachable peer is not an error here)."""
    if transport is not None and not transport.is_closing():
        try:
            transport.sendto(data, addr)
        except OSError:
            pass
