"""Progress of long commands: one bar for every command that has one, and the status lines.

Every long computation reports through a ``say(msg: str)`` callback. Progress updates are
:class:`BarMessage` strings (made by :func:`bar_message`: the text bar, and how far along);
anything else is a status line. The CLI's sink, :class:`Reporter`, shows them:

* on a terminal: status lines as they come, and the bar as **one updating line** (rewritten
  in place with a carriage return, cut to the terminal's width so it never wraps; the
  finished bar stays on screen);
* not on a terminal (a pipe, a log file, CI, or ``CI`` set in the environment): status lines
  as they come, and the bar as **sparse plain lines**, at most one every
  :data:`PLAIN_PERIOD` seconds plus the last one (``done == total``), so a long command
  writes a few dozen lines to a log, not thousands.

Each line starts with the time since the command started, ``[  12.3 s]``.
"""

from __future__ import annotations

import math
import os
import re
import shutil
import sys
import time
from typing import Callable, Optional, TextIO

BAR_WIDTH = 20
PLAIN_PERIOD = 10.0    #: seconds between two progress lines when not on a terminal
TTY_PERIOD = 0.1       #: seconds between two redraws of the bar on a terminal

Say = Callable[[str], None]
"""A progress sink: called with one message (a status line or a :class:`BarMessage`)."""

_BAR_RE = re.compile(r"^\[([#.]+)\]")


def bar(done: float, total: float, width: int = BAR_WIDTH) -> str:
    """``[#####...............]``: ``done`` of ``total`` as a bar of ``width`` characters."""
    filled = min(width, max(0, int(round(width * done / max(total, 1)))))
    return f"[{'#' * filled}{'.' * (width - filled)}]"


class BarMessage(str):
    """A progress update: the text (starting with :func:`bar`) plus ``done`` and ``total``."""

    done: float
    total: float

    def __new__(cls, text: str, done: float, total: float) -> "BarMessage":
        obj = super().__new__(cls, text)
        obj.done = float(done)
        obj.total = float(total)
        return obj

    @property
    def finished(self) -> bool:
        """True for the last update (``done >= total``)."""
        return self.done >= self.total


def bar_message(done: float, total: float, text: str = "") -> BarMessage:
    """The progress update ``"[####......] text"`` for ``done`` of ``total``."""
    return BarMessage(f"{bar(done, total)} {text}".rstrip(), done, total)


def _as_bar(msg: str) -> Optional[BarMessage]:
    """``msg`` as a progress update, or None for a status line (a plain string that starts
    with a bar counts as an update, finished when the bar is full)."""
    if isinstance(msg, BarMessage):
        return msg
    m = _BAR_RE.match(msg)
    if m is None:
        return None
    filled = m.group(1).count("#")
    return BarMessage(msg, filled, len(m.group(1)))


def runs_progress(say: Say, what: str = "runs", period: float = 1.0) -> Callable[[int, int], None]:
    """A ``progress(done, total)`` callback for the batch engine that reports through ``say``:
    at most once every ``period`` seconds, and always when ``done == total``."""
    last = [-math.inf]

    def progress(done: int, total: int) -> None:
        now = time.perf_counter()
        if done >= total or now - last[0] >= period:
            last[0] = now
            say(bar_message(done, total, f"{done}/{total} {what}"))

    return progress


def is_terminal(stream: TextIO) -> bool:
    """True when ``stream`` is an interactive terminal and ``CI`` is not set."""
    if os.environ.get("CI", "").strip().lower() not in ("", "0", "false", "no"):
        return False
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError):
        return False


class Reporter:
    """The CLI's progress sink (module doc): ``reporter(msg)`` shows a status line or updates
    the bar; :meth:`close` ends an open bar line.

    Parameters
    ----------
    quiet : bool
        Show nothing.
    stream : text stream, optional
        Where to write (default ``sys.stderr`` at the time of each message).
    tty : bool, optional
        Force terminal (True) or plain (False) behaviour; default :func:`is_terminal`.
    plain_period : float
        Seconds between two bar lines when not on a terminal [s].
    clock : callable, optional
        Time source [s] (default ``time.perf_counter``; tests pass their own).
    """

    def __init__(self, quiet: bool = False, stream: Optional[TextIO] = None, tty: Optional[bool] = None,
                 plain_period: float = PLAIN_PERIOD, clock: Callable[[], float] = time.perf_counter) -> None:
        self.quiet = quiet
        self._stream = stream
        self._tty = tty
        self.plain_period = plain_period
        self._clock = clock
        self._start = clock()
        self._last_bar = -math.inf
        self._open = False          # a bar line is on screen without its newline (terminal)
        self._pending: Optional[str] = None   # the latest bar not drawn yet (terminal)

    @property
    def stream(self) -> TextIO:
        return self._stream if self._stream is not None else sys.stderr

    @property
    def tty(self) -> bool:
        return is_terminal(self.stream) if self._tty is None else self._tty

    def _stamp(self, msg: str) -> str:
        return f"[{self._clock() - self._start:6.1f} s] {msg}"

    def __call__(self, msg: str) -> None:
        if self.quiet:
            return
        update = _as_bar(msg)
        if update is None:
            self._line(msg)
            return
        now = self._clock()
        if self.tty:
            if update.finished or now - self._last_bar >= TTY_PERIOD:
                self._last_bar = now
                width = max(20, shutil.get_terminal_size((100, 24)).columns - 1)
                text = self._stamp(str(update))
                self.stream.write("\r" + text[:width] + "\x1b[K")
                self._open = True
                if update.finished:             # the finished bar stays; what follows goes below it
                    self.close()
                self.stream.flush()
        elif update.finished or now - self._last_bar >= self.plain_period:
            self._last_bar = now
            self._write(self._stamp(str(update)))

    def _line(self, msg: str) -> None:
        self.close()
        self._write(self._stamp(msg))

    def _write(self, text: str) -> None:
        print(text, file=self.stream, flush=True)

    def close(self) -> None:
        """End an open bar line (terminal): the next output starts on a new line."""
        if self._open:
            self.stream.write("\n")
            self.stream.flush()
            self._open = False


_REPORTERS: list[Reporter] = []


def reporter(quiet: bool = False) -> Reporter:
    """A :class:`Reporter` on ``sys.stderr`` for one command (closed by :func:`close_all`)."""
    r = Reporter(quiet)
    _REPORTERS.append(r)
    return r


def close_all(forget: bool = False) -> None:
    """End the open bar line of every reporter made by :func:`reporter`; ``forget``: also drop
    them (end of a command)."""
    for r in _REPORTERS:
        r.close()
    if forget:
        _REPORTERS.clear()
