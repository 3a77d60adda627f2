"""Options shared by ``steerlab trial ...`` and ``steerlab imo`` (ship, speed, options, gear)."""

from __future__ import annotations

import json
import math

from steerlab.errors import InputError

FLAG_NAMES = {"rudder": "--rudder", "heading": "--heading", "max_rudder": "--max-rudder", "step": "--step",
              "n_rates": "--points", "hold": "--hold-s", "speed_kn": "--speed-kn", "dt": "--dt",
              "side": "--side"}


def add_ship_arguments(p) -> None:
    p.add_argument("--ship", required=True, help="ship name from the registry (e.g. esso, nomoto1)")
    p.add_argument("--speed-kn", type=float, default=None,
                   help="approach speed [kn] (default 16, or the middle of the ship's validity range)")
    p.add_argument("--ship-option", action="append", default=[], metavar="NAME=VALUE",
                   help="a [ship.options] value, repeatable (e.g. --ship-option K=0.1 --ship-option T=80)")
    p.add_argument("--no-gear", action="store_true",
                   help="open loop: ideal rudder that follows the order (no rate limit, lag dt/1.6)")
    p.add_argument("--rudder-limit", type=float, default=None, metavar="DEG",
                   help="steering-gear rudder limit [deg] (default 35)")
    p.add_argument("--rudder-rate", type=float, default=None, metavar="DEG_S",
                   help="steering-gear rate limit [deg/s] (default 2.33; model-scale ships need a "
                        "Froude-scaled, faster gear)")
    p.add_argument("--dt", type=float, default=0.1, help="integration step [s] (default 0.1)")
    p.add_argument("--quiet", action="store_true", help="no progress messages")


def parse_ship_options(items) -> dict:
    """``["K=0.1", "name=abc"]`` -> ``{"K": 0.1, "name": "abc"}`` (JSON values where they parse)."""
    out = {}
    for item in items:
        name, sep, value = item.partition("=")
        name = name.strip()
        if not sep or not name:
            raise InputError("--ship-option", f"expected NAME=VALUE, got {item!r}")
        try:
            v = json.loads(value)
        except ValueError:
            v = value
        if isinstance(v, float) and not math.isfinite(v):
            raise InputError(f"--ship-option {name}", f"must be finite, got {value!r}")
        out[name] = v
    return out


def conditions_from_args(args):
    from steerlab.trials.runner import TrialConditions

    gear = {}
    if args.rudder_limit is not None:
        if not (math.isfinite(args.rudder_limit) and 0.0 < args.rudder_limit <= 90.0):
            raise InputError("--rudder-limit", f"must be in (0, 90] deg, got {args.rudder_limit}")
        gear["delta_max_deg"] = args.rudder_limit
    if args.rudder_rate is not None:
        if not (math.isfinite(args.rudder_rate) and 0.0 < args.rudder_rate <= 100.0):
            raise InputError("--rudder-rate", f"must be in (0, 100] deg/s, got {args.rudder_rate}")
        gear["rate_max_deg_s"] = args.rudder_rate
    if args.speed_kn is not None and not (math.isfinite(args.speed_kn) and 0.0 < args.speed_kn <= 40.0):
        raise InputError("--speed-kn", f"must be in (0, 40] kn, got {args.speed_kn}")
    if not (math.isfinite(args.dt) and 0.0 < args.dt <= 5.0):
        raise InputError("--dt", f"must be in (0, 5] s, got {args.dt}")
    cond = TrialConditions(ship=args.ship, speed_kn=args.speed_kn, options=parse_ship_options(args.ship_option),
                           gear=not args.no_gear, gear_config=gear, dt=args.dt)
    return with_flag_names(cond.resolved)


def with_flag_names(fn, *a, **kw):
    """Call ``fn``; re-raise an :class:`InputError` with the CLI flag name of its field."""
    try:
        return fn(*a, **kw)
    except InputError as err:
        if err.field in FLAG_NAMES:
            raise InputError(FLAG_NAMES[err.field], err.message) from None
        raise
