"""WebSocket slots that idle clients cannot hold against the operator.

A runtime server (bridge page, Signal K stream) keeps at most ``capacity`` WebSocket clients.
On loopback every local process has the same address, so a cap per address cannot tell the
operator's browser from a hostile process that opens connections and sends nothing. Instead,
when the slots are full a new client takes the slot of the client that has been **quiet
longest** (no message from it since it connected or last spoke), provided that one has been
quiet at least ``min_quiet`` seconds; the evicted client is closed with code 1013 ("try again
later"). Only when every client spoke within ``min_quiet`` is the newcomer refused (503).

So a hundred idle clients cannot lock the operator out: the operator's page evicts the oldest
of them, and once it acts it is the newest speaker and the last to be evicted. A process that
keeps every slot busy by talking on each of them (rate-limited per connection) is the limit of
this defence (docs/reliability.md).
"""

from __future__ import annotations

import asyncio
import time

EVICT_CODE = 1013
"""WebSocket close code sent to an evicted client (RFC 6455 section 7.4.1: try again later)."""


class ClientSlots:
    """``capacity`` slots; :meth:`make_room` before accepting, :meth:`add` / :meth:`touch` /
    :meth:`remove` over a client's life. ``clock``: seconds, monotonic."""

    def __init__(self, capacity: int, min_quiet: float = 1.0, clock=time.monotonic):
        self.capacity = int(capacity)
        self.min_quiet = float(min_quiet)
        self.clock = clock
        self.last: dict = {}            # connection -> time it last spoke (or connected) [s]
        self.evicted = 0

    def __len__(self) -> int:
        return len(self.last)

    def add(self, conn) -> None:
        """Give ``conn`` a slot; it is freed when the connection is lost (websockets'
        ``connection_lost_waiter``), even if its handshake then fails."""
        self.last[conn] = self.clock()
        lost = getattr(conn, "connection_lost_waiter", None)
        if lost is not None and hasattr(lost, "add_done_callback"):
            lost.add_done_callback(lambda _f, c=conn: self.remove(c))

    def touch(self, conn) -> None:
        if conn in self.last:
            self.last[conn] = self.clock()

    def remove(self, conn) -> None:
        self.last.pop(conn, None)

    def make_room(self) -> bool:
        """True if a new client may connect now (a quiet one evicted if the slots were full)."""
        if len(self.last) < self.capacity:
            return True
        victim, spoke = min(self.last.items(), key=lambda kv: kv[1])
        if self.clock() - spoke < self.min_quiet:
            return False
        self.last.pop(victim)           # its slot is the newcomer's now; it closes in the background
        self.evicted += 1
        close = getattr(victim, "close", None)
        if close is not None:
            try:
                asyncio.get_running_loop().create_task(close(EVICT_CODE, "slots full: the quietest client makes room"))
            except RuntimeError:        # no loop (a test's plain object): nothing to close
                pass
        return True
