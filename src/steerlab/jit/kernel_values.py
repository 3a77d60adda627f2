"""The module-level values a user's kernel reads, digested into its cache key.

numba reads a compiled function's module globals once, when it compiles, and freezes them
into the machine code as constants: ``GAIN = float(os.environ["MY_GAIN"])`` or a value read
from a data file at import is part of the code, not of the source. The drivers' key
(:mod:`steerlab.jit.drivers`) was the kernels' names and source files only, so a plug-in whose
value came from a data file kept the first run's numbers after the file changed (iae 832.7
instead of 665.2; right with ``STEERLAB_DRIVER_CACHE=0``).

:func:`module_values_digest` follows the kernels of a driver - and the kernels they call,
through the module globals that hold them (a wrapper's ``_inner``) - and digests, for every
function defined outside steerlab, the values of the globals its code names (and of the
attributes its code names of a module it reads, ``cfg.GAIN``): numbers, strings, bytes,
``None``, numpy scalars and arrays (dtype, shape and bytes), and tuples of them. Functions,
classes and other objects are not data numba can freeze and are left out. steerlab's own
modules are covered by the package fingerprint.
"""

from __future__ import annotations

import hashlib
import types
from pathlib import Path

import numpy as np

from steerlab.jit.numba_cache import PACKAGE_ROOT

VALUES_LINE = "# module values read by the kernels (sha256 {digest})"
"""How a generated driver's text records :func:`module_values_digest` (when not empty)."""

_SCALARS = (bool, int, float, complex, str, bytes, type(None))


def _value_text(value, depth: int = 0):
    """Exact text of a freezable value, or None if it is no data numba freezes."""
    if isinstance(value, _SCALARS):
        return f"{type(value).__name__}:{value!r}"
    if isinstance(value, np.ndarray):
        arr = np.ascontiguousarray(value)
        return f"ndarray:{arr.dtype.str}:{arr.shape}:{hashlib.sha256(arr.tobytes()).hexdigest()}"
    if isinstance(value, np.generic):
        return f"{value.dtype.str}:{value.tobytes().hex()}"
    if isinstance(value, tuple) and depth < 8:
        parts = [_value_text(v, depth + 1) for v in value]
        return None if any(p is None for p in parts) else f"tuple({','.join(parts)})"
    return None


def _steerlab_module(module: types.ModuleType) -> bool:
    try:
        Path(getattr(module, "__file__", "") or "").resolve().relative_to(PACKAGE_ROOT)
        return True
    except (ValueError, OSError):
        return False


def _names(code: types.CodeType) -> set[str]:
    out = set(code.co_names)
    for const in code.co_consts:
        if isinstance(const, types.CodeType):
            out |= _names(const)
    return out


def module_values_digest(kernels) -> str:
    """SHA-256 (16 hex digits) of the module-level values the user code of ``kernels`` (numba
    dispatchers; None entries skipped) and the kernels they call read; ``""`` when they read
    none (steerlab's own kernels)."""
    lines: list[str] = []
    seen: set[int] = set()
    todo = [k for k in kernels if k is not None]
    while todo:
        kernel = todo.pop()
        fn = getattr(kernel, "py_func", kernel)
        if id(fn) in seen or not isinstance(fn, types.FunctionType):
            continue
        seen.add(id(fn))
        glob = fn.__globals__
        names = sorted(_names(fn.__code__))
        user = not str(fn.__module__ or "").startswith("steerlab.")
        for name in names:
            if name not in glob:
                continue
            value = glob[name]
            if hasattr(value, "py_func"):                    # a kernel it calls
                todo.append(value)
                continue
            if not user:
                continue
            if isinstance(value, types.ModuleType):
                if _steerlab_module(value):
                    continue
                for attr in names:
                    text = _value_text(getattr(value, attr, None)) if hasattr(value, attr) else None
                    if text is not None:
                        lines.append(f"{fn.__module__}:{name}.{attr}={text}")
                continue
            text = _value_text(value)
            if text is not None:
                lines.append(f"{fn.__module__}:{name}={text}")
    if not lines:
        return ""
    return hashlib.sha256("\n".join(sorted(set(lines))).encode()).hexdigest()[:16]
