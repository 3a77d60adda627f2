"""Settings a scenario gives that its chosen models never read: one warning each.

A value typed into a scenario is meant to change the run. Some settings only act together with
another: ``wave_power`` shapes the eq (39) waves and does nothing without ``waves = true``;
``omega0`` is the thesis wave model's, ignored by the spectrum model; a wind acts only on a ship
with a wind model. Before, such a setting was accepted and silently ignored (a user who set
``wave_power = 0.5`` without ``waves = true`` got a calm run and no word).

:func:`inert_settings` lists them, ``"field: why it has no effect"``, for the settings given a
value other than their default (a dump of a scenario re-read, as sweeps do, sets every field to
what it was: defaults never warn). :func:`warn_inert_settings` (called once per design by
:meth:`steerlab.sim.setup.Design.of`) warns each as a :class:`~steerlab.errors.InertSettingWarning`,
with the wind probed on the ship's kernel (:mod:`steerlab.sim.wind_felt`); the CLI prints
them as ``steerlab: warning: ...`` lines and lists them in a run's ``metrics.json``. The run is
the one the scenario describes without them: no number changes.
"""

from __future__ import annotations

import os
import sys
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from steerlab.errors import InertSettingWarning
from steerlab.jit.numba_cache import PACKAGE_ROOT

#: [environment.wave] fields each wave model reads (besides ``model``; the eq (39) waves read
#: ``environment.wave_power`` and ``wave_sample_time`` instead)
_WAVE_FIELDS = {
    "thesis": {"yaw_rate_std_deg_s", "zeta", "omega0", "wave_angle_deg", "channel",
               "Hs", "Tp", "sea_state", "spectrum", "jonswap_gamma"},
    "spectrum": {"spectrum", "Hs", "Tp", "sea_state", "jonswap_gamma", "wave_angle_deg",
                 "yaw_accel_per_slope", "n_components", "channel"},
    "eq39": set(),
    "none": set(),
}
#: [guidance] fields each guidance type reads (``psi0_deg`` and ``start`` are every run's initial
#: heading and position; ``rate_max_deg_s`` is also the ``autopilot`` command's turn rate, so a
#: route type is not told it is unread)
_COURSE = {"psi0_deg", "start", "changes", "rate_max_deg_s"}
_ROUTE = {"psi0_deg", "start", "rate_max_deg_s", "route", "route_file", "lookahead_L", "accept_radius_m",
          "xte_tolerance_m"}
_GUIDANCE_FIELDS = {
    "course": _COURSE,
    "rate_limited": _COURSE | {"omega_n", "zeta", "accel_max_deg_s2"},
    "third_order": _COURSE | {"omega_n", "zeta", "accel_max_deg_s2"},
    "los": _ROUTE,
    "berthing": _ROUTE | {"rpm_plan", "stop_radius_m", "success_radius_m", "berth_speed_max_kn", "model_scale"},
}
#: with ``omega0`` given, the thesis model does not derive its peak frequency from these
_THESIS_PEAK_FROM = ("Hs", "Tp", "sea_state", "spectrum", "jonswap_gamma")


def given(cfg: Any, name: str) -> bool:
    """Whether field ``name`` of the pydantic config ``cfg`` was given a value other than its
    default."""
    return name in cfg.model_fields_set and getattr(cfg, name) != type(cfg).model_fields[name].default


def _wave_block(wave) -> list[str]:
    """The unread settings of an ``[environment.wave]`` block, with why."""
    model, fields = wave.model, type(wave).model_fields
    if model in ("eq39", "none"):
        why = f'model = "{model}" reads no other setting of this block'
        if model == "eq39":
            why += " (the eq (39) waves take environment.wave_power and wave_sample_time)"
        reasons = {name: why for name in fields if name != "model"}
    else:
        other = "spectrum" if model == "thesis" else "thesis"
        reasons = {name: f'a setting of the {other} model, not read with model = "{model}"'
                   for name in fields if name != "model" and name not in _WAVE_FIELDS[model]}
        if model == "thesis" and wave.omega0 is not None:
            reasons.update({name: "the thesis model takes its peak frequency from omega0, which is given"
                            for name in _THESIS_PEAK_FROM})
        if wave.spectrum != "jonswap":
            reasons.setdefault("jonswap_gamma", f'only the JONSWAP spectrum reads it (spectrum = "{wave.spectrum}")')
    return [f"environment.wave.{name}: has no effect: {why}" for name, why in reasons.items() if given(wave, name)]


