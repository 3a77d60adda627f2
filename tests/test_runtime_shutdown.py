"""The runtime's servers shut down promptly with a client that keeps its socket open after an
HTTP answer (a 404, a refused origin): the connection is dropped after
:data:`~steerlab.runtime.http_conn.CLOSE_TIMEOUT` instead of websockets' default 10 s (real
sockets on loopback)."""

from __future__ import annotations

import asyncio
import socket

import pytest

from steerlab.runtime.http_conn import CLOSE_TIMEOUT
from steerlab.runtime.signalk_ws import SignalKStreamServer
from steerlab.runtime.web import BridgeServer

WEBSOCKETS_DEFAULT_CLOSE_TIMEOUT = 10.0


def _servers():
    return {"signalk": lambda: SignalKStreamServer(host="127.0.0.1", port=0),
            "bridge": lambda: BridgeServer(object(), "127.0.0.1", 0)}


@pytest.mark.parametrize("kind", sorted(_servers()))
def test_a_client_lingering_after_an_http_answer_does_not_hold_up_the_shutdown(kind):
    assert CLOSE_TIMEOUT < WEBSOCKETS_DEFAULT_CLOSE_TIMEOUT / 3

    async def go():
        srv = await _servers()[kind]().start()
        host, port = srv.address
        s = socket.create_connection((host, port), timeout=5)
        try:
            s.sendall(f"GET /no/such/path HTTP/1.1\r\nHost: {host}:{port}\r\n\r\n".encode())
            head = await asyncio.to_thread(s.recv, 64)
            assert head.startswith(b"HTTP/1.1 4"), head           # answered (404 or 403), socket kept open
            # the old wait was websockets' 10 s; this deadline is well above CLOSE_TIMEOUT, well below 10 s
            await asyncio.wait_for(srv.close(), timeout=2.0 * CLOSE_TIMEOUT + 1.0)
        finally:
            s.close()

    asyncio.run(go())
