"""Scenario: a frozen, validated description of one closed-loop run, loaded from TOML.

Degrees, knots and rpm appear only here (the edge); :func:`steerlab.sim.setup.build` turns a
scenario into SI arrays for the engines. Example (``examples/scenarios/calm_default.toml``, the default up to 0.1.0)::

    name = "esso-adrc-course-change-waves"
    seed = 1
    dt = 0.1            # s
    duration = 3000.0   # s

    [ship]
    model = "esso"
    speed_kn = 16.0

    [gear]              # eq (15) defaults: 35 deg, 2.33 deg/s, 1 s
    delta_max_deg = 35.0

    [controller]
    type = "adrc"       # or "pid"
    T_settle = 150.0    # s
    c0 = "estimate"     # eq (29); "exact" (linearisation) or a number [1/s^2], steerlab sign

    [guidance]
    psi0_deg = 0.0
    changes = [{ t = 100.0, psi_deg = 20.0 }]

    [environment]
    waves = true
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, Literal, Mapping, Optional

from pydantic import BaseModel, Field, PlainValidator, ValidationError, model_validator
from pydantic_core import PydanticCustomError

from steerlab.config_base import FrozenConfig
from steerlab.control.registry import CONTROLLERS
from steerlab.environment.sea_config import (CurrentVariationConfig, GustConfig, WaveConfig,
                                             WindRudderConfig)
from steerlab.sensors.config import SensorsConfig

from steerlab.errors import InputError


_Frozen = FrozenConfig


class ShipConfig(_Frozen):
    model: str = "esso"
    speed_kn: Optional[float] = Field(None, ge=0.01, le=40.0,
                                      description="approach speed [kn], 0.01-40 kn; default: the ship's design speed")
    rpm: Optional[float] = Field(None, gt=0.0, le=1000.0,
                                 description="propeller rate [rpm]; default: the rate that holds speed_kn")
    options: dict[str, Any] = Field(
        default_factory=dict, description="ship-specific options, validated by the ship's options_model")

    def speed(self) -> float:
        """The approach speed [m/s]: ``speed_kn``, else the ship's design speed
        (:attr:`steerlab.ships.registry.ShipSpec.design_speed`; 16 kn for the Esso tanker)."""
        from steerlab.ships.registry import get_ship
        from steerlab.units import knots_to_ms

        if self.speed_kn is not None:
            return knots_to_ms(self.speed_kn)
        return float(get_ship(self.model).design_speed)

    def speed_in_kn(self) -> float:
        """:meth:`speed` in knots (``speed_kn`` itself when it is given)."""
        from steerlab.units import ms_to_knots

        return self.speed_kn if self.speed_kn is not None else ms_to_knots(self.speed())


class GearConfig(_Frozen):
    """``[gear]``: eq (15) defaults (35 deg, 2.33 deg/s, 1 s) for a full-size ship; a key left
    out takes the ship's :meth:`~steerlab.ships.registry.ShipSpec.default_gear` value (a scale
    model's gear is Froude-scaled: :func:`ship_gear_defaults`)."""

    delta_max_deg: float = Field(35.0, gt=0.0, le=90.0)
    rate_max_deg_s: float = Field(2.33, gt=0.0, le=100.0)
    T_sg: float = Field(1.0, ge=0.001, le=100.0, description="servo time constant [s], 0.001-100 s")
    dead_zone_deg: float = Field(0.0, ge=0.0, le=10.0)


def ship_gear_defaults(model: Any) -> dict:
    """``[gear]`` values (degrees at the edge) of ship ``model``'s default steering gear when it
    differs from :class:`GearConfig`'s (a scale model: Froude-scaled rate and lag), else ``{}``.
    An unknown ship gives ``{}`` (``[ship] model`` is reported by its own check)."""
    from steerlab.ships.registry import get_ship

    try:
        spec = get_ship(model if isinstance(model, str) else ShipConfig().model)
    except Exception:  # noqa: BLE001 - the ship's own validation reports an unknown model
        return {}
    if getattr(spec, "model_scale", None) is None:
        return {}
    g = spec.default_gear()
    return {"rate_max_deg_s": math.degrees(g.rate_max), "T_sg": g.T_sg}


def _fill_ship_gear(data: Any) -> Any:
    """Scenario data with the ``[gear]`` keys it leaves out taken from the ship's default gear."""
    if not isinstance(data, dict):
        return data
    ship = data.get("ship", {})
    model = ship.get("model") if isinstance(ship, dict) else getattr(ship, "model", None)
    defaults = ship_gear_defaults(model)
    if not defaults:
        return data
    gear = data.get("gear", {})
    if isinstance(gear, BaseModel):
        given = {k: getattr(gear, k) for k in gear.model_fields_set}
    elif isinstance(gear, dict):
        given = dict(gear)
    else:
        return data           # not a table: reported by the [gear] validation
    return {**data, "gear": {**defaults, **given}}


