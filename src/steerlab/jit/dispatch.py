"""What the rest of steerlab may ask about numba's compiled functions, without numba's internals.

numba's dispatcher class (``numba.core.registry.CPUDispatcher``), its target options
(``numba.core.cpu.CPUTargetOptions``) and its compile events (``numba.core.event``) live in
``numba.core``, which only :mod:`steerlab.jit` imports (``tests/test_layering.py``). The kernel
fusion (:mod:`steerlab.sim.kernels`), the pure-Python reference (:mod:`steerlab.bench`) and the
vectorisation reports (:mod:`steerlab.sim.vector_reports`) ask through these functions instead.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any


def is_dispatcher(obj: Any) -> bool:
    """Whether ``obj`` is a function compiled by ``numba.njit``/``numba.jit`` for the CPU (a
    numba dispatcher, with ``py_func`` the Python function it compiles). ``False`` for plain
    functions, and for everything under ``NUMBA_DISABLE_JIT=1``."""
    try:
        from numba.core.registry import CPUDispatcher
    except ImportError:  # pragma: no cover - depends on the numba version: what a dispatcher has
        return callable(obj) and hasattr(obj, "py_func") and hasattr(obj, "overloads")
    return isinstance(obj, CPUDispatcher)


def supported_options(options: Mapping[str, Any]) -> dict[str, Any]:
    """The entries of ``options`` (keyword arguments of ``numba.njit``) that this numba knows as
    CPU target options, checked without compiling anything; ``{}`` if numba no longer says, or
    on a numba version the tests do not cover (:mod:`steerlab.jit.numba_gate`: the options are
    numba internals, ``_nrt`` among them; the kernels then compile as plain ``njit``, with the
    same numbers)."""
    from steerlab.jit import numba_gate

    if not numba_gate.internals_allowed():
        return {}
    try:
        from numba.core.cpu import CPUTargetOptions
    except ImportError:  # pragma: no cover - depends on the numba version
        return {}
    return {k: v for k, v in options.items() if hasattr(CPUTargetOptions, k)}


def on_compiled(callback: Callable[[Any, tuple], None]) -> bool:
    """Call ``callback(dispatcher, argument_types)`` after each compile numba finishes in this
    process (numba's ``"numba:compile"`` event; not for code loaded from its cache). Returns
    whether the listener was registered (``False`` if this numba has no such event)."""
    try:
        from numba.core import event
    except ImportError:  # pragma: no cover - depends on the numba version
        return False

    class Listener(event.Listener):
        def on_start(self, ev) -> None:
            pass

        def on_end(self, ev) -> None:
            data = ev.data or {}
            callback(data.get("dispatcher"), data.get("args", ()))

    event.register("numba:compile", Listener())
    return True
