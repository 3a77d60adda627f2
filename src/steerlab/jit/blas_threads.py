"""A ``steerlab`` command runs numpy's OpenBLAS on one thread (unless the user chose a number).

numpy's wheels bundle OpenBLAS, which starts one thread per core when numpy is imported. An
idle OpenBLAS thread busy-waits (about 0.1 s of a core) before it sleeps, at start-up and after
each BLAS call; and OpenBLAS stops its threads before every ``fork`` and starts them again at
the next BLAS call, in the parent and in each child. ``steerlab run`` forks the children that
draw its figures (:mod:`steerlab.figure_worker`) while it simulates, so on two cores those
spinning threads took the cores the figures were drawn on. A command's BLAS calls are small
(matrices of a ship's few states; a fit of at most a few parameters), so more threads never
pay: on the 2-core development machine the bundled default run took 0.82-0.85 s with OpenBLAS's
default threads and 0.70-0.75 s with one (medians of alternating runs; CPU 1.38-1.45 s against
1.09-1.16 s; ``docs/compile-cache.md``).

:func:`one_thread_for_commands` (called by ``import steerlab`` before numpy is imported) sets
``OPENBLAS_NUM_THREADS=1`` when this process is the ``steerlab`` command (the console script or
``python -m steerlab``: :func:`is_command_process`), numpy is not imported yet (afterwards it
would have no effect) and the variable is not set (a user's value is kept). The processes the
command starts inherit it. ``import steerlab`` in a user's own program or notebook changes
nothing: their numpy keeps its threads. ``STEERLAB_ONE_BLAS_THREAD=0`` switches it off.

Measured with ``python benchmarks/bench_startup.py --switches`` (2026-11-28, the warm default
run with this setting switched off against all on, medians of 5 interleaved rounds, CPU of
the process tree; the machine was loaded, 1-minute load 17, so wall times were 5x the idle
ones and only CPU is quoted; ``benchmarks/RESULTS.md``): 1.77 s of CPU without it against 1.64 s
with it: 0.13 s.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Sequence
from pathlib import Path

VARIABLE = "OPENBLAS_NUM_THREADS"
ENV = "STEERLAB_ONE_BLAS_THREAD"
#: the interpreter's options that take a value in the next argument (``python -X importtime``)
_OPTIONS_WITH_VALUE = ("-W", "-X")
#: the console script's names (``pip`` writes ``steerlab``, on Windows ``steerlab.exe``)
_SCRIPT_NAMES = ("steerlab", "steerlab.exe")


def is_command_process(orig_argv: Sequence[str], argv0: str) -> bool:
    """Whether a process started as ``orig_argv`` (``sys.orig_argv``, the interpreter's own
    command line) with ``sys.argv[0] == argv0`` is the ``steerlab`` command.

    The console script (``argv0`` names the ``steerlab`` script) and ``python [options] -m
    steerlab ...`` are; ``python script.py``, ``python -c ...``, ``python -m pytest`` and the
    like are not.
    """
    if Path(argv0).name in _SCRIPT_NAMES:
        return True
    args = list(orig_argv[1:])
    i = 0
    while i < len(args):
        a = args[i]
        if a == "-m":
            return i + 1 < len(args) and args[i + 1] == "steerlab"
        if a.startswith("-m"):
            return a[2:] == "steerlab"
        if a == "-c" or a == "-" or not a.startswith("-"):
            return False                      # a -c string, standard input or a script
        i += 2 if a in _OPTIONS_WITH_VALUE else 1
    return False


def one_thread_for_commands() -> bool:
    """Set ``OPENBLAS_NUM_THREADS=1`` in the ``steerlab`` command's process (see the module
    docstring). Returns whether it was set."""
    if VARIABLE in os.environ or "numpy" in sys.modules or os.environ.get(ENV, "1") == "0":
        return False
    if not is_command_process(getattr(sys, "orig_argv", ()), sys.argv[0] if sys.argv else ""):
        return False
    os.environ[VARIABLE] = "1"
    return True