def _expected_tags() -> str:
    return ", ".join(repr(name) for name in CONTROLLERS)


def _controller_config(value: Any) -> Any:
    """``[controller]``: validated against the config of the controller its ``type`` names.

    The same check as a discriminated union of every registered controller's config (the same
    error types, so the same messages), without importing every controller module: the
    chosen one is found by name (:meth:`steerlab.plugins.Registry.get_spec`, which imports
    only its module when steerlab's index knows it).
    """
    if isinstance(value, dict):
        tag = value.get("type", _MISSING)
    elif isinstance(value, BaseModel):
        tag = getattr(value, "type", _MISSING)
    else:
        raise PydanticCustomError("model_attributes_type",
                                  "Input should be a valid dictionary or object to extract fields from")
    if tag is _MISSING:
        raise PydanticCustomError("union_tag_not_found",
                                  "Unable to extract tag using discriminator {discriminator}",
                                  {"discriminator": "'type'"})
    try:
        spec = CONTROLLERS.find(tag) if isinstance(tag, str) else None
        expected = _expected_tags() if spec is None else ""
    except InputError as err:          # the registry itself: a broken plug-in, a name declared twice
        raise PydanticCustomError(_REGISTRY_ERROR, "{field}: {message}",
                                  {"field": err.field, "message": err.message}) from None
    if spec is None:
        raise PydanticCustomError("union_tag_invalid",
                                  "Input tag {tag} found using {discriminator} does not match any of the "
                                  "expected tags: {expected_tags}",
                                  {"discriminator": "'type'", "tag": str(tag), "expected_tags": expected})
    config: type[BaseModel] = spec.config
    return config.model_validate(value)


_REGISTRY_ERROR = "steerlab_registry"   #: error type carrying a registry's InputError through pydantic


_MISSING = object()

if TYPE_CHECKING:      # any registered controller's config (FrozenConfig subclasses)
    ControllerConfig = Any
else:
    ControllerConfig = Annotated[Any, PlainValidator(_controller_config)]


def _default_controller():
    from steerlab.control.adrc import ADRCConfig

    return ADRCConfig(type="adrc")


class CourseChange(_Frozen):
    t: float = Field(ge=0.0, description="time of the change [s]")
    psi_deg: float = Field(ge=-360.0, le=360.0, description="new set heading [deg]")
    direction: Literal["shortest", "starboard", "port"] = Field(
        "shortest", description="which way to turn (types rate_limited, third_order)")


class GuidanceConfig(_Frozen):
    """``[guidance]``: see :mod:`steerlab.guidance.plan` and docs/guidance.md."""

    type: Literal["course", "rate_limited", "third_order", "los", "berthing"] = "course"
    psi0_deg: float = Field(0.0, ge=-360.0, le=360.0)
    rate_max_deg_s: float = Field(0.0, ge=0.0, le=10.0, description="0 = step set-point")
    changes: tuple[CourseChange, ...] = ()
    # course-change reference models
    omega_n: float = Field(0.1, gt=0.0, le=10.0, description="natural frequency [rad/s]")
    zeta: float = Field(1.0, gt=0.0, le=10.0, description="damping ratio [-]")
    accel_max_deg_s2: Optional[float] = Field(None, gt=0.0, le=100.0,
                                              description="yaw-acceleration limit [deg/s^2]; none if absent")
    # routes (los, berthing)
    start: tuple[float, float] = Field((0.0, 0.0), description="initial position [x_n, y_e] [m]")
    route: tuple[tuple[float, float], ...] = Field((), description="waypoints [[x_n, y_e], ...] [m]")
    route_file: Optional[str] = Field(None, description="CSV of waypoints x_n, y_e [m]")
    lookahead_L: float = Field(2.0, gt=0.0, le=100.0, description="n in Delta = n L [-]")
    accept_radius_m: Optional[float] = Field(None, gt=0.0, le=1e6, description="R [m]; default L")
    xte_tolerance_m: Optional[float] = Field(None, gt=0.0, le=1e6,
                                             description="|XTE| counted on route [m]; default R")
    # berthing
    rpm_plan: tuple[tuple[float, float], ...] = Field(
        (), description="[[distance to berth [m], rpm], ...], distances decreasing")
    stop_radius_m: Optional[float] = Field(None, gt=0.0, le=1e6, description="rpm 0 inside [m]; default R")
    success_radius_m: Optional[float] = Field(None, gt=0.0, le=1e6,
                                              description="berthed if the final D is within [m]; default L/2")
    berth_speed_max_kn: float = Field(1.0, gt=0.0, le=10.0, description="full-scale speed limit [kn]")
    model_scale: float = Field(1.0, ge=1.0, le=1000.0, description="Froude scale of the ship model [-]")


