"""numba's threading layer for steerlab's ``parallel=True`` entry points: a fork-safe one.

The native Gymnasium vector environment spreads a step (and a reset) of many ships over the
cores with numba's ``prange`` (``step_parallel`` and ``reset_parallel`` of
:mod:`steerlab.jit.env_template`), which runs on numba's *threading layer*: one per process,
chosen by numba when its threads are first started (the first ``parallel=True`` call or the
first ``numba.get_num_threads()``), from ``numba.config.THREADING_LAYER`` (the
``NUMBA_THREADING_LAYER`` environment variable, default ``"default"``: TBB if it can be
loaded, else OpenMP, else workqueue).

On Linux numba's OpenMP layer is GNU OpenMP, which is **not fork-safe**: a process forked
after a parallel call aborts at its own first parallel call ("fork() called from a process
already using GNU OpenMP"); steerlab forks (the figure worker, multiprocessing, Dask
workers), and so do RL libraries' subprocess vector envs. It also busy-waits: with the cores
held by other programs, a 1024-ship step took 8 ms instead of 0.3 ms on the 2-core
development VM. So :func:`prefer_fork_safe` (called by the ``steerlab`` command) asks numba for
its ``"forksafe"`` layer - **TBB** when it can be loaded, else **workqueue** (numba's own
pthreads pool, always there) - **unless the user chose**: ``NUMBA_THREADING_LAYER`` set, or
``numba.config.THREADING_LAYER`` changed before the command starts, or numba's threads
already started; then steerlab runs on that layer (an explicit ``omp`` is the user's choice,
fork-unsafe). It only sets ``numba.config.THREADING_LAYER``, so it would apply to any other
``parallel=True`` code of the process too: the ``steerlab`` command makes this choice
(:mod:`steerlab.jit.command`), ``import steerlab`` does not (a user's program keeps numba's
``"default"``: TBB where it loads, which :func:`num_threads` helps it find, else OpenMP; choose
``NUMBA_THREADING_LAYER=forksafe`` to fork after steerlab's parallel calls on a machine without
TBB). numba starts its threads later, on first use (13-20 ms, not paid by commands that never
use them).

steerlab starts them through :func:`num_threads` (the vector environment's and the batch
engine's thread counts), which first loads pip's TBB where numba would not find it
(:func:`preload_pip_tbb`): the ``tbb`` wheel (in the ``rl`` extra, Linux x86-64) installs
``libtbb.so.12`` in ``sys.prefix/lib``, on the library path of some Pythons (pyenv's) but not
of a virtual environment's. TBB is fork-safe and thread-safe, and the faster of the two by far
(``benchmarks/README.md``): on workqueue a threaded step is slower than one call, so there
the vector environment steps on one thread (:func:`threads_pay`).

workqueue is fork-safe but not thread-safe: two threads launching parallel calls at once
make it abort the process. numba releases the GIL around a parallel call, so the GIL does
not prevent that; steerlab's parallel calls are made under :data:`LAUNCH`, one process-wide
lock (:func:`launch`), so environments stepped from several Python threads take turns
(another library's concurrent ``parallel=True`` calls on workqueue are not covered: choose
``NUMBA_THREADING_LAYER=tbb`` for those).
"""

from __future__ import annotations

import os
import sys
import threading
from typing import Optional

FORK_SAFE = "forksafe"
"""The value :func:`prefer_fork_safe` gives ``numba.config.THREADING_LAYER`` (numba's name for
"TBB if it loads, else workqueue" on Linux)."""

LAUNCH = threading.Lock()
"""Held during each of steerlab's parallel calls (see the module docstring)."""


def prefer_fork_safe() -> bool:
    """Ask numba for its fork-safe threading layer unless the user chose one (module docstring);
    returns whether it did. The ``steerlab`` command's setting (:mod:`steerlab.jit.command`):
    ``import steerlab`` leaves numba's choice to the user's program."""
    import numba

    if "NUMBA_THREADING_LAYER" in os.environ or _threads_started():
        return False
    if str(numba.config.THREADING_LAYER).lower() != "default":
        return False
    numba.config.THREADING_LAYER = FORK_SAFE
    return True


