"""The controllers steerlab knows, by name, discovered from the modules of :mod:`steerlab.control`.

A controller module declares itself with a module-level ``CONTROLLER = ControllerSpec(...)``
(or ``CONTROLLERS = [...]`` for several). Nothing else needs editing to add one: the scenario
schema, the CLI and the engines pick it up from here. Controllers outside the package:
:func:`register_controller`, the entry-point group ``steerlab.controllers`` or the
``STEERLAB_PLUGINS`` variable (:mod:`steerlab.plugins`); docs/adding-a-controller.md.

``config`` is a :class:`~steerlab.config_base.FrozenConfig` subclass with a field
``type: Literal["<name>"]`` (the discriminator of ``[controller]`` in a scenario) and
``build(cfg, ctx) -> (controller, params)`` turns a validated config and a
:class:`~steerlab.control.design_context.DesignContext` into an object with
``init_state(x0, ref0) -> z0`` and the packed float64 parameter record of the kernel
``update(z, p, t, x, ref, h) -> delta_cmd``. ``params`` (optional) is the
:class:`~steerlab.records.Layout` of that record: with it, the tuner and variation find a
field's slot by name (``Kp``, through wrappers ``inner.Kp``); without it a tuned field is
designed per candidate (``build``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable, Optional

from steerlab.plugins import PicklesByName, Registry


@dataclass(frozen=True)
class ControllerSpec(PicklesByName):
    name: str
    description: str
    update: Callable
    n_state: int
    config: type
    build: Callable
    source: str = ""
    params: Optional[object] = field(default=None, compare=False)   #: records.Layout of the record
    #: the rule the default gains come from, with its source (``steerlab design``,
    #: ``Controller.describe()``); empty for a law without a stated rule
    design_rule: str = field(default="", compare=False)
    #: ``(function, args)`` that made this spec from another one, e.g. ``(sensed_spec, (inner,))``:
    #: it pickles as that (:class:`steerlab.plugins.PicklesByName`)
    recipe: Optional[tuple] = field(default=None, compare=False, repr=False)


def _collect(module) -> list:
    """The controllers a module declares (``CONTROLLERS`` list and/or ``CONTROLLER``)."""
    specs = list(getattr(module, "CONTROLLERS", ()))
    if hasattr(module, "CONTROLLER"):
        specs.append(module.CONTROLLER)
    return specs


CONTROLLERS = Registry("controller", "steerlab.control", _collect, ControllerSpec, "controller.type",
                       "steerlab.controllers", skip={"registry", "design_context"},
                       derive="steerlab.control.wave_filtered:wave_filtered_variants")
"""Lazy read-only view ``name -> ControllerSpec`` (:class:`steerlab.plugins.Registry`). Every
controller also comes behind the wave filter, as ``"<name>+wf"``; the deriving function is named,
not imported: the registry imports it from its package when it first derives, as it imports the
package's controllers (the registry sits below the controllers it finds)."""


def _discover() -> dict:
    return CONTROLLERS._discover()


def get_controller(name: str) -> ControllerSpec:
    return CONTROLLERS.get_spec(name)


def register_controller(spec: ControllerSpec, replace: bool = False) -> ControllerSpec:
    """Make ``spec`` (and its ``"+wf"`` variant) known to scenarios, the CLI and the engines."""
    return CONTROLLERS.register(spec, replace)
