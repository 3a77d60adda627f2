"""Options shared by ``steerlab trial ...`` and ``steerlab imo`` (ship, speed, options, gear)."""

from __future__ import annotations

import json
import math

from steerlab.errors import InputError

FLAG_NAMES = {"rudder": "--rudder", "heading": "--heading", "max_rudder": "--max-rudder", "step": "--step",
              "n_rates": "--points", "hold": "--hold-s", "speed_kn": "--speed-kn", "dt": "--dt",
              "side": "--side", "ship.rpm": "--propeller-rps", "ship.options.depth_m": "--depth",
              "gear.T_sg": "--servo-lag", "gear.rate_max_deg_s": "--rudder-rate", "ship.model": "--ship"}


def add_ship_arguments(p) -> None:
    p.add_argument("--ship", required=True, help="ship name from the registry (e.g. esso, nomoto1)")
    speed = p.add_mutually_exclusive_group()
    speed.add_argument("--speed-kn", type=float, default=None,
                       help="approach speed [kn] (default 16, or the middle of the ship's validity range)")
    speed.add_argument("--speed-m-s", type=float, default=None, metavar="M_S",
                       help="approach speed [m/s] (model tests: e.g. 1.179 for kvlcc2-l7)")
    prop = p.add_mutually_exclusive_group()
    prop.add_argument("--propeller-rps", type=float, default=None, metavar="RPS",
                      help="propeller rate [rev/s], held (default: the ship's own, e.g. self-propulsion)")
    prop.add_argument("--propeller-rpm", type=float, default=None, metavar="RPM",
                      help="propeller rate [rev/min], held (as --propeller-rps x 60)")
    p.add_argument("--depth", type=float, default=None, metavar="M",
                   help="water depth [m], for ships whose model has shallow-water terms (mss-tanker)")
    p.add_argument("--ship-option", action="append", default=[], metavar="NAME=VALUE",
                   help="a [ship.options] value, repeatable (e.g. --ship-option K=0.1 --ship-option T=80)")
    p.add_argument("--no-gear", action="store_true",
                   help="open loop: ideal rudder that follows the order (no rate limit, lag dt/1.6)")
    p.add_argument("--rudder-limit", type=float, default=None, metavar="DEG",
                   help="steering-gear rudder limit [deg] (default 35)")
    p.add_argument("--rudder-rate", type=float, default=None, metavar="DEG_S",
                   help="steering-gear rate limit [deg/s] (default 2.33; a scale model: Froude-scaled, "
                        "2.33 sqrt(L_full/L_model), e.g. 15.75 for kvlcc2-l7)")
    p.add_argument("--servo-lag", type=float, default=None, metavar="S",
                   help="steering-gear servo time constant [s] (default 1; a scale model: 1/sqrt(L_full/L_model))")
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
    lag = getattr(args, "servo_lag", None)
    if lag is not None:
        if not (math.isfinite(lag) and 0.001 <= lag <= 100.0):
            raise InputError("--servo-lag", f"must be in [0.001, 100] s, got {lag}")
        gear["T_sg"] = lag
    speed_kn = args.speed_kn
    if speed_kn is not None and not (math.isfinite(speed_kn) and 0.0 < speed_kn <= 40.0):
        raise InputError("--speed-kn", f"must be in (0, 40] kn, got {speed_kn}")
    speed_m_s = getattr(args, "speed_m_s", None)
    if speed_m_s is not None:
        from steerlab.units import KNOT

        if not (math.isfinite(speed_m_s) and 0.0 < speed_m_s <= 40.0 * KNOT):
            raise InputError("--speed-m-s", f"must be in (0, {40.0 * KNOT:.4g}] m/s, got {speed_m_s}")
        speed_kn = speed_m_s / KNOT
    if not (math.isfinite(args.dt) and 0.0 < args.dt <= 5.0):
        raise InputError("--dt", f"must be in (0, 5] s, got {args.dt}")
    options = parse_ship_options(args.ship_option)
    rpm = _propeller_rpm(args)
    depth = getattr(args, "depth", None)
    if depth is not None:
        options["depth_m"] = _checked_depth(args.ship, depth)
    cond = TrialConditions(ship=args.ship, speed_kn=speed_kn, options=options,
                           gear=not args.no_gear, gear_config=gear, dt=args.dt, rpm=rpm)
    try:
        return with_flag_names(cond.resolved, flags=flag_names(args))
    except InputError as err:
        if speed_m_s is not None and err.field == "--speed-kn":
            raise InputError("--speed-m-s", f"{speed_m_s:g} m/s = {err.message}") from None
        raise


def _propeller_rpm(args) -> float | None:
    """``--propeller-rps`` or ``--propeller-rpm`` as rev/min (None: neither given)."""
    rps, rpm = getattr(args, "propeller_rps", None), getattr(args, "propeller_rpm", None)
    if rps is not None:
        if not (math.isfinite(rps) and 0.0 < rps <= 1000.0 / 60.0):
            raise InputError("--propeller-rps", f"must be in (0, {1000.0 / 60.0:.4g}] rev/s, got {rps}")
        return 60.0 * rps
    if rpm is not None and not (math.isfinite(rpm) and 0.0 < rpm <= 1000.0):
        raise InputError("--propeller-rpm", f"must be in (0, 1000] rev/min, got {rpm}")
    return rpm


def _checked_depth(ship_name: str, depth: float) -> float:
    """``--depth`` [m]: finite, positive, and only for a ship whose options take ``depth_m``."""
    from steerlab.ships.registry import get_ship

    ship = get_ship(ship_name)
    fields = getattr(ship.options_model, "model_fields", {}) if ship.options_model is not None else {}
    if "depth_m" not in fields:
        raise InputError("--depth", f"ship {ship_name!r} has no shallow-water terms (deep water only); "
                                    f"ships with them: mss-tanker")
    if not (math.isfinite(depth) and depth > 0.0):
        raise InputError("--depth", f"must be a water depth > 0 m (and above the draught), got {depth}")
    return float(depth)


def flag_names(args) -> dict:
    """:data:`FLAG_NAMES` with the propeller rate (``ship.rpm``) named by the flag the user gave
    (``--propeller-rpm`` or ``--propeller-rps``), and the rate they gave in their own unit."""
    names = dict(FLAG_NAMES)
    rpm = getattr(args, "propeller_rpm", None)
    if rpm is not None:
        names["ship.rpm"] = ("--propeller-rpm", f"{rpm:g} rpm = {rpm / 60.0:.4g} rev/s")
    rps = getattr(args, "propeller_rps", None)
    if rps is not None:
        names["ship.rpm"] = ("--propeller-rps", f"{rps:g} rev/s = {60.0 * rps:.4g} rpm")
    return names


def with_flag_names(fn, *a, flags: dict | None = None, **kw):
    """Call ``fn``; re-raise an :class:`InputError` with the CLI flag name of its field.

    ``flags``: field -> flag name, or ``(flag name, what the user gave)`` (:func:`flag_names`;
    default :data:`FLAG_NAMES`).
    """
    flags = FLAG_NAMES if flags is None else flags
    try:
        return fn(*a, **kw)
    except InputError as err:
        if err.field in flags:
            msg = err.message
            if err.field == "ship.options.depth_m":
                msg = f"water depth [m] {msg} (the model refuses depths at or below the draught)"
            flag = flags[err.field]
            if isinstance(flag, tuple):
                flag, given = flag
                msg = f"{msg} (you gave {given})"
            raise InputError(flag, msg) from None
        raise
