"""Progress messages of long commands: one text bar for every command that has one."""

from __future__ import annotations

BAR_WIDTH = 20


def bar(done: float, total: float, width: int = BAR_WIDTH) -> str:
    """``[#####...............]``: ``done`` of ``total`` as a bar of ``width`` characters."""
    filled = min(width, max(0, int(round(width * done / max(total, 1)))))
    return f"[{'#' * filled}{'.' * (width - filled)}]"


def runs_progress(say, what: str = "runs"):
    """A ``progress(done, total)`` callback for the batch engine that prints through ``say``."""
    def progress(done: int, total: int) -> None:
        say(f"{bar(done, total)} {done}/{total} {what}")

    return progress
