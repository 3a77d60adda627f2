"""Lines out of a byte stream (serial port, TCP), bounded, and grouped as NMEA "datagrams".

A stream has no datagram boundaries: :class:`LineSplitter` cuts it at LF (CR LF or LF, as
NMEA 0183 talkers end lines), keeps an unfinished line for the next chunk, and drops a line
that grows past ``max_line`` bytes without an end (counted ``overlong``), so garbage without
newlines never grows memory. :func:`nmea_chunks` groups complete lines into the byte chunks
the autopilot's NMEA input takes (:meth:`steerlab.runtime.autopilot.Autopilot.on_nmea_datagram`):
at most :data:`steerlab.runtime.nmea.MAX_LINES` lines each, a line with non-ASCII bytes alone
(rejected once as ``not_ascii``, without taking the good lines around it along).
"""

from __future__ import annotations

from collections import Counter

MAX_STREAM_LINE = 1024
"""An unterminated line longer than this [bytes] is dropped (NMEA lines are at most 82)."""


class LineSplitter:
    """Feed bytes, get complete lines (without the line end)."""

    def __init__(self, max_line: int = MAX_STREAM_LINE):
        self.max_line = int(max_line)
        self.buf = bytearray()
        self.dropping = False          # inside an overlong line: skip to its end
        self.counts: Counter = Counter()

    def feed(self, data: bytes) -> list[bytes]:
        out = []
        self.buf += data
        while True:
            i = self.buf.find(b"\n")
            if i < 0:
                break
            line = bytes(self.buf[:i]).rstrip(b"\r")
            del self.buf[:i + 1]
            if self.dropping:
                self.dropping = False
                continue
            if line.strip():
                out.append(line)
        if len(self.buf) > self.max_line:
            if not self.dropping:
                self.counts["overlong"] += 1
            self.dropping = True
            self.buf.clear()
        return out


def nmea_chunks(lines, max_lines: int = 32):
    """Group ``lines`` (bytes, no line ends) into CRLF-joined chunks of at most ``max_lines``;
    a line with a non-ASCII byte forms a chunk of its own."""
    chunk: list[bytes] = []
    for ln in lines:
        if not ln.isascii():
            if chunk:
                yield b"\r\n".join(chunk) + b"\r\n"
                chunk = []
            yield ln + b"\r\n"
            continue
        chunk.append(ln)
        if len(chunk) >= max_lines:
            yield b"\r\n".join(chunk) + b"\r\n"
            chunk = []
    if chunk:
        yield b"\r\n".join(chunk) + b"\r\n"
