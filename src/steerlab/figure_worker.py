"""A child process that imports matplotlib while the command works, then draws its figures.

A run's four PNGs with matplotlib's import cost about 0.7 s of CPU, more than the simulation,
the metrics and the CSV together, and the machines steerlab runs on have two or more cores.
``steerlab run`` starts a :class:`FigureWorker` first thing: the worker forks a child that
imports matplotlib and lays out a first figure (fonts, text engine) while the parent loads the
scenario, designs and simulates (``parts=n`` forks n children that share the figures). The parent then :meth:`~FigureWorker.submit`\\ s the result
(pickled through a pipe, a few MB, by a thread: a child still warming up does not hold the
parent back), writes the CSV and the JSON while the child draws, and
:meth:`~FigureWorker.wait`\\ s: a failure in the child is raised in the parent as one
:class:`RuntimeError` with the child's error line. The parent never imports matplotlib.

The child is used only where fork is safe and helps: Linux, more than one core, no other Python
thread running, ``STEERLAB_FORK_JOBS`` not ``0``. Otherwise, or if the child is gone before the
result reaches it, the parent draws the figures itself in :meth:`~FigureWorker.wait` (same
files, same bytes; tested). A command that fails, or is killed, takes the child with it: it is
killed on the way out, and a child whose parent died reads the end of its pipe and exits.
"""

from __future__ import annotations

