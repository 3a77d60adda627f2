"""Report rejected input while the runtime runs (not only at exit).

A flood, a second sender refused by the session lock, a DNS-rebinding page or a stream of
malformed sentences used to show only in the totals printed at exit. :func:`report_rejections`
prints one line per source every ``period`` seconds in which something new was rejected, with
the counts by reason since the last line (nothing when nothing was rejected).
"""

from __future__ import annotations

import asyncio
import sys
from collections import Counter

NOT_REJECTIONS = frozenset({"accepted", "ignored", "clients", "sent", "subscriptions", "put_ok"})
"""Counter keys that count normal traffic, not rejections."""


def rejections(counts) -> Counter:
    """The rejection counts of a counter dict (normal-traffic keys dropped, zeros dropped)."""
    return Counter({k: v for k, v in dict(counts).items() if k not in NOT_REJECTIONS and v})


async def report_rejections(prog: str, sources: dict, period: float = 10.0, out=None, sleep=None) -> None:
    """Every ``period`` [wall s], one line per source with new rejections: ``sources`` maps a name
    to a function returning its counters (e.g. ``lambda: server.filter.counts``). Runs until
    cancelled. ``sleep``: the coroutine function that waits a period (tests pass their own)."""
    sleep = sleep or asyncio.sleep
    last = {name: rejections(get()) for name, get in sources.items()}
    while True:
        await sleep(period)
        for name, get in sources.items():
            now = rejections(get())
            new = now - last[name]
            last[name] = now
            if new:
                print(f"{prog}: {name}: rejected in the last {period:g} s: "
                      + ", ".join(f"{k} {v}" for k, v in sorted(new.items())),
                      file=out or sys.stderr, flush=True)
