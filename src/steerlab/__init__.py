"""steerlab: design, tune, assess and run ship autopilots.

Conventions (everywhere inside the library)
-------------------------------------------
* SI units and radians inside; degrees and knots only at the edges (CLI, TOML, plots).
* Heading ``psi`` clockwise from north, yaw rate ``r > 0`` turning to starboard,
  rudder angle ``delta > 0`` turns the ship to starboard.
* Every heading error goes through :func:`steerlab.angles.wrap_to_pi`.

The public API (``import steerlab as sl``) is loaded lazily: ``import steerlab`` imports
neither numpy nor numba and changes nothing outside steerlab; ``sl.simulate`` and friends
import their module on first use (PEP 562 module ``__getattr__``), so a command pays only for
what it uses (``steerlab --help`` starts without numba). The first module with a numba kernel
puts the package stamp of steerlab's cached kernels in place (:mod:`steerlab.jit.numba_stamped`).
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

__version__ = "0.1.0"

# Nothing here changes anything outside steerlab (tests/test_import_side_effects.py). One
# setting must come first: in the steerlab command's own process only, numpy's OpenBLAS on one
# thread, which works only before numpy is imported (blas_threads: a no-op in a user's program).
# The package stamp of steerlab's cached kernels is put in place by the first module that
# defines a kernel (steerlab.jit.numba_stamped); the command's other process-wide settings are
# asked for by its entry point (steerlab.jit.command, from steerlab.cli.console_main).
from steerlab.jit import blas_threads  # noqa: E402  (isort: skip)

blas_threads.one_thread_for_commands()
from steerlab.errors import InputError  # noqa: F401

_LAZY = {
    # name: "module:attribute" (one line each; keep sorted within a block)
    "default_scenario": "steerlab.sim.scenario:default_scenario",
    "load_scenario": "steerlab.sim.scenario:load_scenario",
    "register_controller": "steerlab.control.registry:register_controller",
    "register_ship": "steerlab.ships.registry:register_ship",
    "simulate": "steerlab.sim.engine:simulate",
    "simulate_batch": "steerlab.sim.batch:simulate_batch",
    "vary": "steerlab.sim.vary:vary",
    "wrap_to_pi": "steerlab.angles:wrap_to_pi",
    # components for other people's loops (steerlab.components)
    "controller": "steerlab.components.controller:controller",
    "controllers": "steerlab.components.controller:controllers",
    "linearize": "steerlab.components.linear:linearize",
    "ship": "steerlab.components.ship:ship",
    "transfer_function": "steerlab.components.linear:transfer_function",
}


if TYPE_CHECKING:   # what type checkers see of the lazy names above (keep in step with _LAZY)
    from steerlab.components.controller import controller as controller
    from steerlab.components.controller import controllers as controllers
    from steerlab.components.linear import linearize as linearize
    from steerlab.components.linear import transfer_function as transfer_function
    from steerlab.angles import wrap_to_pi as wrap_to_pi
    from steerlab.components.ship import ship as ship
    from steerlab.control.registry import register_controller as register_controller
    from steerlab.ships.registry import register_ship as register_ship
    from steerlab.sim.batch import simulate_batch as simulate_batch
    from steerlab.sim.engine import simulate as simulate
    from steerlab.sim.scenario import default_scenario as default_scenario
    from steerlab.sim.scenario import load_scenario as load_scenario
    from steerlab.sim.vary import vary as vary


def __getattr__(name: str) -> Any:
    target = _LAZY.get(name)
    if target is None:
        raise AttributeError(f"module 'steerlab' has no attribute {name!r}")
    module, _, attr = target.partition(":")
    value = getattr(importlib.import_module(module), attr)
    globals()[name] = value
    return value


_NOT_API = {"Any", "TYPE_CHECKING", "annotations", "importlib"}
"""Names this module needs but does not offer (left out of ``dir(steerlab)``, i.e. tab completion)."""


def __dir__() -> list[str]:
    return sorted((set(globals()) | set(_LAZY)) - _NOT_API)


__all__ = ["InputError", *_LAZY]
