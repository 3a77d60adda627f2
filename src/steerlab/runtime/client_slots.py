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
keeps every slot busy by talking on each of them (rate-limited per connection) defeats that
alone; hence **reserved operator slots** (``operator_capacity``, :data:`OPERATOR_SLOTS`): a
client that presents the run's operator token (:mod:`steerlab.runtime.operator_session`) takes
one of them, outside the public ``capacity``, whatever the other clients do; when they are full
the operator's newest connection replaces its oldest (a page reopened). No other client can
take or evict an operator slot.
"""

from __future__ import annotations

import asyncio
import time

OPERATOR_SLOTS = 2
"""Connections reserved for the operator (a bridge page and a phone, say), beyond ``capacity``."""
EVICT_CODE = 1013
"""WebSocket close code sent to an evicted client (RFC 6455 section 7.4.1: try again later)."""


class ClientSlots:
    """``capacity`` slots; :meth:`make_room` before accepting, :meth:`add` / :meth:`touch` /
    :meth:`remove` over a client's life. ``clock``: seconds, monotonic."""

    def __init__(self, capacity: int, min_quiet: float = 1.0, clock=time.monotonic,
                 operator_capacity: int = OPERATOR_SLOTS):
        self.capacity = int(capacity)
        self.operator_capacity = int(operator_capacity)
        self.min_quiet = float(min_quiet)
        self.clock = clock
        self.last: dict = {}            # connection -> time it last spoke (or connected) [s]
        self.operator: dict = {}        # the operator's connections -> time they connected [s]
        self.evicted = 0
        self.operator_replaced = 0

    def __len__(self) -> int:
        return len(self.last) + len(self.operator)

    def add(self, conn, operator: bool = False) -> None:
        """Give ``conn`` a slot (a reserved one for the ``operator``); it is freed when the
        connection is lost (websockets' ``connection_lost_waiter``), even if its handshake then fails."""
        (self.operator if operator else self.last)[conn] = self.clock()
        lost = getattr(conn, "connection_lost_waiter", None)
        if lost is not None and hasattr(lost, "add_done_callback"):
            lost.add_done_callback(lambda _f, c=conn: self.remove(c))

    def touch(self, conn) -> None:
        if conn in self.last:
            self.last[conn] = self.clock()

    def remove(self, conn) -> None:
        self.last.pop(conn, None)
        self.operator.pop(conn, None)

    @staticmethod
    def _close(victim, reason: str) -> None:
        close = getattr(victim, "close", None)
        if close is not None:
            try:
                asyncio.get_running_loop().create_task(close(EVICT_CODE, reason))
            except RuntimeError:        # no loop (a test's plain object): nothing to close
                pass

    def make_room(self, operator: bool = False) -> bool:
        """True if a new client may connect now (a quiet one evicted if the slots were full).
        The ``operator`` always may: a reserved slot, its own oldest connection replaced when
        they are all taken."""
        if operator:
            if len(self.operator) >= max(1, self.operator_capacity):
                victim = min(self.operator.items(), key=lambda kv: kv[1])[0]
                self.operator.pop(victim)
                self.operator_replaced += 1
                self._close(victim, "the operator connected again elsewhere")
            return True
        if len(self.last) < self.capacity:
            return True
        victim, spoke = min(self.last.items(), key=lambda kv: kv[1])
        if self.clock() - spoke < self.min_quiet:
            return False
        self.last.pop(victim)           # its slot is the newcomer's now; it closes in the background
        self.evicted += 1
        self._close(victim, "slots full: the quietest client makes room")
        return True
