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

Only steerlab's own dispatchers load that way, and the hook sits where their caches are made.
numba makes a dispatcher's cache in ``Dispatcher.enable_caching`` (``@numba.njit(cache=True)``)
as ``FunctionCache(py_func)``, the name ``FunctionCache`` looked up in ``numba.core.dispatcher``.
:func:`install` (called by :func:`steerlab.jit.numba_cache.install`, right after it puts steerlab's
cache locator in place) binds that name to :class:`StampedFunctionCache`, a ``FunctionCache``
subclass that makes numba's own ``FunctionCache`` and returns it: unchanged when its locator is
not steerlab's (a user's function, any code that is not steerlab's: the same object, of numba's
class, numba's load), and, when it is (a package kernel or a generated driver, the files
:class:`steerlab.jit.numba_cache.PackageStampLocator` claims), after giving that one instance a
``load_overload`` attribute that prepares exactly the symbols above and then loads
(:func:`give`). numba's classes (``Cache``, ``FunctionCache``) are not touched
(``tests/test_import_side_effects.py``, ``tests/test_numba_cache_load.py``), nor are
``numba.core.caching``'s names, ``@cfunc`` or ``@vectorize`` caches (numba's load). Compiling is
unchanged: numba's compiler refreshes the context itself before every compilation, so a process
that compiles later (a user's function, a cache miss) gets the registries then. A light load that
fails for any reason is retried the numba way (full refresh).

It reaches numba internals (``numba.core.dispatcher.FunctionCache``, a cache's ``_impl.locator``
and ``Cache._load_overload``, written against numba 0.67-0.68), so it is installed only on the
numba versions the tests cover (:mod:`steerlab.jit.numba_gate`); elsewhere, or if a name it
needs is missing, steerlab's kernels load the numba way (slower, the same numbers). Set
``STEERLAB_LIGHT_CACHE_LOAD=0`` (before ``import steerlab``) to switch it off.

Measured with ``python benchmarks/bench_startup_ab.py`` (2026-11-29, ``benchmarks/RESULTS.md``,
"Start-up after the light load of steerlab's own kernels"): a library user's first
``sl.simulate(sl.default_scenario())`` with a warm cache costs what the tree before the compile
boundary (``a91f3ce``) did, where it was 1.55x that tree's CPU without it.
"""

from __future__ import annotations

import os

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


def give_if_ours(cache) -> bool:
    """Give ``cache`` (a numba ``Cache`` numba has just made) the light load if its locator is
    steerlab's (:class:`steerlab.jit.numba_cache.PackageStampLocator`); returns whether it has it.
    Any other cache, or one of another shape, is left as numba made it."""
    impl = getattr(cache, "_impl", None)
    if not getattr(getattr(impl, "locator", None), "_steerlab", False):
        return False
    return give(cache)


StampedFunctionCache = None
"""The subclass of numba's ``FunctionCache`` that :func:`install` binds in
``numba.core.dispatcher`` (made there, on the ``FunctionCache`` of the numba in use)."""

INSTALLED = False
"""Whether steerlab's dispatchers get the light load in this process (:func:`install`)."""


def _make_stamped(function_cache):
    class _StampedFunctionCache(function_cache):
        __doc__ = ("numba's FunctionCache, made by numba; steerlab's own files' caches get the "
                   "light load (steerlab.jit.numba_cache_load).")
        _steerlab = True

        def __new__(cls, py_func, *args, **kwargs):
            cache = function_cache(py_func, *args, **kwargs)   # numba's own class and instance
            try:
                give_if_ours(cache)
            except Exception:  # noqa: BLE001 - anything unexpected: the cache as numba made it
                pass
            return cache       # not an instance of cls: Python does not call __init__ again

    _StampedFunctionCache.__name__ = _StampedFunctionCache.__qualname__ = "StampedFunctionCache"
    _StampedFunctionCache.__module__ = __name__
    return _StampedFunctionCache


def install() -> bool:
    """Make numba give the caches of steerlab's own dispatchers the light load as it makes them
    (module docstring); idempotent. Called by :func:`steerlab.jit.numba_cache.install` once its
    locator is in place, so before any steerlab kernel is defined. Returns whether it is
    installed: ``False`` when switched off (``STEERLAB_LIGHT_CACHE_LOAD=0``), outside the tested
    numba versions, or if numba no longer makes caches the way described (numba's load then)."""
    global StampedFunctionCache, INSTALLED
    if not enabled():
        return False
    try:
        from numba.core import caching, dispatcher

        current = dispatcher.FunctionCache
        caching.Cache._load_overload  # noqa: B018 - the names the light load needs
        caching.Cache._guard_against_spurious_io_errors  # noqa: B018
    except (ImportError, AttributeError):  # pragma: no cover - depends on the numba version
        return False
    if getattr(current, "_steerlab", False):
        INSTALLED = True
        return True
    if current is not caching.FunctionCache:  # pragma: no cover - someone else's: leave it
        return False
    StampedFunctionCache = _make_stamped(current)
    dispatcher.FunctionCache = StampedFunctionCache
    INSTALLED = True
    return True