class EnvironmentConfig(_Frozen):
    constant_rudder_deg: float = Field(0.0, ge=-60.0, le=60.0)
    constant_start: float = Field(0.0, ge=0.0)
    waves: bool = False
    wave_sample_time: float = Field(0.5, gt=0.0, le=60.0)
    wave_power: float = Field(1e-4, ge=0.0, le=1.0)
    wind_speed: float = Field(0.0, ge=0.0, le=100.0, description="constant true wind speed [m/s]")
    wind_dir_deg: float = Field(0.0, ge=-360.0, le=360.0,
                                description="direction the wind comes FROM [deg], clockwise from north")
    current_speed: float = Field(0.0, ge=0.0, le=10.0, description="constant current speed [m/s]")
    current_dir_deg: float = Field(0.0, ge=-360.0, le=360.0,
                                   description="direction the current flows TOWARDS [deg], clockwise from north")
    # optional sea blocks (steerlab.environment.sea_config), all off by default
    wave: Optional[WaveConfig] = None
    gusts: Optional[GustConfig] = None
    current_variation: Optional[CurrentVariationConfig] = None
    wind_rudder: Optional[WindRudderConfig] = None


MAX_NAME = 200
"""Longest scenario ``name`` [characters]: it titles every figure, report and table (a name of
100 000 characters took 76 s of figure layout, millions hung; now refused in one line)."""
MAX_DESCRIPTION = 10_000
"""Longest scenario ``description`` [characters]."""


class Scenario(_Frozen):
    name: str = Field("scenario", max_length=MAX_NAME,
                      description=f"titles the figures and the report; at most {MAX_NAME} characters")
    description: str = Field("", max_length=MAX_DESCRIPTION)
    seed: int = Field(0, ge=0, le=2**63 - 1)
    dt: float = Field(0.1, ge=1e-4, le=10.0, description="integration step [s], 1e-4-10 s")
    duration: float = Field(3000.0, gt=0.0, le=1e6, description="[s]")
    ship: ShipConfig = ShipConfig()
    gear: GearConfig = GearConfig()
    controller: ControllerConfig = Field(default_factory=_default_controller)
    guidance: GuidanceConfig = GuidanceConfig()
    environment: EnvironmentConfig = EnvironmentConfig()
    sensors: Optional[SensorsConfig] = None   # steerlab.sensors: off by default

    @model_validator(mode="before")
    @classmethod
    def _ship_gear(cls, data: Any) -> Any:
        """The ``[gear]`` keys the scenario leaves out, from the ship's default gear."""
        return _fill_ship_gear(data)

    @property
    def n_steps(self) -> int:
        return int(math.ceil(self.duration / self.dt - 1e-9))

    def replace(self, **changes: Any) -> "Scenario":
        """A validated copy with top-level fields replaced (nested: pass whole sub-configs)."""
        return scenario_from_dict({**self.model_dump(), **_dump(changes)})


def _dump(d):
    return {k: (v.model_dump() if isinstance(v, BaseModel) else v) for k, v in d.items()}


def _is_union_member_tag(part) -> bool:
    """pydantic puts the tried union member in ``loc`` ('adrc', 'float', "literal['a','b']")."""
    return isinstance(part, str) and (part in CONTROLLERS or part in ("float", "int", "str", "dict")
                                      or part.startswith("literal["))


def _tag_message(error: Mapping[str, Any]) -> str:
    """One short line for an unknown or missing discriminator (e.g. ``[controller] type``):
    the base types, once, and the ``+wf`` rule instead of every wrapped variant."""
    ctx = error.get("ctx") or {}
    tags = [t.strip(" '") for t in str(ctx.get("expected_tags", "")).split(",") if t.strip(" '")] or list(CONTROLLERS)
    base = sorted(t for t in tags if "+" not in t)
    known = ", ".join(base)
    for x in sorted({t.split("+", 1)[1] for t in tags if "+" in t}):
        without = [b for b in base if f"{b}+{x}" not in tags]
        known += f" (each also as '<type>+{x}'" + (f", except {', '.join(without)})" if without else ")")
    if error["type"] == "union_tag_not_found":
        return f"missing; give type = one of {known}"
    return f"unknown type {ctx.get('tag')!r}; known: {known}"


