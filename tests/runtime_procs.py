"""A ``python -m steerlab ...`` process for the runtime tests (a ship server, an autopilot),
with its stderr lines collected as they come, waits on them, Ctrl-C and a bounded wait."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import threading
import time


class SteerlabProcess:
    """A ``python -m steerlab ...`` process whose stderr lines are collected by a thread."""

    def __init__(self, argv):
        self.lines: list[str] = []
        self.p = subprocess.Popen([sys.executable, "-m", "steerlab", *argv], stdin=subprocess.DEVNULL,
                                  stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()

    def _read(self):
        for line in self.p.stderr:
            self.lines.append(line.rstrip("\n"))

    def wait_for(self, pattern: str, limit_s: float = 120.0) -> re.Match:
        end = time.monotonic() + limit_s
        while time.monotonic() < end:
            for line in list(self.lines):
                if m := re.search(pattern, line):
                    return m
            if self.p.poll() is not None and not self._reader.is_alive():
                break
            time.sleep(0.02)
        raise AssertionError(f"no line matching {pattern!r}; stderr:\n" + "\n".join(self.lines))

    def interrupt(self) -> None:
        """Ctrl-C (after SIGCONT, in case it is frozen)."""
        if self.p.poll() is None:
            os.kill(self.p.pid, signal.SIGCONT)
            os.kill(self.p.pid, signal.SIGINT)

    def wait(self) -> int:
        try:
            return self.p.wait(timeout=30)
        except subprocess.TimeoutExpired:
            self.p.kill()
            return self.p.wait(timeout=30)
