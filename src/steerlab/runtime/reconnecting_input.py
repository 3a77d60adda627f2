"""The scaffolding every reconnecting network input shares (NMEA over TCP, Signal K).

A subclass writes ``_run``, the coroutine that connects, reads until the link drops and
reconnects every ``reconnect_period`` seconds; this class holds what they have in common: the
address, the ``connected`` flag and the ``counts`` of link events, and the task's start and
cancellation.
"""

from __future__ import annotations

import asyncio
import sys
from collections import Counter


def stderr_line(line: str) -> None:
    """The inputs' default ``log``: one line to standard error, flushed."""
    print(line, file=sys.stderr, flush=True)


class ReconnectingInput:
    """A network input that keeps reconnecting (``connected``, ``ever_connected``, ``counts``).

    Parameters
    ----------
    host, port : str, int
        The talker or server to connect to.
    reconnect_period : float
        Seconds between connection attempts and after a dropped link [s].
    log : callable
        One-line messages (default: standard error).
    """

    def __init__(self, host: str, port: int, reconnect_period: float = 1.0, log=stderr_line):
        self.host, self.port = host, int(port)
        self.reconnect_period = float(reconnect_period)
        self.log = log
        self.counts: Counter = Counter()
        self.connected = False
        self.ever_connected = False
        self._task = None

    def lost(self) -> bool:
        """True when the link was up once and is down now."""
        return self.ever_connected and not self.connected

    async def _run(self) -> None:          # pragma: no cover - every subclass writes its own
        raise NotImplementedError

    async def start(self):
        """Start reconnecting in the running event loop; returns ``self``."""
        self._task = asyncio.get_running_loop().create_task(self._run())
        return self

    async def close(self) -> None:
        """Cancel the connection task and wait for it to end."""
        if self._task is not None:
            self._task.cancel()
            try:
                await self._task
            except (asyncio.CancelledError, Exception):
                pass
