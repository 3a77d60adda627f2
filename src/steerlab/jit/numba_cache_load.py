"""Loading a cached kernel without numba's compile-time registries: about 0.1 s less per process.

Before numba loads a compiled function from its disk cache, ``Cache.load_overload`` calls
``target_context.refresh()``, which imports and installs numba's typing and lowering
registries (``numba.np.arraymath``, ``numba.cpython.unicode``, cffi's parser, ...): 0.1-0.2 s
of CPU, the largest cost of a warm ``steerlab run`` after the imports. Loading machine code
needs none of it: only the symbols that code links against. Those come from

* numba's helper library, C maths and exception objects (installed when the target context
  is created, before any load);
* the runtime (NRT: allocation, reference counting): ``rtsys.initialize``;
* ``numba.cpython.hashing`` (``_Py_HashSecret``, for hashed strings), added when that module is
  imported;
* third-party numba extensions (``numba.core.entrypoints.init_all``).

:func:`install` replaces ``load_overload`` by one that prepares exactly these and then loads.
Compiling is unchanged: numba's compiler refreshes the context itself before every
compilation, so a process that compiles later (a cache miss, a new kernel) gets the
registries then. A load that fails for any reason is retried the numba way (full refresh).

It patches a numba internal (``numba.core.caching.Cache``; written against numba 0.68), so it
is made by the ``steerlab`` command only (:mod:`steerlab.jit.command`), never at ``import
steerlab``, and only on the numba versions the tests cover (:mod:`steerlab.jit.numba_gate`);
if the names it needs are missing, :func:`install` changes nothing. Set
``STEERLAB_LIGHT_CACHE_LOAD=0`` to switch it off.

Measured with ``python benchmarks/bench_startup.py --switches`` (2026-11-28, the warm default
run with this setting switched off against all on, medians of 5 interleaved rounds, CPU of
the process tree; the machine was loaded, 1-minute load 17, so wall times were 5x the idle
ones and only CPU is quoted; ``benchmarks/RESULTS.md``): 1.88 s of CPU without it against 1.64 s
with it: 0.24 s.
"""

from __future__ import annotations

import os

ENV = "STEERLAB_LIGHT_CACHE_LOAD"
STATS = {"light": 0, "fallback": 0}
"""Loads done the light way, and loads that fell back to numba's (this process)."""


def _prepare(target_context) -> None:
    """What linking a cached library needs, without the registries (module docstring)."""
    from numba.core import entrypoints
    from numba.core.runtime import nrt
    import numba.cpython.hashing  # noqa: F401  (registers _Py_HashSecret with LLVM)

    nrt.rtsys.initialize(target_context)
    entrypoints.init_all()


def install() -> bool:
    """Replace numba's ``Cache.load_overload`` (idempotent); returns whether it is in place."""
    global INSTALLED
    if os.environ.get(ENV, "1") == "0":
        return False
    from steerlab.jit import numba_gate

    if not numba_gate.internals_allowed():
        return False
    try:
        from numba.core import caching

        cache = caching.Cache
        original = cache.load_overload
        load, guard = cache._load_overload, cache._guard_against_spurious_io_errors  # noqa: F841
    except (ImportError, AttributeError):  # pragma: no cover - depends on the numba version
        return False
    if getattr(original, "_steerlab", False):
        return True

    def load_overload(self, sig, target_context):
        try:
            _prepare(target_context)
            with self._guard_against_spurious_io_errors():
                data = self._load_overload(sig, target_context)
            STATS["light"] += 1
            return data
        except Exception:  # noqa: BLE001 - anything unexpected: numba's own way
            STATS["fallback"] += 1
            return original(self, sig, target_context)

    load_overload._steerlab = True  # type: ignore[attr-defined]
    load_overload.__doc__ = original.__doc__
    cache.load_overload = load_overload
    INSTALLED = True
    return True


INSTALLED = False
"""Whether :func:`install` replaced numba's load in this process (the ``steerlab`` command does,
unless ``STEERLAB_LIGHT_CACHE_LOAD=0``)."""
