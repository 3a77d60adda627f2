"""Progress messages of long commands: one text bar for every command that has one."""

from __future__ import annotations

import math
import time

BAR_WIDTH = 20


def bar(done: float, total: float, width: int = BAR_WIDTH) -> str:
    """``[#####...............]``: ``done`` of ``total`` as a bar of ``width`` characters."""
    filled = min(width, max(0, int(round(width * done / max(total, 1)))))
    return f"[{'#' * filled}{'.' * (width - filled)}]"


def runs_progress(say, what: str = "runs", period: float = 1.0):
    """A ``progress(done, total)`` callback for the batch engine that prints through ``say``:
    at most once every ``period`` seconds, and always when ``done == total``."""
    last = [-math.inf]

    def progress(done: int, total: int) -> None:
        now = time.perf_counter()
        if done >= total or now - last[0] >= period:
            last[0] = now
            say(f"{bar(done, total)} {done}/{total} {what}")

    return progress
