"""A child process that imports matplotlib while the command works, then draws its figures.

A run's four PNGs with matplotlib's import cost about 0.7 s of CPU, more than the simulation,
the metrics and the CSV together, and the machines steerlab runs on have two or more cores.
``steerlab run`` starts a :class:`FigureWorker` first thing: the worker forks a child that
imports matplotlib and lays out a first figure (fonts, text engine) while the parent loads the
scenario, designs and simulates. The parent then :meth:`~FigureWorker.submit`\\ s the result
(pickled through a pipe, a few MB), writes the CSV and the JSON while the child draws, and
:meth:`~FigureWorker.wait`\\ s: a failure in the child is raised in the parent as one
:class:`RuntimeError` with the child's error line. The parent never imports matplotlib.

The child is used only where fork is safe and helps: Linux, more than one core, no other Python
thread running, ``STEERLAB_FORK_JOBS`` not ``0``. Otherwise, or if the child is gone before the
result reaches it, the parent draws the figures itself in :meth:`~FigureWorker.wait` (same
files, same bytes; tested). A command that fails, or is killed, takes the child with it: it is
killed on the way out, and a child whose parent died reads the end of its pipe and exits.
"""

from __future__ import annotations

import os
import pickle
import sys
import threading
from typing import Any, Callable, Optional

ENV = "STEERLAB_FORK_JOBS"


def fork_allowed() -> bool:
    """Whether :class:`FigureWorker` forks here (see the module docstring)."""
    return (sys.platform.startswith("linux") and hasattr(os, "fork") and (os.cpu_count() or 1) > 1
            and threading.active_count() == 1 and os.environ.get(ENV, "1") != "0")


def _read_all(fd: int) -> bytes:
    chunks = []
    while True:
        chunk = os.read(fd, 1 << 20)
        if not chunk:
            return b"".join(chunks)
        chunks.append(chunk)


def _write_all(fd: int, data: bytes) -> None:
    view = memoryview(data)
    while view:
        view = view[os.write(fd, view):]


class FigureWorker:
    """Draw ``draw(*args)`` in a child forked at :meth:`start`, with ``args`` given later.

    Parameters
    ----------
    draw : callable
        ``draw(*args)``: writes the figures (e.g. :func:`steerlab.report.write_run_figures`).
    warm : callable, optional
        Called in the child right after the fork, while the parent works (imports, a first
        figure).
    """

    def __init__(self, draw: Callable[..., Any], warm: Optional[Callable[[], Any]] = None):
        self.draw = draw
        self.warm = warm
        self.pid: Optional[int] = None
        self._job_w: Optional[int] = None
        self._done_r: Optional[int] = None
        self._args: Optional[tuple] = None
        self._inline = False

    # ------------------------------------------------------------------ parent side
    def start(self) -> "FigureWorker":
        """Fork the child (if :func:`fork_allowed`); it warms up, then waits for :meth:`submit`."""
        if not fork_allowed():
            return self
        sys.stdout.flush()
        sys.stderr.flush()
        job_r, job_w = os.pipe()
        done_r, done_w = os.pipe()
        pid = os.fork()
        if pid == 0:                                   # child: never returns
            os.close(job_w)
            os.close(done_r)
            self._child(job_r, done_w)
        os.close(job_r)
        os.close(done_w)
        self.pid, self._job_w, self._done_r = pid, job_w, done_r
        return self

    def submit(self, *args: Any) -> None:
        """Hand ``args`` to the child (or keep them for :meth:`wait` to draw inline)."""
        self._args = args
        if self.pid is None:
            self._inline = True
            return
        try:
            _write_all(self._job_w, pickle.dumps(args, protocol=pickle.HIGHEST_PROTOCOL))
        except (BrokenPipeError, OSError, pickle.PicklingError):
            self.cancel()                              # the child is gone: draw here instead
            self._inline = True
            return
        os.close(self._job_w)
        self._job_w = None

    def wait(self) -> None:
        """Wait for the child's figures (or draw them here); raise the child's error."""
        if self._inline:
            self._inline = False
            self.draw(*self._args)
            return
        if self.pid is None:
            return
        message = _read_all(self._done_r).decode("utf-8", "replace")
        os.close(self._done_r)
        self._done_r = None
        _, status = os.waitpid(self.pid, 0)
        self.pid = None
        if status != 0:
            raise RuntimeError(f"drawing the figures failed: {message or f'exit status {status}'}")

    def cancel(self) -> None:
        """Kill the child (if any) and close the pipes; nothing is drawn."""
        for fd in (self._job_w, self._done_r):
            if fd is not None:
                try:
                    os.close(fd)
                except OSError:
                    pass
        self._job_w = self._done_r = None
        if self.pid is not None:
            try:
                os.kill(self.pid, 9)
                os.waitpid(self.pid, 0)
            except OSError:
                pass
            self.pid = None

    def __enter__(self) -> "FigureWorker":
        return self.start()

    def __exit__(self, exc_type, exc, tb) -> None:
        if exc_type is None and (self._inline or self._args is not None):
            self.wait()
        else:                                          # failed, or nothing was submitted
            self.cancel()

    # ------------------------------------------------------------------ child side
    def _child(self, job_r: int, done_w: int) -> None:
        code = 0
        try:
            if self.warm is not None:
                self.warm()
            data = _read_all(job_r)
            if data:                                   # empty: the parent cancelled or died
                self.draw(*pickle.loads(data))
        except BaseException as err:                   # noqa: BLE001 - reported to the parent
            try:
                os.write(done_w, f"{type(err).__name__}: {err}".encode("utf-8", "replace")[:4000])
            except OSError:
                pass
            code = 1
        finally:
            os._exit(code)