def _guidance_block(guidance) -> list[str]:
    """The unread settings of ``[guidance]`` for its ``type``, with the types that read them."""
    out = []
    for name in type(guidance).model_fields:
        if name == "type" or name in _GUIDANCE_FIELDS[guidance.type] or not given(guidance, name):
            continue
        readers = ", ".join(t for t, fields in _GUIDANCE_FIELDS.items() if name in fields)
        out.append(f'guidance.{name}: has no effect with type = "{guidance.type}" (read by type {readers})')
    return out


def inert_settings(scenario: Any) -> list[str]:
    """``"field: why it has no effect"`` for each setting of ``scenario`` its models do not read
    (the wind's effect on the ship is probed separately: :func:`warn_inert_settings`)."""
    env = scenario.environment
    out = []
    eq39 = env.waves or (env.wave is not None and env.wave.model == "eq39")
    if not eq39:
        for name in ("wave_power", "wave_sample_time"):
            if given(env, name):
                out.append(f"environment.{name}: has no effect without the eq (39) waves "
                           "(waves = true, or [environment.wave] model = \"eq39\")")
    if given(env, "constant_start") and env.constant_rudder_deg == 0.0:
        out.append("environment.constant_start: has no effect without a constant_rudder_deg")
    if given(env, "wind_dir_deg") and env.wind_speed == 0.0:
        out.append("environment.wind_dir_deg: has no effect without a wind (wind_speed > 0 m/s)")
    if given(env, "current_dir_deg") and env.current_speed == 0.0 and env.current_variation is None:
        out.append("environment.current_dir_deg: has no effect without a current (current_speed > 0 m/s or "
                   "[environment.current_variation])")
    if env.wave is not None:
        out += _wave_block(env.wave)
    return out + _guidance_block(scenario.guidance)


def rpm_unread(scenario: Any, ship: Any, ps: Any, repack: Callable[[float], Any]) -> str | None:
    """The message for a ``[ship] rpm`` the ship's record does not take (None if it does, or if
    none is given): ``repack(rpm)`` packs the ship's record at another rate (0.9 times the given
    one); the same record means the rate is not read (the Nomoto, Norrbin, Bech and van Leeuwen
    models steer at a constant speed)."""
    rpm = scenario.ship.rpm
    if rpm is None or not np.array_equal(np.asarray(ps), np.asarray(repack(0.9 * rpm))):
        return None
    return (f"ship.rpm: has no effect: ship {ship.name!r} takes no propeller rate (its speed is "
            "ship.speed_kn)")


def warn_inert_settings(scenario: Any, ship: Any, ps: Any, x0: Any,
                        repack: Callable[[float], Any] | None = None) -> list[str]:
    """Warn (:class:`~steerlab.errors.InertSettingWarning`) for each of :func:`inert_settings`,
    for a wind the ship does not read and for a propeller rate it does not take (with ``repack``,
    :func:`rpm_unread`); returns the messages."""
    from steerlab.sim.wind_felt import unfelt_wind_message, wind_felt

    messages = inert_settings(scenario)
    rpm = None if repack is None else rpm_unread(scenario, ship, ps, repack)
    if rpm is not None:
        messages.append(rpm)
    wind = unfelt_wind_message(ship.name, scenario.environment)
    if wind is not None and not wind_felt(ship, ps, x0):
        messages.append(wind)
    level = _first_caller_outside_steerlab()
    for message in messages:
        warnings.warn(message, InertSettingWarning, stacklevel=level)
    return messages


def _first_caller_outside_steerlab() -> int:
    """The ``stacklevel`` (for a ``warnings.warn`` in the caller of this function) of the first
    frame outside the steerlab package and outside the Gymnasium package (whose ``gym.make``
    builds steerlab's environments): the user's line that asked for the run (a notebook cell, a
    script), which Python's warning then names, and by which its default filter shows a
    repeated warning once per line."""
    inside = (str(PACKAGE_ROOT) + os.sep,) + _gymnasium_root()
    frame, level = sys._getframe(2), 2
    while frame is not None and frame.f_code.co_filename.startswith(inside):
        frame, level = frame.f_back, level + 1
    return level


def _gymnasium_root() -> tuple[str, ...]:
    """Gymnasium's package folder, if it is imported (it is, when it builds an environment)."""
    gymnasium = sys.modules.get("gymnasium")
    file = getattr(gymnasium, "__file__", None)
    return (str(Path(file).resolve().parent) + os.sep,) if file else ()
