"""The ships steerlab knows, by name: the modules of :mod:`steerlab.ships`, plug-ins and the user's.

A module declares ships with a module-level ``SHIP_SPECS`` (a list of :class:`ShipSpec`, or a
function returning one, e.g. built from data files). Nothing else needs editing to add a
ship: scenarios, the CLI, the engines and the trials pick it up from here. Ships outside the
package: :func:`register_ship`, the entry-point group ``steerlab.ships`` or the
``STEERLAB_PLUGINS`` variable (:mod:`steerlab.plugins`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any, Callable, Mapping, Optional

from pydantic import ValidationError

from steerlab.errors import InputError
from steerlab.plugins import PicklesByName, Registry
from steerlab.ships.b2_estimate import b2_estimate
from steerlab.units import knots_to_ms

#: speed [kn] of a ship whose source states none and whose model has no finite validity
#: range (the Esso tanker's service speed, Zwierzewicz et al. 2021, Table 1)
DEFAULT_SPEED_KN = 16.0

if TYPE_CHECKING:
    from steerlab.config_base import FrozenConfig
    from steerlab.steering_gear import SteeringGear


@dataclass(frozen=True)
class ShipSpec(PicklesByName):
    """A ship model as the engine sees it.

    * ``rhs(t, x, delta, w, p, dx)``: numba kernel writing the derivatives of the ship states
      (``x`` is the whole plant state, the rudder angle last; the ship writes ``dx[:n_states]``).
    * ``pack(speed [m/s], rpm [rev/min] or None, options) -> params``; ``options`` is an
      instance of ``options_model`` (a :class:`~steerlab.config_base.FrozenConfig`) validated
      from the scenario's ``[ship.options]``, or ``None`` when the ship has no options.
    * ``b2_exact(speed)`` and ``dims`` (c_B, L [m], B [m]) feed the ADRC design (``c0``),
      steerlab sign; ``linearise(speed) -> (A1, B1)`` is the sway-yaw linear model on
      ``[v, r]``, steerlab sign; ``nomoto_KT(speed) -> (K [1/s], T [s])`` a first-order
      Nomoto model (default: from ``linearise``). Ships with an ``options_model`` take the
      validated options as a second argument: ``b2_exact(speed, options)``,
      ``nomoto_KT(speed, options)`` (``options`` may be ``None``: the defaults).
    * ``service_speed`` [m/s]: the speed its source states (a service or design speed, the
      speed of the captive tests); :attr:`design_speed` is the speed a scenario without
      ``speed_kn`` and a design without a speed use.
    * ``model_scale``: ``lambda = L_full / L_model`` of a scale model (None: a full-size ship);
      its :meth:`default_gear` is the Froude-scaled one, which a scenario without those
      ``[gear]`` keys gets (``docs/ships.md``, "Model-scale ships").
    """

    name: str
    description: str
    rhs: Callable
    n_states: int
    state_names: tuple
    state_units: tuple
    pack: Callable
    b2_exact: Callable
    dims: tuple
    source: str
    linearise: Callable | None = None
    options_model: type[FrozenConfig] | None = None
    nomoto_KT: Callable | None = None
    speed_range: tuple = (0.0, float("inf"))   #: validity range of the model [m/s]
    #: the speed the ship's source states [m/s] (None: none stated; :attr:`design_speed`)
    service_speed: float | None = None
    #: ``(speed, options) -> delta0 [rad]`` holding a straight course (None: 0, a symmetric hull)
    equilibrium_rudder: Callable | None = None
    #: ``(speed, options) -> bool``: whether delta -> -delta mirrors the response (None: True)
    symmetric: Callable | None = None
    #: ``options -> kernel``: a kernel suited to these validated options (None: always ``rhs``);
    #: it must give the same derivatives as ``rhs`` for every record ``pack`` makes with them
    kernel_for_options: Callable | None = None
    #: ``lambda = L_full / L_model`` of a scale model, None for a full-size ship
    model_scale: float | None = None
    #: how the spectrum wave model's ``channel = "auto"`` reaches this ship: ``"through-hull"``
    #: (a yaw moment in the ship's equations of motion) or ``"superposed"`` (the wave-frequency
    #: yaw rate, the linear first-order response of that moment, added to the rate of turn,
    #: ``psi' = r + r_w``: for a manoeuvring model whose nonlinear spiral terms are fitted to
    #: steady turns and are not wave-frequency physics; :mod:`steerlab.environment.sea`)
    wave_motion: str = "through-hull"
    #: the layout of the record ``pack`` makes (:class:`steerlab.records.Layout`: each field's
    #: name, unit and meaning); ``steerlab ships show`` prints the record at the design speed
    params: Any = field(default=None, compare=False, repr=False)
    #: ``(function, args)`` that made this spec from another one (:meth:`for_options`): it
    #: pickles as that (:class:`steerlab.plugins.PicklesByName`)
    recipe: tuple | None = field(default=None, compare=False, repr=False)

    def for_options(self, options: Any) -> "ShipSpec":
        """This spec with the kernel :attr:`kernel_for_options` picks for ``options`` (e.g. the
        MMG kernel without the rpm-schedule look-up, which vectorises, when there is no schedule)."""
        if self.kernel_for_options is None:
            return self
        rhs = self.kernel_for_options(options)
        return self if rhs is self.rhs else replace(self, rhs=rhs, recipe=(ShipSpec.for_options, (self, options)))

    @property
    def design_speed(self) -> float:
        """The ship's design speed [m/s]: the speed a scenario without ``speed_kn`` runs at.

        The rule (docs/ships.md, "Design speed"):

        1. the speed the source states (:attr:`service_speed`: the Esso tanker's and MSS
           tanker's 16 kn service speed, KVLCC2's 15.5 kn, the L7 model's 1.179 m/s, Kosoko's
           0.5 m/s design point, ...);
        2. else the middle of a finite validity range :attr:`speed_range` (a ship identified
           at several speeds: the middle one; at one speed: that speed);
        3. else 16 kn (8.2311 m/s), the Esso tanker's service speed (Zwierzewicz et al. 2021,
           Table 1) and the scenario default up to 0.1.0.
        """
        if self.service_speed is not None:
            return float(self.service_speed)
        lo, hi = self.speed_range
        if math.isfinite(hi) and hi > 0.0:
            return 0.5 * (lo + hi)
        return knots_to_ms(DEFAULT_SPEED_KN)

    def default_gear(self) -> "SteeringGear":
        """The steering gear a scenario gets when its ``[gear]`` table leaves a key out.

        A full-size ship: Zwierzewicz et al. (2021) eq (15), 35 deg, 2.33 deg/s, servo lag 1 s
        (:class:`steerlab.steering_gear.SteeringGear`). A scale model (:attr:`model_scale`):
        that gear Froude-scaled (:func:`steerlab.steering_gear.froude_scaled`: rate times
        ``sqrt(lambda)``, lag divided by it, angle kept).
        """
        from steerlab.steering_gear import SteeringGear, froude_scaled

        g = SteeringGear()
        return g if self.model_scale is None else froude_scaled(g, self.model_scale)

    def b2(self, speed: float, method: str, options: Optional[FrozenConfig] = None) -> float:
        """Rudder efficiency [1/s^2], steerlab sign: ``exact`` (linearisation) or ``estimate`` (eq 29).

        ``options``: the validated ``[ship.options]`` (passed on to ``b2_exact`` when the ship
        has an ``options_model``).
        """
        if method == "exact":
            return self.b2_exact(speed, options) if self.options_model is not None else self.b2_exact(speed)
        if method == "estimate":
            c_B, L, B = self.dims
            return b2_estimate(c_B, L, B, speed)
        raise InputError("controller.c0", f"must be a number, 'estimate' or 'exact', got {method!r}")

    def nomoto(self, speed: float, options: Optional[FrozenConfig] = None) -> tuple[float, float]:
        """First-order Nomoto ``(K [1/s], T [s])`` at ``speed`` [m/s] (``options`` as in :meth:`b2`)."""
        if self.nomoto_KT is not None:
            return self.nomoto_KT(speed, options) if self.options_model is not None else self.nomoto_KT(speed)
        if self.linearise is None:
            raise InputError("ship.model", f"ship {self.name!r} has neither a Nomoto model nor a linearisation")
        from steerlab.ships.linear_analysis import nomoto_from_linear

        n = nomoto_from_linear(*self.linearise(speed))
        return n["K"], n["T"]

    def options(self, raw: Mapping[str, Any] | None) -> Optional[FrozenConfig]:
        """Validate ``[ship.options]`` against ``options_model`` (errors name ``ship.options.X``)."""
        raw = dict(raw or {})
        if self.options_model is None:
            if raw:
                raise InputError("ship.options", f"ship {self.name!r} takes no options, got {sorted(raw)}")
            return None
        try:
            return self.options_model.model_validate(raw)
        except ValidationError as err:
            first = err.errors()[0]
            loc = ".".join(str(p) for p in first["loc"])
            ctx = first.get("ctx") or {}
            bounds = [f"{k.replace('_', ' ')} {v}" for k, v in ctx.items() if k in ("gt", "ge", "lt", "le")]
            msg = first["msg"] + (f" (allowed: {', '.join(bounds)})" if bounds else "")
            raise InputError(f"ship.options.{loc}" if loc else "ship.options", msg) from None


def _collect(module) -> list:
    """The ships a module declares (``SHIP_SPECS``: a list, or a function returning one)."""
    specs = getattr(module, "SHIP_SPECS", ())
    return list(specs() if callable(specs) else specs)


SHIPS = Registry("ship", "steerlab.ships", _collect, ShipSpec, "ship.model", "steerlab.ships",
                 skip={"registry"}, recursive=True)
"""Lazy read-only view ``name -> ShipSpec`` (:class:`steerlab.plugins.Registry`)."""


def _discover() -> dict:
    return SHIPS._discover()


def get_ship(name: str) -> ShipSpec:
    return SHIPS.get_spec(name)


def register_ship(spec: ShipSpec, replace: bool = False) -> ShipSpec:
    """Make ``spec`` known by its name to scenarios, the CLI and the engines (``replace``: override)."""
    return SHIPS.register(spec, replace)
