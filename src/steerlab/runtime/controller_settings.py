"""Live controller settings: named profiles and gain changes at run time, through the design path.

A controller's settings are its scenario's ``[controller]`` table (gains, limits, options,
e.g. ``{"type": "pid", "Kp": 2.0, "Kd": 8.0}``). At run time they change in two ways:

* a **profile**: a named set of settings (``calm``, ``rough``, ...) from a profiles file
  (``steerlab autopilot --profiles FILE.toml``), one TOML table per profile, each a partial
  ``[controller]`` table merged over the scenario's::

      [calm]
      Kp = 1.5
      Kd = 6.0

      [rough]
      Kp = 2.5
      Kd = 10.0
      Ki = 0.002

  The profile ``scenario`` is always there: the scenario's own settings.
* **gains**: single settings given on top of the profile (the bridge page, Signal K, a signed
  command on the plug-in's link); choosing a profile drops them.

Either way the new settings go through the one design path that built the controller at start
(:meth:`steerlab.runtime.controller_runtime.ControllerRuntime.reconfigure`: the scenario schema
validates every field and its range, then ``design`` and ``realise``), so the controller that
steers on is the controller a fresh start with those settings would build. A setting that fails
validation changes nothing and is refused in one line naming the field.
"""

from __future__ import annotations

import math

from steerlab.errors import InputError

SCENARIO_PROFILE = "scenario"
FIXED = ("type", "sample_time")
"""Settings a run-time change may not touch: the law itself and the runtime's sample time."""
MAX_PROFILES = 64
MAX_NAME = 40


def _check_name(name, field: str) -> str:
    if not isinstance(name, str) or not name or len(name) > MAX_NAME \
            or not all(c.isalnum() or c in "-_" for c in name):
        raise InputError(field, f"a profile name is 1-{MAX_NAME} letters, digits, '-' or '_'; got {str(name)[:60]!r}")
    return name


def check_gains(gains, field: str = "gains") -> dict:
    """``gains`` as a plain dict of settings (numbers, strings, booleans), or InputError naming
    ``field`` (the ranges are the scenario schema's, checked by the design path)."""
    if not isinstance(gains, dict) or not gains:
        raise InputError(field, "expected a non-empty object of controller settings, e.g. {\"Kp\": 2.0}")
    out = {}
    for k, v in gains.items():
        if not isinstance(k, str) or not k or len(k) > MAX_NAME:
            raise InputError(field, f"a setting's name is 1-{MAX_NAME} characters; got {str(k)[:60]!r}")
        if k in FIXED:
            raise InputError(f"{field}.{k}", "cannot change at run time (restart with another --controller / --sample-time)")
        if isinstance(v, float) and not math.isfinite(v):
            raise InputError(f"{field}.{k}", f"must be a finite number, got {v}")
        if not isinstance(v, (int, float, str, bool)):
            raise InputError(f"{field}.{k}", f"must be a number, a string or a boolean, got {type(v).__name__}")
        out[k] = v
    return out


def load_profiles(path) -> dict:
    """``{name: settings}`` from a profiles TOML file (see the module docstring); InputError
    naming ``--profiles`` for a file that cannot be read or has a malformed profile. The
    settings' values and ranges are checked against the scenario schema by
    :meth:`ControllerSettings.check` (at start) and again when a profile is chosen."""
    from steerlab.textfile import read_user_text
    from steerlab.toml_input import parse_toml

    text = read_user_text(path, "--profiles", max_bytes=1 << 20)
    data = parse_toml(text, "--profiles", str(path))
    if len(data) > MAX_PROFILES:
        raise InputError("--profiles", f"at most {MAX_PROFILES} profiles, got {len(data)}")
    out = {}
    for name, settings in data.items():
        _check_name(name, "--profiles")
        if name == SCENARIO_PROFILE:
            raise InputError("--profiles", f"the profile name {SCENARIO_PROFILE!r} is the scenario's own settings")
        if not isinstance(settings, dict):
            raise InputError(f"--profiles.{name}", "expected a table of controller settings")
        out[name] = check_gains(settings, f"--profiles.{name}")
    return out


class ControllerSettings:
    """The profile in effect and the gains given on top of it.

    Parameters
    ----------
    base : dict
        The scenario's ``[controller]`` settings (profile :data:`SCENARIO_PROFILE`).
    profiles : dict
        ``{name: partial settings}`` (:func:`load_profiles`).
    """

    def __init__(self, base: dict, profiles: dict | None = None):
        self.base = dict(base)
        self.profiles = {SCENARIO_PROFILE: {}, **(profiles or {})}
        self.profile = SCENARIO_PROFILE
        self.gains: dict = {}

    def check(self, scenario) -> None:
        """Validate every profile against ``scenario``'s schema (InputError naming
        ``--profiles.NAME.field``), so a bad value is found at start, not when it is chosen."""
        from steerlab.sim.scenario import scenario_from_dict

        d = scenario.model_dump()
        for name in self.profiles:
            d["controller"] = self.resolve(name, {})
            try:
                scenario_from_dict(d)
            except InputError as err:
                raise InputError(f"--profiles.{name}.{err.field.removeprefix('controller.')}", err.message) from None

    def names(self) -> list:
        return list(self.profiles)

    def resolve(self, profile: str, gains: dict) -> dict:
        """The full settings for ``profile`` with ``gains`` on top (InputError for an unknown
        profile, naming ``profile``)."""
        if profile not in self.profiles:
            raise InputError("profile", f"unknown profile {str(profile)[:60]!r}; known: {', '.join(self.profiles)}")
        return {**self.base, **self.profiles[profile], **gains}

    def current(self) -> dict:
        return self.resolve(self.profile, self.gains)
