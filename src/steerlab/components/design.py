r"""The design context of a controller built outside a scenario.

A controller's design rule (``ControllerSpec.build(cfg, ctx)``) reads the loop it is built for
from a :class:`~steerlab.control.design_context.DesignContext`. Outside a scenario that
context is made here from one of:

* ``ship=ID, speed_kn=U`` - a catalogue ship (``steerlab ships``) at its approach speed (default:
  the ship's design speed);
* ``nomoto=(K, T)`` - a first-order Nomoto model alone (``T r' + r = K delta``, Nomoto 1957),
  carried by the context itself (:class:`NomotoModel`): K [1/s] and T [s] of either sign but
  the same one (``T < 0``, ``K < 0``: a course-unstable ship; ``K/T > 0`` always: a starboard
  rudder starts a starboard turn), and ``length_m`` (default 100 m) for laws written in
  non-dimensional form. The rudder efficiency is ``b2 = K / T`` [1/s^2] (exact for that
  model) unless ``b2=`` is given;
* neither - only laws that need no model (fixed-gain PID, classic autopilot, ...) can be
  designed; a law that needs one raises :class:`~steerlab.errors.InputError` naming ``nomoto``.

A speed that is not given is NaN; a design that needs it then has non-finite parameters and
:func:`steerlab.components.controller.controller` asks for ``speed_kn``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Mapping, NoReturn, Optional, Union

from steerlab.control.design_context import DesignContext
from steerlab.errors import InputError, require_finite_range
from steerlab.ships.registry import get_ship
from steerlab.ships.state import PLANAR_NAMES, PLANAR_UNITS
from steerlab.steering_gear import SteeringGear
from steerlab.units import knots_to_ms


@dataclass(frozen=True)
class GivenB2Context(DesignContext):
    """A design context whose ``b2`` [1/s^2] is given (or ``K / T`` of a Nomoto-only design)."""

    b2_value: float = math.nan

    def b2(self, method: str) -> float:
        return self.b2_value


class NoModel:
    """The "ship" of a design without a model: any question about the ship names ``nomoto``."""

    name = "none"
    n_states = 6
    state_names = PLANAR_NAMES
    state_units = PLANAR_UNITS
    options_model = None

    @staticmethod
    def _need(what: str) -> NoReturn:
        raise InputError("nomoto", f"this design needs the ship's {what}: give nomoto=(K [1/s], T [s]) "
                                   "(plus b2=... [1/s^2] if it differs from K/T), or ship=ID, speed_kn=...")

    @property
    def dims(self) -> NoReturn:
        self._need("length (dims)")

    def nomoto(self, speed: float, options: object = None) -> NoReturn:
        self._need("Nomoto K, T")

    def b2(self, speed: float, method: str, options: object = None) -> NoReturn:
        self._need("rudder efficiency b2")


@dataclass(frozen=True)
class NomotoModel:
    """The "ship" of a design from a first-order Nomoto model alone (``nomoto=(K, T)``).

    It answers what a design rule may ask of a ship: ``nomoto()`` gives ``(K [1/s], T [s])``
    with their signs, ``b2()`` the rudder efficiency [1/s^2] (``K/T`` unless given), ``dims``
    the (draught, length, beam) [m] of the ``nomoto1`` ship of that length. Its plant state has
    the planar layout of ``nomoto1`` (``x_n, y_e, psi, u, v, r``). Unlike ``nomoto1``'s
    ``[ship.options]`` (``K > 0``) it takes a course-unstable model (``K < 0``, ``T < 0``).
    """

    K: float
    T: float
    L: float = 100.0
    b2_value: float = math.nan

    name = "nomoto"
    n_states = len(PLANAR_NAMES)
    state_names = PLANAR_NAMES
    state_units = PLANAR_UNITS
    options_model = None
    source = "nomoto=(K, T)"

    @classmethod
    def checked(cls, nomoto: Any, length_m: Optional[float], b2: Optional[float]) -> "NomotoModel":
        """The model of ``nomoto=(K, T)``, or :class:`InputError` naming ``nomoto``/``length_m``."""
        try:
            K, T = (float(v) for v in nomoto)
        except (TypeError, ValueError):
            raise InputError("nomoto", f"must be a pair (K [1/s], T [s]), got {nomoto!r}") from None
        if not (math.isfinite(K) and math.isfinite(T)) or K == 0.0 or abs(T) < 1e-6 or abs(K) > 100.0 \
                or abs(T) > 1e5:
            raise InputError("nomoto", f"needs finite K with 0 < |K| <= 100 [1/s] and T with 1e-6 <= |T| <= 1e5 [s], "
                                       f"got ({K!r}, {T!r})")
        if K / T < 0.0:
            raise InputError("nomoto", f"K = {K:g} 1/s and T = {T:g} s have opposite signs; give both with one sign "
                                       f"(a course-unstable ship: K < 0 and T < 0, e.g. ({-abs(K):g}, {-abs(T):g}))")
        L = 100.0 if length_m is None else require_finite_range("length_m", length_m, 0.0, 1000.0, lo_open=True)
        return cls(K, T, L, K / T if b2 is None else float(b2))

    @property
    def dims(self) -> tuple[float, float, float]:
        return (0.8, self.L, self.L / 6.5)

    def nomoto(self, speed: float, options: object = None) -> tuple[float, float]:
        return self.K, self.T

    def b2(self, speed: float, method: str, options: object = None) -> float:
        return self.b2_value


def make_gear(gear: Union[SteeringGear, Mapping[str, float], None]) -> SteeringGear:
    """A :class:`SteeringGear` from ``None`` (35 deg, 2.33 deg/s, T_sg 1 s), a ``SteeringGear``,
    or a dict of the scenario's ``[gear]`` keys (``delta_max_deg``, ``rate_max_deg_s``,
    ``T_sg``, ``dead_zone_deg``)."""
    if gear is None:
        return SteeringGear().validated()
    if isinstance(gear, SteeringGear):
        return gear.validated()
    if isinstance(gear, dict):
        from steerlab.sim.scenario import GearConfig

        known = set(GearConfig.model_fields)
        bad = sorted(set(gear) - known)
        if bad:
            raise InputError(f"gear.{bad[0]}", f"unknown key; allowed: {sorted(known)}")
        from pydantic import ValidationError

        from steerlab.sim.scenario import _format_validation_error
        from steerlab.sim.setup import gear_from_config

        try:
            config = GearConfig(**gear)
        except ValidationError as err:       # one line naming gear.<key> and its range, as in a scenario
            e = _format_validation_error(err, gear, GearConfig)
            raise InputError(f"gear.{e.field}", e.message) from None
        return gear_from_config(config).validated()
    raise InputError("gear", f"must be None, a SteeringGear or a dict of [gear] keys, got {type(gear).__name__}")


def design_context(ship: Optional[str] = None, speed_kn: Optional[float] = None,
                   nomoto: Optional[tuple[float, float]] = None, b2: Optional[float] = None,
                   gear: Union[SteeringGear, Mapping[str, float], None] = None, sample_time: float = 0.1,
                   ship_options: Optional[Mapping[str, Any]] = None, length_m: Optional[float] = None
                   ) -> DesignContext:
    """The :class:`DesignContext` of a controller built outside a scenario (see the module doc).

    Parameters
    ----------
    ship : str, optional
        Catalogue ship id (``steerlab ships``); exclusive with ``nomoto``.
    speed_kn : float, optional
        Approach speed [kn] (with ``ship``; default: the ship's design speed ``ShipSpec.design_speed``).
    nomoto : (float, float), optional
        First-order Nomoto ``(K [1/s], T [s])``; ``T < 0`` is a course-unstable model.
    b2 : float, optional
        Rudder efficiency [1/s^2] (yaw acceleration per rad of rudder), overriding the model's.
    gear : None, SteeringGear or dict
        Steering gear (its limit is the default controller output limit).
    sample_time : float
        Controller sample time [s].
    ship_options : dict, optional
        The ship's ``[ship.options]`` (with ``ship``).
    length_m : float, optional
        Ship length [m] for a Nomoto-only design (default 100 m; laws in non-dimensional form).
    """
    require_finite_range("sample_time", sample_time, 0.0, 60.0, lo_open=True)
    g = make_gear(gear)
    speed = math.nan
    if speed_kn is not None:
        speed = knots_to_ms(require_finite_range("speed_kn", speed_kn, 0.0, 40.0, lo_open=True))
    if b2 is not None:
        b2 = require_finite_range("b2", b2)
        if b2 == 0.0:
            raise InputError("b2", "must be non-zero [1/s^2]")
    if ship is not None and nomoto is not None:
        raise InputError("nomoto", "give either ship=ID (with speed_kn) or nomoto=(K, T), not both")
    if ship is not None:
        spec = get_ship(ship) if isinstance(ship, str) else ship
        if speed_kn is None:
            design_speed = getattr(spec, "design_speed", None)
            if design_speed is None:
                raise InputError("speed_kn", f"give the approach speed [kn] of ship {getattr(spec, 'name', ship)!r}")
            speed = float(design_speed)          # the ship's design speed (ShipSpec.design_speed)
        lo, hi = getattr(spec, "speed_range", (0.0, math.inf))
        if not lo <= speed <= hi:
            kn = speed_kn if speed_kn is not None else speed / knots_to_ms(1.0)
            raise InputError("speed_kn", f"{kn:g} kn is outside ship {spec.name!r}'s validity range "
                                         f"[{lo / knots_to_ms(1.0):.4g}, {hi / knots_to_ms(1.0):.4g}] kn")
        opts = spec.options(ship_options) if hasattr(spec, "options") else ship_options
        if b2 is not None:
            return GivenB2Context(spec, speed, g, sample_time, sample_time, opts, b2_value=b2)
        return DesignContext(spec, speed, g, sample_time, sample_time, opts)
    if ship_options is not None:
        raise InputError("ship_options", "only with ship=ID")
    if nomoto is not None:
        model = NomotoModel.checked(nomoto, length_m, b2)
        return GivenB2Context(model, speed, g, sample_time, sample_time, None, b2_value=model.b2_value)
    if length_m is not None:
        raise InputError("length_m", "only with nomoto=(K, T)")
    if b2 is not None:
        return GivenB2Context(NoModel(), speed, g, sample_time, sample_time, None, b2_value=b2)
    return DesignContext(NoModel(), speed, g, sample_time, sample_time, None)