def _field_bounds(model: Any, loc: list, data: Any = None) -> list[str]:
    """The declared bounds (``gt 0.0``, ``le 1000000.0``) of the field at ``loc`` in the pydantic
    ``model`` (nested models, optional and list fields followed; list indices skipped; the
    ``[controller]`` table's config found by its ``type`` in ``data``, the input), for the
    error line of a value pydantic refused before it compared it with them (NaN, inf). Empty
    if the field is not found or declares none."""
    field = None
    for part in loc:
        if isinstance(part, int):
            continue
        fields = getattr(model, "model_fields", None)
        if not isinstance(fields, dict) or part not in fields:
            return []
        field = fields[part]
        model = next((a for a in _annotation_types(field.annotation) if hasattr(a, "model_fields")), None)
        table = data.get(part) if isinstance(data, dict) else None
        if model is None and part == "controller" and isinstance(table, dict) and isinstance(table.get("type"), str):
            try:                                          # the config its type names (_controller_config)
                spec = CONTROLLERS.find(table["type"])
            except InputError:
                return []
            model = spec.config if spec is not None else None
        data = table
    if field is None:
        return []
    out = []
    for m in field.metadata:
        out += [f"{k} {getattr(m, k)}" for k in ("gt", "ge", "lt", "le") if getattr(m, k, None) is not None]
    return out


def _annotation_types(annotation: Any) -> list:
    """``annotation`` and the types inside it (``Optional[X]``, ``list[X]``, ``tuple[X, ...]``)."""
    import typing

    out, todo = [], [annotation]
    while todo:
        a = todo.pop()
        out.append(a)
        todo.extend(x for x in typing.get_args(a) if x is not Ellipsis)
    return out


def _format_validation_error(err: ValidationError, data: Any = None, model: Any = None) -> InputError:
    """One :class:`InputError` line for pydantic's ``err`` (the first problem, and how many more);
    ``data``, the input, and ``model``, the pydantic model it was validated against (default
    :class:`Scenario`), find the declared range of a field pydantic refused as not finite."""
    first = err.errors()[0]
    if first["type"] == _REGISTRY_ERROR:                     # raised as it was, with its own field
        return InputError(first["ctx"]["field"], first["ctx"]["message"])
    loc = ".".join(str(p) for p in first["loc"] if not _is_union_member_tag(p))
    msg = first["msg"]
    ctx = first.get("ctx") or {}
    bounds = [f"{k.replace('_', ' ')} {v}" for k, v in ctx.items() if k in ("gt", "ge", "lt", "le")]
    if not bounds and first["type"] == "finite_number":      # NaN/inf: pydantic names no range
        bounds = _field_bounds(model or Scenario, [p for p in first["loc"] if not _is_union_member_tag(p)], data)
    if bounds:
        msg += f" (allowed: {', '.join(bounds)})"
    if first["type"] in ("union_tag_invalid", "union_tag_not_found"):
        loc = f"{loc}.type" if loc else "controller.type"
        msg = _tag_message(first)
    more = len({tuple(x for x in e["loc"] if not _is_union_member_tag(x)) for e in err.errors()}) - 1
    if more:
        msg += f" [and {more} more problem{'s' if more > 1 else ''}]"
    return InputError(loc or "scenario", msg)


def scenario_from_dict(data: dict) -> Scenario:
    """Validate a plain dict (as parsed from TOML) into a :class:`Scenario`."""
    try:
        return Scenario.model_validate(data)
    except ValidationError as err:
        raise _format_validation_error(err, data) from None


MAX_SCENARIO_BYTES = 16 << 20   #: largest scenario file [bytes]


def load_scenario(path: str | os.PathLike[str]) -> Scenario:
    """Load and validate a scenario TOML file; raises :class:`InputError` on any problem,
    also when the file sets nothing (empty, or comments only).

    The file is read as bytes and decoded strictly (:func:`steerlab.textfile.read_user_text`:
    regular file, at most 16 MiB, no NUL, valid UTF-8) and parsed with bounded nesting
    (:func:`steerlab.toml_input.parse_toml`).
    """
    from steerlab.textfile import read_user_text
    from steerlab.toml_input import parse_toml

    p = Path(path)
    data = parse_toml(read_user_text(p, "scenario", MAX_SCENARIO_BYTES), "scenario", p.name)
    if not data:       # every field has a default, but a file without one is a mistake, not a scenario
        raise InputError("scenario", f"{p.name} sets nothing (an empty file or comments only): give at least "
                         "[ship] and [controller] (examples/scenarios/), or no file for the bundled default")
    g = data.get("guidance") if isinstance(data, dict) else None
    if isinstance(g, dict) and isinstance(g.get("route_file"), str) and not Path(g["route_file"]).is_absolute():
        g["route_file"] = str(p.parent / g["route_file"])     # relative to the scenario file
    return scenario_from_dict(data)


def default_scenario_path() -> Path:
    return Path(__file__).resolve().parent.parent / "scenarios" / "default.toml"


def default_scenario() -> Scenario:
    """The bundled default: Esso tanker + ADRC, 20 deg course change, then course keeping in a
    JONSWAP sea of sea state 6 from 45 deg off the bow (``src/steerlab/scenarios/default.toml``)."""
    return load_scenario(default_scenario_path())
