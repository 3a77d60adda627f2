"""A controller's kernel as Python calls it: directly, or through a cached driver entry.

The engines' drivers fuse a controller's kernel into their loops; Python code that steps a
controller itself (:class:`~steerlab.components.controller.Controller`, the runtime's
autopilot, the readable engine, :class:`~steerlab.components.controller_vector.ControllerVector`)
calls the kernel's dispatcher. A registered law is compiled with numba's disk cache and loads
in a fresh process; a law wrapped at run time (``"pid+wf"``, a controller behind ``[sensors]``:
:func:`steerlab.jit.kernel_refs.bound_kernel`) has no disk cache of its own and compiled again in
every process (0.6-1.9 s before the first order). :func:`controller_step` returns, for such a
kernel, the ``step`` entry of :mod:`steerlab.jit.controller_step_template` bound to it,
which a fresh process loads from the driver cache; any other kernel is returned as it is.
"""

from __future__ import annotations

import types
from pathlib import Path
from typing import Callable

TEMPLATE = Path(__file__).with_name("controller_step_template.py")


def _module(update: Callable[..., float]) -> types.ModuleType:
    from steerlab.jit import drivers

    return drivers.driver(None, update, None, template=TEMPLATE)


def _disk_cached(kernel) -> bool:
    """Whether numba keeps ``kernel``'s own machine code on disk (``cache=True``)."""
    cache = getattr(kernel, "_cache", None)
    return cache is not None and type(cache).__name__ != "NullCache"


def controller_step(update: Callable[..., float]) -> Callable[..., float]:
    """``step(z, p, t, x, ref, h) -> order``: ``update`` itself when it has a disk cache of its
    own or cannot be named, else the cached driver entry that calls it (the same order, bit
    for bit)."""
    if _disk_cached(update):
        return update
    mod = _module(update)
    if not mod._steerlab_cached:
        return update                         # built in memory: the kernel itself compiles as fast
    from steerlab.jit import drivers

    return drivers.entry(mod, "step")


def vector_step(update: Callable[..., float]) -> Callable[..., None]:
    """``vector_step(Z, P, t, X, R, h, out)``: ``out[i] = update(Z[i], P[i], t, X[i], R[i], h)``
    for each i, from the driver cache (a fresh process loads it; a kernel that cannot be named
    gets it built in memory: :func:`steerlab.jit.drivers.driver`)."""
    from steerlab.jit import drivers

    return drivers.entry(_module(update), "vector_step")
