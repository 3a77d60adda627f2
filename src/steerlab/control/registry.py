"""The controllers steerlab knows, by name, discovered from the modules of :mod:`steerlab.control`.

A controller module declares itself with a module-level ``CONTROLLER = ControllerSpec(...)``
(or ``CONTROLLERS = [...]`` for several). Nothing else needs editing to add one: the scenario
schema, the CLI and the engines pick it up from here.

``config`` is a :class:`~steerlab.config_base.FrozenConfig` subclass with a field
``type: Literal["<name>"]`` (the discriminator of ``[controller]`` in a scenario) and
``build(cfg, ctx) -> (controller, params)`` turns a validated config and a
:class:`~steerlab.control.design_context.DesignContext` into an object with
``init_state(x0, ref0) -> z0`` and the packed float64 parameter record of the kernel
``update(z, p, t, x, ref, h) -> delta_cmd``.
"""

from __future__ import annotations

import importlib
import pkgutil
from dataclasses import dataclass
from functools import lru_cache
from typing import Callable

from steerlab.errors import InputError


@dataclass(frozen=True)
class ControllerSpec:
    name: str
    description: str
    update: Callable
    n_state: int
    config: type
    build: Callable
    source: str = ""


_SKIP = {"registry", "design_context", "__init__"}


@lru_cache(maxsize=None)
def _discover() -> dict:
    import steerlab.control as pkg

    found = {}
    for mod in sorted(pkgutil.iter_modules(pkg.__path__), key=lambda m: m.name):
        if mod.name in _SKIP or mod.name.startswith("_"):
            continue
        module = importlib.import_module(f"steerlab.control.{mod.name}")
        specs = list(getattr(module, "CONTROLLERS", ()))
        if hasattr(module, "CONTROLLER"):
            specs.append(module.CONTROLLER)
        for spec in specs:
            if spec.name in found:
                raise RuntimeError(f"controller {spec.name!r} declared twice")
            found[spec.name] = spec
    return found


class _Registry(dict):
    """Lazy, read-only view of the discovered controllers (name -> ControllerSpec)."""

    def _d(self):
        return _discover()

    def __getitem__(self, k):
        return self._d()[k]

    def __contains__(self, k):
        return k in self._d()

    def __iter__(self):
        return iter(self._d())

    def __len__(self):
        return len(self._d())

    def keys(self):
        return self._d().keys()

    def items(self):
        return self._d().items()

    def values(self):
        return self._d().values()

    def get(self, k, default=None):
        return self._d().get(k, default)


CONTROLLERS = _Registry()


def get_controller(name: str) -> ControllerSpec:
    try:
        return _discover()[name]
    except KeyError:
        raise InputError("controller.type",
                         f"unknown controller {name!r}; known controllers: {sorted(_discover())}") from None
