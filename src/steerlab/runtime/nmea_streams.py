"""NMEA 0183 over byte streams beside UDP: a serial port, TCP as client and as server.

Every input here turns its stream into lines (:class:`~steerlab.runtime.line_splitter.LineSplitter`)
and hands them, grouped as a datagram would carry them, to the same handler as the UDP port
(``on_datagram(data, source)``: :meth:`steerlab.runtime.autopilot.Autopilot.on_nmea_datagram`,
its checks, counts and per-source rate limit), so a compass on a serial line and a
multiplexer on TCP are read exactly like a UDP talker.

* :class:`NmeaSerialInput` -- ``--nmea-serial PATH[:BAUD]`` (4 800 baud by default); a device
  that vanishes is one line and the ``lost`` counter, then reopened every second.
* :class:`NmeaTcpClient` -- ``--nmea-tcp HOST:PORT``: connects to a talker (a multiplexer, a
  chart plotter's NMEA server, conventionally on port :data:`NMEA_TCP_PORT`), reconnecting
  every ``reconnect_period`` seconds when the connection drops or is refused.
* :class:`NmeaTcpServer` -- ``--nmea-tcp-listen HOST:PORT``: talkers connect to it (at most
  ``max_clients`` at once; more are closed at once and counted ``refused``).
"""

from __future__ import annotations

import asyncio
from collections import Counter

from steerlab.errors import InputError
from steerlab.runtime.line_splitter import LineSplitter, nmea_chunks
from steerlab.runtime.reconnecting_input import ReconnectingInput
from steerlab.runtime.reconnecting_input import stderr_line as _stderr

NMEA_TCP_PORT = 10110
"""The conventional TCP port of NMEA 0183 over IP (IANA "nmea-0183", used by plotters and
multiplexers such as OpenCPN, Signal K server and kplex)."""




class _Lines:
    """Bytes of one stream -> ``on_datagram(chunk, source)`` calls."""

    def __init__(self, on_datagram, source):
        self.on_datagram = on_datagram
        self.source = source
        self.splitter = LineSplitter()

    def feed(self, data: bytes) -> None:
        for chunk in nmea_chunks(self.splitter.feed(data)):
            self.on_datagram(chunk, self.source)


class NmeaSerialInput:
    """NMEA 0183 from a serial port (:class:`~steerlab.runtime.serial_port.SerialLink`)."""

    def __init__(self, path: str, baud: int, on_datagram, log=_stderr, reopen_period: float = 1.0):
        from steerlab.runtime.serial_port import SerialLink

        self.lines = _Lines(on_datagram, ("serial", path))
        self.link = SerialLink(path, baud, self.lines.feed, name="--nmea-serial", log=log,
                               reopen_period=reopen_period)

    @property
    def counts(self) -> Counter:
        return self.link.counts + self.lines.splitter.counts

    async def start(self) -> "NmeaSerialInput":
        await self.link.start(required=True)
        return self

    async def close(self) -> None:
        await self.link.close()


class NmeaTcpClient(ReconnectingInput):
    """NMEA 0183 from a TCP talker, reconnecting (``connected``, ``counts``)."""

    def __init__(self, host: str, port: int, on_datagram, reconnect_period: float = 1.0, log=_stderr):
        super().__init__(host, port, reconnect_period, log)
        self.on_datagram = on_datagram

    async def _run(self) -> None:
        said_down = False
        while True:
            try:
                reader, writer = await asyncio.open_connection(self.host, self.port)
            except OSError as err:
                self.counts["connect_failed"] += 1
                if not said_down:
                    self.log(f"--nmea-tcp: cannot connect to {self.host}:{self.port} ({err.strerror or err}); "
                             f"retrying every {self.reconnect_period:g} s")
                    said_down = True
                await asyncio.sleep(self.reconnect_period)
                continue
            self.connected, said_down, self.ever_connected = True, False, True
            self.counts["connected"] += 1
            lines = _Lines(self.on_datagram, (self.host, self.port))
            try:
                while True:
                    data = await reader.read(4096)
                    if not data:
                        break
                    self.counts["bytes"] += len(data)
                    lines.feed(data)
            except OSError:
                pass
            finally:
                self.connected = False
                self.counts.update(lines.splitter.counts)
                writer.close()
            self.counts["disconnected"] += 1
            self.log(f"--nmea-tcp: {self.host}:{self.port} closed the connection; reconnecting")
            await asyncio.sleep(self.reconnect_period)


class NmeaTcpServer:
    """A TCP port talkers connect to (``address`` once started; ``counts``)."""

    def __init__(self, host: str, port: int, on_datagram, max_clients: int = 8):
        self.host, self.port = host, int(port)
        self.on_datagram = on_datagram
        self.max_clients = int(max_clients)
        self.counts: Counter = Counter()
        self.clients: dict = {}           # task -> its writer
        self.server = None

    @property
    def address(self):
        return self.server.sockets[0].getsockname()[:2] if self.server else None

    async def start(self) -> "NmeaTcpServer":
        try:
            self.server = await asyncio.start_server(self._client, self.host, self.port)
        except OSError as err:
            raise InputError("--nmea-tcp-listen", f"cannot listen on {self.host}:{self.port}: "
                                                  f"{err.strerror or err}") from None
        return self

    async def _client(self, reader, writer) -> None:
        if len(self.clients) >= self.max_clients:
            self.counts["refused"] += 1
            writer.close()
            return
        task = asyncio.current_task()
        self.clients[task] = writer
        self.counts["clients"] += 1
        peer = writer.get_extra_info("peername")
        lines = _Lines(self.on_datagram, tuple(peer[:2]) if peer else ("tcp", 0))
        try:
            while True:
                data = await reader.read(4096)
                if not data:
                    break
                self.counts["bytes"] += len(data)
                lines.feed(data)
        except (OSError, asyncio.CancelledError):
            pass
        finally:
            self.counts.update(lines.splitter.counts)
            self.clients.pop(task, None)
            writer.close()

    async def close(self) -> None:
        if self.server is not None:
            self.server.close()
            for writer in list(self.clients.values()):
                writer.close()                   # its reader ends: the client task returns
            await asyncio.gather(*self.clients, return_exceptions=True)
            await self.server.wait_closed()