import gc
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
    """Draw ``draw(*args, part=k, parts=n)`` in ``n`` children forked at :meth:`start`, with
    ``args`` given later.

    Parameters
    ----------
    draw : callable
        ``draw(*args, part=k, parts=n)``: writes part ``k`` of ``n`` of the figures (e.g.
        :func:`steerlab.report.write_run_figures`).
    warm : callable, optional
        Called in each child right after the fork, while the parent works (imports, a first
        figure).
    parts : int, optional
        Number of children (each draws its part; inline, the parts are drawn in order).
    split : int, optional
        Each child, once the job has arrived, forks ``split - 1`` grandchildren and draws its
        part in ``split`` shares at once (``draw(..., part=k * split + j, parts=parts * split)``).
        Forked after the warm-up, a grandchild starts with matplotlib imported and costs
        milliseconds; the parent is mostly waiting by then, so the shares use its core. A
        grandchild dies with its child (``PR_SET_PDEATHSIG``); its error is the child's.
    """

    def __init__(self, draw: Callable[..., Any], warm: Optional[Callable[[], Any]] = None, parts: int = 1,
                 split: int = 1):
        self.draw = draw
        self.warm = warm
        self.parts = max(1, int(parts))
        self.split = max(1, int(split))
        self._children: list[tuple[int, int, int]] = []     # (pid, job pipe write end, done pipe read end)
        self._args: Optional[tuple] = None
        self._inline = False
        self._writer: Optional[threading.Thread] = None
        self._lost = False

    @property
    def pid(self) -> Optional[int]:
        """The first child's process id (None: no child, the parent draws)."""
        return self._children[0][0] if self._children else None

    # ------------------------------------------------------------------ parent side
    def start(self) -> "FigureWorker":
        """Fork the children (if :func:`fork_allowed`); they warm up, then wait for :meth:`submit`."""
        if not fork_allowed():
            return self
        sys.stdout.flush()
        sys.stderr.flush()
        # the objects so far go to the collector's permanent generation for the fork: a child's
        # collections then never walk (and so never copy) the pages it shares with the parent,
        # about 10 000 page copies and 0.1 s of CPU per run; the parent takes them back
        gc.freeze()
        try:
            self._fork_children()
        finally:
            gc.unfreeze()                              # (a child never returns here)
        return self

    def _fork_children(self) -> None:
        for part in range(self.parts):
            job_r, job_w = os.pipe()
            done_r, done_w = os.pipe()
            pid = os.fork()
            if pid == 0:                               # child: never returns
                for _, w, r in self._children:         # the earlier children's pipes are not ours
                    os.close(w)
                    os.close(r)
                os.close(job_w)
                os.close(done_r)
                self._child(job_r, done_w, part)
            os.close(job_r)
            os.close(done_w)
            self._children.append((pid, job_w, done_r))

    def submit(self, *args: Any) -> None:
        """Hand ``args`` to the children (or keep them for :meth:`wait` to draw inline)."""
        self._args = args
        if not self._children:
            self._inline = True
            return
        data = pickle.dumps(args, protocol=pickle.HIGHEST_PROTOCOL)
        pipes = [job_w for _, job_w, _ in self._children]
        self._children = [(pid, -1, done_r) for pid, _, done_r in self._children]
        # a few MB through 64 kB pipes: written by a thread, so that the caller goes on (CSV,
        # JSON) while a child still warming up has not started reading
        self._writer = threading.Thread(target=self._send, args=(data, pipes), daemon=True)
        self._writer.start()

    def _send(self, data: bytes, pipes: list) -> None:
        try:
            for job_w in pipes:
                _write_all(job_w, data)
        except OSError:                                # BrokenPipeError: a child is gone
            self._lost = True
        finally:
            for job_w in pipes:
                try:
                    os.close(job_w)
                except OSError:
                    pass

    def _join_writer(self) -> bool:
        """Wait for :meth:`submit`'s writer; whether every child got the job."""
        writer, self._writer = self._writer, None
        if writer is not None:
            writer.join()
        lost, self._lost = self._lost, False
        return not lost

    def wait(self) -> None:
        """Wait for the children's figures (or draw them here); raise a child's error."""
        if not self._join_writer():
            self.cancel()                              # a child is gone: draw here instead
            self._inline = True
        if self._inline:
            self._inline = False
            for part in range(self.parts):
                self.draw(*self._args, part=part, parts=self.parts)
            return
        errors = []
        for pid, _, done_r in self._children:
            message = _read_all(done_r).decode("utf-8", "replace")
            os.close(done_r)
            _, status = os.waitpid(pid, 0)
            if status != 0:
                errors.append(message or f"exit status {status}")
        self._children = []
        if errors:
            raise RuntimeError(f"drawing the figures failed: {errors[0]}")

    def cancel(self) -> None:
        """Kill the children (if any) and close the pipes; nothing is drawn."""
        for pid, job_w, done_r in self._children:
            for fd in (job_w, done_r):
                if fd >= 0:
                    try:
                        os.close(fd)
                    except OSError:
                        pass
            try:
                os.kill(pid, 9)
                os.waitpid(pid, 0)
            except OSError:
                pass
        self._children = []
        self._join_writer()                            # its writes fail now that the children are gone

    def __enter__(self) -> "FigureWorker":
        return self.start()

    def __exit__(self, exc_type, exc, tb) -> None:
        if exc_type is None and (self._inline or self._children):
            self.wait()
        else:                                          # failed, or nothing was submitted
            self.cancel()

    # ------------------------------------------------------------------ child side
    def _child(self, job_r: int, done_w: int, part: int) -> None:
        def work():
            if self.warm is not None:
                self.warm()
            data = _read_all(job_r)
            if data:                                   # empty: the parent cancelled or died
                self._draw_shares(pickle.loads(data), part)

        _run_then_exit(work, done_w)

    def _draw_shares(self, args: tuple, part: int) -> None:
        """Draw part ``part`` in :attr:`split` shares: share 0 here, the others in grandchildren."""
        m, n = self.split, self.parts * self.split
        me = os.getpid()
        gc.freeze()                                    # as in start(): this process ends after drawing
        grandchildren = []
        for j in range(1, m):
            try:
                err_r, err_w = os.pipe()
                pid = os.fork()
            except OSError:                            # no fork: the child draws the rest itself
                break
            if pid == 0:                               # grandchild: never returns
                os.close(err_r)

                def share(j=j):
                    _die_with_parent(me)
                    self.draw(*args, part=part * m + j, parts=n)

                _run_then_exit(share, err_w)
            os.close(err_w)
            grandchildren.append((pid, err_r))
        for j in [0, *range(1 + len(grandchildren), m)]:
            self.draw(*args, part=part * m + j, parts=n)
        errors = []
        for pid, err_r in grandchildren:
            message = _read_all(err_r).decode("utf-8", "replace")
            os.close(err_r)
            _, status = os.waitpid(pid, 0)
            if status != 0:
                errors.append(message or f"exit status {status}")
        if errors:
            raise _ChildError(errors[0])


def _run_then_exit(work: Callable[[], Any], err_fd: int) -> None:
    """In a forked process: run ``work``, write its error line (if any) to ``err_fd``, exit."""
    code = 0
    try:
        work()
    except BaseException as err:                       # noqa: BLE001 - reported to the parent
        try:
            os.write(err_fd, _error_line(err))
        except OSError:
            pass
        code = 1
    finally:
        os._exit(code)


class _ChildError(Exception):
    """A grandchild's error line, passed on as it is."""


def _error_line(err: BaseException) -> bytes:
    text = str(err) if isinstance(err, _ChildError) else f"{type(err).__name__}: {err}"
    return text.encode("utf-8", "replace")[:4000]


def _die_with_parent(parent: int) -> None:
    """Ask Linux to kill this process when its parent (process id ``parent``) dies (the
    command's ``cancel`` kills only its children); exit at once if it is already gone."""
    import ctypes
    import signal

    try:
        ctypes.CDLL(None, use_errno=True).prctl(1, int(signal.SIGKILL))    # PR_SET_PDEATHSIG = 1
    except (OSError, AttributeError):
        pass
    if os.getppid() != parent:
        os._exit(1)
