"""Run independent jobs (figures) in forked child processes while the parent goes on.

A run's four PNGs cost about 0.7 s of CPU with matplotlib's import, more than the simulation,
the metrics and the CSV together; the machines steerlab runs on have two or more cores. A
:class:`ForkedJobs` forks one child per group of jobs (after the run, so the children share the
result's arrays without copying or pickling), the parent writes the CSV and the JSON meanwhile,
and :meth:`ForkedJobs.wait` joins them: a job that fails in a child is raised in the parent as
one :class:`RuntimeError` with the child's error line (inline, the job's own exception).

Fork is used only where it is safe and helps: Linux, more than one core, no other Python thread
running, and ``STEERLAB_FORK_JOBS`` not ``0``. Otherwise the jobs run in the parent, in order,
inside :meth:`wait` (same files, same bytes).
"""

from __future__ import annotations

import os
import sys
import threading
from typing import Callable, Sequence

ENV = "STEERLAB_FORK_JOBS"


def fork_allowed() -> bool:
    """Whether :class:`ForkedJobs` forks here (see the module docstring)."""
    return (sys.platform.startswith("linux") and hasattr(os, "fork") and (os.cpu_count() or 1) > 1
            and threading.active_count() == 1 and os.environ.get(ENV, "1") != "0")


class ForkedJobs:
    """Groups of zero-argument callables, each group in a forked child (or inline).

    Parameters
    ----------
    groups : sequence of sequence of callable
        Each group runs in order in one child process; the groups run in parallel.
    """

    def __init__(self, groups: Sequence[Sequence[Callable[[], object]]]):
        self.groups = [list(g) for g in groups if g]
        self._children: list[tuple[int, int]] = []     # (pid, read end of its error pipe)
        self._inline: list[list[Callable[[], object]]] = []

    def start(self) -> "ForkedJobs":
        """Fork the children (or keep the groups for :meth:`wait` to run inline)."""
        if not fork_allowed():
            self._inline = self.groups
            return self
        sys.stdout.flush()
        sys.stderr.flush()
        for group in self.groups:
            r, w = os.pipe()
            pid = os.fork()
            if pid == 0:                             # child: run the group, report, never return
                os.close(r)
                code = 0
                try:
                    for job in group:
                        job()
                except BaseException as err:         # noqa: BLE001 - reported to the parent
                    os.write(w, f"{type(err).__name__}: {err}".encode("utf-8", "replace")[:4000])
                    code = 1
                finally:
                    os._exit(code)
            os.close(w)
            self._children.append((pid, r))
        return self

    def wait(self) -> None:
        """Run the inline groups, or join every child; raise the first child's error."""
        for group in self._inline:
            for job in group:
                job()
        self._inline = []
        errors = []
        for pid, r in self._children:
            chunks = []
            while True:
                chunk = os.read(r, 4096)
                if not chunk:
                    break
                chunks.append(chunk)
            os.close(r)
            _, status = os.waitpid(pid, 0)
            if status != 0:
                message = b"".join(chunks).decode("utf-8", "replace") or f"exit status {status}"
                errors.append(message)
        self._children = []
        if errors:
            raise RuntimeError(f"a forked job failed: {errors[0]}")

    def __enter__(self) -> "ForkedJobs":
        return self.start()

    def __exit__(self, exc_type, exc, tb) -> None:
        if exc_type is None:
            self.wait()
            return
        for pid, r in self._children:               # the parent failed: do not leave children behind
            try:
                os.kill(pid, 9)
                os.waitpid(pid, 0)
            except OSError:
                pass
            os.close(r)
        self._children = []
