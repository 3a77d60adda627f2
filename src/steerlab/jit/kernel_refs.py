"""Names for compiled kernels that a fresh Python process can turn back into the kernel.

The compiled drivers (:mod:`steerlab.jit.drivers`) are generated as small modules on disk so
that numba can cache their machine code across processes. Such a module must name the ship,
controller and guidance kernels it binds in a way that re-importing it finds the same
kernels. A *kernel reference* is that name, a plain tuple (``repr`` gives valid Python):

* ``("ref", "package.module:qualname")``: a kernel defined at module level (any importable
  module, steerlab's own or a user's plug-in package);
* ``("bound", "package.module:template", name, (("global", <ref>), ...))``: a kernel made
  from a template Python function whose module globals are rebound to other kernels (the
  wrapper pattern of ``+wf`` and ``+sensors``: ``_inner`` -> the wrapped controller). Make
  such kernels with :func:`bound_kernel`, which records their reference.

:func:`kernel_ref` returns ``None`` for kernels that cannot be named (defined in
``__main__``, in a notebook cell, or as closures); the drivers then compile them in the
process as before, without the disk cache.
"""

from __future__ import annotations

import importlib
import threading
import types
from typing import Callable, Optional

from steerlab.jit.numba_stamped import numba

_REFS: dict = {}          # id(kernel) -> (kernel, reference) for bound kernels
_BOUND: dict = {}         # (template, name, bindings) -> kernel
_LOCK = threading.Lock()


def _qualified(fn) -> Optional[str]:
    """``"module:qualname"`` of a module-level function, or None if it cannot be imported back."""
    module = getattr(fn, "__module__", None)
    qualname = getattr(fn, "__qualname__", "")
    if not module or module == "__main__" or "<locals>" in qualname or "<" in qualname:
        return None
    return f"{module}:{qualname}"


def _lookup(path: str):
    module, _, qualname = path.partition(":")
    obj = importlib.import_module(module)
    for part in qualname.split("."):
        obj = getattr(obj, part)
    return obj


def bound_kernel(template: Callable, name: str, **bindings) -> Callable:
    """``template`` (a plain Python function) compiled with some module globals rebound.

    ``bindings`` maps global names of ``template`` to kernels (e.g. ``_inner=pid_update``).
    Memoised: the same template, name and bindings give the same kernel object. The kernel
    remembers its reference, so a generated driver can rebuild it in another process.
    """
    key = (template, name, tuple(sorted(bindings.items(), key=lambda kv: kv[0])))
    with _LOCK:
        kernel = _BOUND.get(key)
        if kernel is not None:
            return kernel
        g = dict(template.__globals__)
        g.update(bindings)
        fn = types.FunctionType(template.__code__, g, name, template.__defaults__, template.__closure__)
        fn.__qualname__ = name
        fn.__doc__ = template.__doc__
        kernel = numba.njit(fn)
        tpl = _qualified(template)
        inner = tuple((k, kernel_ref(v)) for k, v in key[2])
        ref = None if tpl is None or any(r is None for _, r in inner) else ("bound", tpl, name, inner)
        _REFS[id(kernel)] = (kernel, ref)
        _BOUND[key] = kernel
        return kernel


def kernel_ref(kernel) -> Optional[tuple]:
    """The reference of ``kernel`` (module docstring), or None if it cannot be named."""
    if kernel is None:
        return None
    known = _REFS.get(id(kernel))
    if known is not None and known[0] is kernel:
        return known[1]
    path = _qualified(getattr(kernel, "py_func", kernel))
    if path is None:
        return None
    try:
        found = _lookup(path)
    except Exception:  # noqa: BLE001 - any import problem means: not nameable
        return None
    return ("ref", path) if found is kernel or _unpickled_copy(kernel, found) else None


def _unpickled_copy(kernel, found) -> bool:
    """Whether ``kernel`` is a copy of the module-level kernel ``found`` made by pickling.

    numba pickles a dispatcher by its function's code; another process (a ``spawn``
    multiprocessing child, a Dask worker) unpickles a *new* dispatcher of a rebuilt function
    instead of the module's own. It is the same kernel when the class, the code, the defaults and
    the compile options are equal and neither has a closure: then it is named like the module's
    kernel, so its driver comes from the disk cache instead of being compiled in every such
    process (the module's kernel runs: the same code)."""
    a, b = getattr(kernel, "py_func", None), getattr(found, "py_func", None)
    if a is None or b is None or type(kernel) is not type(found):
        return False
    return (a.__code__ == b.__code__ and a.__closure__ is None and b.__closure__ is None
            and a.__defaults__ == b.__defaults__ and kernel.targetoptions == found.targetoptions)


def resolve(ref: Optional[tuple]):
    """The kernel a reference names (the inverse of :func:`kernel_ref`); None for None."""
    if ref is None:
        return None
    kind = ref[0]
    if kind == "ref":
        return _lookup(ref[1])
    if kind == "bound":
        _, template, name, inner = ref
        return bound_kernel(_lookup(template), name, **{k: resolve(r) for k, r in inner})
    raise ValueError(f"unknown kernel reference {ref!r}")


def describe(ref: Optional[tuple]) -> str:
    """A short human name of a reference: ``esso_rhs``, ``pid_update+sensors`` ..."""
    if ref is None:
        return "-"
    if ref[0] == "ref":
        return ref[1].rpartition(":")[2]
    return ref[2]
