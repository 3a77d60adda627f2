"""A serial port (pyserial) read by the asyncio loop, that survives the device vanishing.

NMEA 0183 talkers (a fluxgate compass, a multiplexer) and the line-based actuator
(:mod:`steerlab.runtime.actuator_serial`) are serial devices: ``PATH[:BAUD]``, 4 800 baud by
default (NMEA 0183; 38 400 for "high speed" talkers). :class:`SerialLink` opens the port with
pyserial (raw mode, 8N1, no flow control), hands every byte read to ``on_bytes`` from the
event loop (``add_reader`` on the port's descriptor: no thread), and writes lines.

A device that vanishes (a USB adapter unplugged, the other end of a pseudo-terminal closed)
is one line on ``log`` and the ``lost`` counter; the port is then reopened every
``reopen_period`` seconds (wall) until it is back (``reopened``). Nothing raises out of the
loop's callbacks; ``connected`` tells the state.
"""

from __future__ import annotations

import asyncio
from collections import Counter

from steerlab.errors import InputError
from steerlab.runtime.reconnecting_input import stderr_line as _stderr

DEFAULT_BAUD = 4800
BAUD_RATES = (1200, 2400, 4800, 9600, 19200, 38400, 57600, 115200, 230400)


def parse_serial_spec(text: str, field: str, default_baud: int = DEFAULT_BAUD) -> tuple[str, int]:
    """``"PATH[:BAUD]"`` -> ``(path, baud)``; BAUD one of :data:`BAUD_RATES`."""
    s = str(text).strip()
    path, sep, baud = s.rpartition(":")
    if not sep or not baud.isdigit():
        path, baud = s, str(default_baud)
    if not path:
        raise InputError(field, f"expected PATH[:BAUD], got {text!r}")
    b = int(baud)
    if b not in BAUD_RATES:
        raise InputError(field, f"baud rate must be one of {', '.join(map(str, BAUD_RATES))}, got {b}")
    return path, b




class SerialLink:
    """One serial port, read from the running event loop.

    Parameters
    ----------
    path : str
        Device (``/dev/ttyUSB0``, a pseudo-terminal's ``/dev/pts/N``).
    baud : int
    on_bytes : callable(bytes)
        Called with every chunk read.
    name : str
        For the log lines (``--nmea-serial``).
    reopen_period : float
        Wall seconds between attempts to reopen a lost port.
    log : callable(str)
        Where the one-line messages go (stderr by default).
    """

    def __init__(self, path: str, baud: int, on_bytes, name: str = "serial", reopen_period: float = 1.0,
                 log=_stderr):
        self.path = path
        self.baud = int(baud)
        self.on_bytes = on_bytes
        self.name = name
        self.reopen_period = float(reopen_period)
        self.log = log
        self.port = None
        self.counts: Counter = Counter()
        self._loop = None
        self._reopen = None
        self._closed = False

    @property
    def connected(self) -> bool:
        return self.port is not None

    def _open(self):
        import serial

        port = serial.Serial(self.path, self.baud, timeout=0, write_timeout=0, exclusive=True)
        self._loop.add_reader(port.fileno(), self._readable)
        self.port = port

    async def start(self, required: bool = True) -> "SerialLink":
        """Open the port; with ``required`` a port that cannot be opened is an
        :class:`~steerlab.errors.InputError` naming the field, else it is retried."""
        import serial

        self._loop = asyncio.get_running_loop()
        try:
            self._open()
            self.counts["opened"] += 1
        except (serial.SerialException, OSError, ValueError) as err:
            if required:
                raise InputError(self.name, f"cannot open {self.path!r}: {err}") from None
            self._lost(f"cannot open: {err}")
        return self

    def _readable(self) -> None:
        import serial

        port = self.port
        if port is None:
            return
        try:
            data = port.read(max(1, port.in_waiting))
        except (serial.SerialException, OSError, TypeError) as err:
            self._lost(str(err))
            return
        if data:
            self.counts["bytes"] += len(data)
            self.on_bytes(data)

    def write(self, data: bytes) -> bool:
        """Write ``data`` (non-blocking); False when the port is not open or the write failed."""
        import serial

        if self.port is None:
            self.counts["write_dropped"] += 1
            return False
        try:
            self.port.write(data)
            return True
        except serial.SerialTimeoutException:
            self.counts["write_dropped"] += 1           # output buffer full: the device reads nothing
            return False
        except (serial.SerialException, OSError) as err:
            self._lost(str(err))
            return False

    def _lost(self, why: str) -> None:
        if self.port is not None:
            try:
                self._loop.remove_reader(self.port.fileno())
            except Exception:
                pass
            try:
                self.port.close()
            except Exception:
                pass
            self.port = None
            self.counts["lost"] += 1
            self.log(f"{self.name}: {self.path} lost ({why.strip() or 'no data'}); reopening every "
                     f"{self.reopen_period:g} s")
        if not self._closed and (self._reopen is None or self._reopen.done()):
            self._reopen = self._loop.create_task(self._reopen_loop())

    async def _reopen_loop(self) -> None:
        import serial

        while not self._closed and self.port is None:
            await asyncio.sleep(self.reopen_period)
            if self._closed:
                return
            try:
                self._open()
            except (serial.SerialException, OSError, ValueError):
                self.counts["reopen_failed"] += 1
                continue
            self.counts["reopened"] += 1
            self.log(f"{self.name}: {self.path} open again")

    async def close(self) -> None:
        self._closed = True
        if self._reopen is not None:
            self._reopen.cancel()
            try:
                await self._reopen
            except (asyncio.CancelledError, Exception):
                pass
        if self.port is not None:
            try:
                self._loop.remove_reader(self.port.fileno())
            except Exception:
                pass
            self.port.close()
            self.port = None
