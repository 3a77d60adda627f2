"""steerlab's own cached kernels load without numba's compile-time registries.

Before numba loads a compiled function from its disk cache, ``Cache.load_overload`` calls
``target_context.refresh()``, which imports and installs numba's typing and lowering
registries (``numba.np.arraymath``, ``numba.np.random.*``, cffi's parser, ...) and, through
them, numba's BLAS probe, which imports ``scipy.linalg``: 0.4-0.7 s of CPU on the first load of
a process, the largest cost of a library user's first ``sl.simulate`` after the imports.
Loading machine code needs none of it: only the symbols that code links against. Those come from

* numba's helper library, C maths and exception objects (installed when the target context
  is created, before any load);
* the runtime (NRT: allocation, reference counting): ``rtsys.initialize``;
* ``numba.cpython.hashing`` (``_Py_HashSecret``, for hashed strings), added when that module is
  imported;
* third-party numba extensions (``numba.core.entrypoints.init_all``).

Only steerlab's own dispatchers load that way. numba's ``Cache`` class is not touched: while
numba makes the cache of a function in a steerlab file (a package kernel or a generated driver,
the files :class:`steerlab.jit.numba_cache.PackageStampLocator` claims), the locator calls
:func:`give_to_cache_being_made`, which finds that cache instance (the ``Cache.__init__`` that
asked the locator, a few frames up) and gives it, as an attribute of that one instance, a
``load_overload`` that prepares exactly the symbols above and then loads (:func:`give`). A
user's own ``@numba.njit(cache=True)`` functions, and any code that is not steerlab's, load as
numba loads them (``tests/test_import_side_effects.py``). Compiling is unchanged: numba's
compiler refreshes the context itself before every compilation, so a process that compiles
later (a user's function, a cache miss) gets the registries then. A light load that fails for
any reason is retried the numba way (full refresh).

It reaches numba internals (the shape of ``Cache.__init__`` and ``Cache._load_overload``,
written against numba 0.68), so it acts only on the numba versions the tests cover
(:mod:`steerlab.jit.numba_gate`); elsewhere, or if the names it needs are missing, steerlab's
kernels load the numba way. Set ``STEERLAB_LIGHT_CACHE_LOAD=0`` (before ``import steerlab``)
to switch it off.

Measured with ``python benchmarks/bench_startup_ab.py`` (2026-11-29, ``benchmarks/RESULTS.md``,
"Start-up after the light load of steerlab's own kernels"): a library user's first
``sl.simulate(sl.default_scenario())`` with a warm cache costs what the tree before the compile
boundary (``a91f3ce``) did, where it was 1.55x that tree's CPU without it.
"""

from __future__ import annotations

import os
import sys

ENV = "STEERLAB_LIGHT_CACHE_LOAD"
STATS = {"given": 0, "light": 0, "fallback": 0}
"""In this process: steerlab caches given the light load, loads done the light way, and loads
that fell back to numba's."""


def enabled() -> bool:
    """Whether steerlab's own caches get the light load in this process (module docstring)."""
    if os.environ.get(ENV, "1") == "0":
        return False
    from steerlab.jit import numba_gate

    return numba_gate.internals_allowed()


def _prepare(target_context) -> None:
    """What linking a cached library needs, without the registries (module docstring)."""
    from numba.core import entrypoints
    from numba.core.runtime import nrt
    import numba.cpython.hashing  # noqa: F401  (registers _Py_HashSecret with LLVM)

    nrt.rtsys.initialize(target_context)
    entrypoints.init_all()


def give(cache) -> bool:
    """Give one numba cache instance (a steerlab function's) the light load; returns whether it
    has it. The instance's own ``load_overload`` attribute shadows the class's method for that
    instance only; numba's class is unchanged."""
    if "load_overload" in vars(cache):
        return getattr(cache.load_overload, "_steerlab", False)
    numba_load = type(cache).load_overload
    try:
        load, guard = cache._load_overload, cache._guard_against_spurious_io_errors
    except AttributeError:  # pragma: no cover - depends on the numba version: numba's load
        return False

    def load_overload(sig, target_context):
        try:
            _prepare(target_context)
            with guard():
                data = load(sig, target_context)
            STATS["light"] += 1
            return data
        except Exception:  # noqa: BLE001 - anything unexpected: numba's own way
            STATS["fallback"] += 1
            return numba_load(cache, sig, target_context)

    load_overload._steerlab = True  # type: ignore[attr-defined]
    load_overload.__doc__ = numba_load.__doc__
    cache.load_overload = load_overload
    STATS["given"] += 1
    return True


def give_to_cache_being_made(py_func) -> bool:
    """Called by :class:`steerlab.jit.numba_cache.PackageStampLocator` when it claims
    ``py_func``'s file: give the light load to the cache numba is making for ``py_func`` (the
    ``self`` of the ``Cache.__init__`` frame that asked the locator, identified by its code
    object and its ``_py_func``). Returns whether it did; anything unexpected (another call
    shape, another numba) leaves that cache as numba made it."""
    if not enabled():
        return False
    try:
        from numba.core import caching

        init = caching.Cache.__init__.__code__
        frame = sys._getframe(1)
    except (ImportError, AttributeError, ValueError):  # pragma: no cover - another numba/Python
        return False
    for _ in range(6):                     # locator <- CacheImpl.__init__ <- Cache.__init__
        if frame is None:
            return False
        if frame.f_code is init:
            cache = frame.f_locals.get("self")
            if isinstance(cache, caching.Cache) and getattr(cache, "_py_func", None) is py_func:
                return give(cache)
            return False
        frame = frame.f_back
    return False