def _threads_started() -> bool:
    """Whether numba's threads have started in this process (numba's internal flag, on the
    tested numba versions: :mod:`steerlab.jit.numba_gate`; else steerlab's own record)."""
    from steerlab.jit import numba_gate

    if not numba_gate.internals_allowed():
        return _started
    from numba.np.ufunc import parallel

    return bool(getattr(parallel, "_is_initialized", False))


_started = False


def num_threads() -> int:
    """``numba.get_num_threads()``, numba's threads started first (once) after pip's TBB is
    loaded where a layer that may pick TBB is asked for (:func:`preload_pip_tbb`)."""
    import numba

    global _started
    if not _started:
        if not _threads_started() and str(numba.config.THREADING_LAYER).lower() in (
                "forksafe", "tbb", "safe", "threadsafe", "default"):
            preload_pip_tbb()
        _started = True
    return numba.get_num_threads()


PAYING = ("tbb", "omp")
"""numba's threading layers on which a threaded step of the vector environment pays (see
:func:`threads_pay`)."""


def threads_pay() -> bool:
    """Whether numba's threading layer (started by :func:`num_threads`) runs a short parallel
    call faster than one thread: TBB and OpenMP do; workqueue, which wakes its sleeping
    threads at every call and leaves the calling thread waiting, does not (a threaded step of
    1024 ships took 330-390 us against 290 us in one call on the 2-core development VM with a
    core free; TBB 155-160 us). OpenMP counts only where it was chosen (``NUMBA_THREADING_LAYER``
    or ``numba.config.THREADING_LAYER`` = ``"omp"``), not where numba's ``"default"`` fell back
    to it in a user's program (fork-unsafe). On a numba outside the tested versions none does
    (:mod:`steerlab.jit.numba_gate`: the threaded step calls by address). The vector environment stays on one thread where it does not
    (:meth:`steerlab.gym.episodes.Episodes._threads`, at every step: the answer is kept, a
    started layer does not change)."""
    global _pays
    if _pays is None:
        import numba

        num_threads()
        from steerlab.jit import numba_gate

        # the threaded step calls the one-call step by address, in numba's calling convention
        # (steerlab.jit.numba_call_at): on the tested numba versions only
        layer = numba.threading_layer()
        # GNU OpenMP is fork-unsafe: steerlab threads on it only where someone chose it (numba's
        # "default" picks it when TBB is missing, and a user's program may fork afterwards)
        chosen = layer != "omp" or str(numba.config.THREADING_LAYER).lower() == "omp"
        _pays = layer in PAYING and chosen and numba_gate.internals_allowed()
    return _pays


_pays: Optional[bool] = None


def tbb_library() -> Optional[str]:
    """The path of ``libtbb.so.12`` of the installed ``tbb`` distribution (pip's wheel), or None
    (not installed, not Linux)."""
    from importlib import metadata

    if not sys.platform.startswith("linux"):
        return None
    try:
        files = metadata.files("tbb") or ()
    except metadata.PackageNotFoundError:
        return None
    for f in files:
        if f.name == "libtbb.so.12":
            path = os.path.realpath(str(f.locate()))
            return path if os.path.exists(path) else None
    return None


def preload_pip_tbb() -> bool:
    """Load pip's ``libtbb.so.12`` (:func:`tbb_library`) into the process (``RTLD_GLOBAL``), so
    that numba's TBB layer, which asks the loader for that name, finds it; returns whether it
    was loaded. Harmless when it is on the library path already."""
    import ctypes

    path = tbb_library()
    if path is None:
        return False
    try:
        ctypes.CDLL(path, mode=ctypes.RTLD_GLOBAL)
    except OSError:
        return False
    return True


def launch(call, *args):
    """``call(*args)`` under :data:`LAUNCH` (a compiled ``parallel=True`` entry point)."""
    with LAUNCH:
        return call(*args)


def _new_lock_in_child() -> None:
    """A forked child gets a free lock (the parent's may have been held by another thread)."""
    global LAUNCH
    LAUNCH = threading.Lock()


os.register_at_fork(after_in_child=_new_lock_in_child)
