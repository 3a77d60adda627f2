"""Ending a finished ``steerlab run`` without the interpreter's teardown: about 0.2 s less per run.

When a process with numba, llvmlite, pydantic and numpy loaded ends, Python deallocates every
module and object and the native libraries run their destructors: 0.2 s of CPU after a
``steerlab run`` on this project's machines (0.13 s after a bare ``import numpy, numba,
matplotlib.pyplot``), on the wall-clock time the user waits. A run has written and closed its
files by then, so :func:`exit_now` flushes ``stdout`` and ``stderr``, runs the ``atexit``
handlers (logging, temporary directories, plug-ins' own) and ends the process with
``os._exit``. It does so only when nothing else expects the normal way out: no tracer or
profiler (coverage, cProfile, pyinstrument), no other thread, not ``python -i``, and
``STEERLAB_FAST_EXIT`` not ``0``; otherwise it returns and the caller exits as usual.

Measured with ``python benchmarks/bench_startup.py --switches`` (2026-11-28, the warm default
run with this setting switched off against all on, medians of 5 interleaved rounds, CPU of
the process tree; the machine was loaded, 1-minute load 17, so wall times were 5x the idle
ones and only CPU is quoted; ``benchmarks/RESULTS.md``): 1.84 s of CPU without it against 1.64 s
with it: 0.20 s. Used by the ``steerlab`` command only (:func:`steerlab.cli.console_main`).
"""

from __future__ import annotations

import atexit
import os
import sys
import threading

ENV = "STEERLAB_FAST_EXIT"


def allowed() -> bool:
    """Whether :func:`exit_now` may skip the teardown here (module docstring)."""
    return (os.environ.get(ENV, "1") != "0" and sys.gettrace() is None and sys.getprofile() is None
            and threading.active_count() == 1 and not sys.flags.inspect
            and hasattr(atexit, "_run_exitfuncs"))


def exit_now(code: int) -> None:
    """End the process with ``code`` at once if :func:`allowed` (never returns then)."""
    if not allowed():
        return
    for stream in (sys.stdout, sys.stderr):
        try:
            if stream is not None:
                stream.flush()
        except (OSError, ValueError):      # a closed pipe: nothing more to say
            pass
    atexit._run_exitfuncs()
    os._exit(code)
