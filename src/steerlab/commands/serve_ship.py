"""``steerlab serve-ship``: run a scenario's ship in real time over UDP."""

from __future__ import annotations

import sys

EXAMPLES = """examples:
  steerlab serve-ship                                  # bundled default scenario (Esso), 127.0.0.1:47110
  steerlab serve-ship examples/scenarios/esso-pid.toml --bind 127.0.0.1:47110 --speedup 5
  steerlab serve-ship examples/scenarios/esso-pid.toml --key-file examples/data/demo-link.key   # HMAC on (the autopilot gets the same --key-file; make your own key once: python -c "import secrets; print(secrets.token_hex(32))" > link.key, chmod 600)
  STEERLAB_LINK_KEY=$(cat examples/data/demo-link.key) steerlab serve-ship examples/scenarios/esso-pid.toml --key-env STEERLAB_LINK_KEY
  steerlab serve-ship examples/scenarios/esso-pid.toml --nmea-to 127.0.0.1:10110 --signalk-to 127.0.0.1:8375
  steerlab serve-ship examples/scenarios/esso-pid.toml --signalk-ws 127.0.0.1:3000       # Signal K WebSocket stream

Then: steerlab autopilot --connect 127.0.0.1:47110 --controller pid --heading 20
Protocol, safety behaviour and NMEA/Signal K mapping: docs/runtime.md"""

DEFAULT_PORT = 47110


def add_link_security(p) -> None:
    g = p.add_argument_group("link security")
    g.add_argument("--key-file", help="file holding the shared HMAC-SHA256 key (>= 16 bytes)")
    g.add_argument("--key-env", help="environment variable holding the key (e.g. STEERLAB_LINK_KEY)")
    g.add_argument("--max-age", type=float, default=0.5,
                   help="reject datagrams whose sender stamp is older than this [wall s]; 0: off (default 0.5)")
    g.add_argument("--report-every", type=float, default=10.0, metavar="SECONDS",
                   help="print the rejected input (by reason) of each period in which there was some [wall s]; "
                        "0: only at exit (default 10)")
    g.add_argument("--allow-origin", action="append", default=[], metavar="URL",
                   help="also let browser pages of this origin (http[s]://HOST[:PORT]) use the WebSocket endpoints "
                        "(repeatable; default: loopback pages only)")


def allowed_origins(args) -> tuple:
    """The ``--allow-origin`` values, normalised (InputError naming the option if one is not an origin)."""
    from steerlab.runtime.access import normalise_origin

    return tuple(normalise_origin(o) for o in args.allow_origin)


def start_rejection_report(prog: str, args, sources: dict) -> None:
    """Start :func:`~steerlab.runtime.rejection_report.report_rejections` in the running loop
    (unless ``--quiet`` or ``--report-every 0``); it ends with the loop."""
    import asyncio

    from steerlab.runtime.rejection_report import report_rejections

    if not args.quiet and args.report_every > 0:
        task = asyncio.get_running_loop().create_task(report_rejections(prog, sources, args.report_every))
        _REPORTS.append(task)                 # keep a reference (the loop keeps only a weak one)


_REPORTS: list = []


def check_report_every(args) -> None:
    from steerlab.errors import require_finite_range

    require_finite_range("--report-every", args.report_every, 0.0, 86400.0)


def no_key_warning(prog: str, what: str) -> str:
    """The loud warning printed when the link runs without a key (HMAC off)."""
    return (f"{prog}: WARNING: HMAC off - no --key-file/--key-env, so {what}. "
            "Give both ends the same key (>= 16 bytes): --key-file FILE or --key-env NAME (docs/runtime.md).")


def freeze_startup_heap() -> None:
    """Move everything alive after start-up (modules, numba, compiled kernels) out of the GC's reach.

    A full collection of a runtime process walks ~170 000 such objects and blocks the event
    loop for ~0.1 s (measured); after ``gc.freeze()`` it walks only what the loop allocates
    since. Frozen objects are still freed by reference counting. No collection first: that
    would itself stall ~0.1 s (start-up garbage in cycles, if any, stays: a few kB).
    """
    import gc

    gc.freeze()


def register(sub, formatter_class) -> None:
    p = sub.add_parser("serve-ship", help="run a ship model in real time over UDP (state out, rudder orders in)",
                       description="Run the ship (+ steering gear, disturbances) of a scenario in real time "
                                   "(or --speedup times faster), publish its state every 0.05 s and accept "
                                   "rudder/rpm commands; if none arrives in time, hold then centre the rudder.",
                       epilog=EXAMPLES, formatter_class=formatter_class)
    p.add_argument("scenario", nargs="?", help="scenario TOML (default: the bundled default scenario)")
    p.add_argument("--bind", default=f"127.0.0.1:{DEFAULT_PORT}", help=f"HOST:PORT (default 127.0.0.1:{DEFAULT_PORT})")
    p.add_argument("--allow-remote", action="store_true", help="allow binding a non-loopback address")
    p.add_argument("--speedup", type=float, default=1.0, help="ship seconds per wall second (default 1)")
    p.add_argument("--duration", type=float, default=0.0, help="stop after this ship time [s]; 0: until Ctrl-C")
    p.add_argument("--publish-period", type=float, default=0.05, help="state period [s] (default 0.05)")
    p.add_argument("--publish", action="append", default=[], metavar="HOST:PORT",
                   help="also send every state here (repeatable)")
    p.add_argument("--cmd-timeout", type=float, default=1.0,
                   help="no valid command for longer: hold the last order (flagged) [s] (default 1)")
    p.add_argument("--centre-after", type=float, default=3.0,
                   help="no valid command for longer: rudder midships [s] (default 3)")
    p.add_argument("--nmea-to", metavar="HOST:PORT", help="send HDT, THS, ROT, RSA, RMC, VTG here (UDP)")
    p.add_argument("--signalk-to", metavar="HOST:PORT", help="send Signal K deltas here (UDP)")
    p.add_argument("--signalk-ws", metavar="HOST:PORT",
                   help="serve the Signal K stream here (WebSocket ws://HOST:PORT/signalk/v1/stream, read-only)")
    p.add_argument("--nmea-period", type=float, default=0.2, help="NMEA / Signal K period [s] (default 0.2)")
    p.add_argument("--session-lock", type=float, default=1.0,
                   help="while the autopilot holding the rudder keeps sending, refuse commands of any other "
                        "sender until it has been silent this long [s]; 0: off (default 1)")
    p.add_argument("--origin", default="54.5,18.9",
                   help="LAT,LON [deg] of the model origin for RMC (default 54.5,18.9: Gulf of Gdansk, at sea)")
    add_link_security(p)
    p.add_argument("--quiet", action="store_true")
    p.set_defaults(func=run)


def _origin(text: str):
    from steerlab.errors import InputError

    try:
        lat, lon = (float(v) for v in text.split(","))
    except ValueError:
        raise InputError("--origin", f"expected LAT,LON in degrees, got {text!r}") from None
    if not (-85.0 <= lat <= 85.0 and -180.0 <= lon <= 180.0):
        raise InputError("--origin", f"latitude must be in [-85, 85], longitude in [-180, 180]; got {text!r}")
    return lat, lon


def run(args) -> int:
    import asyncio

    from steerlab.errors import InputError
    from steerlab.runtime.keys import load_key
    from steerlab.runtime.ship_server import ShipServer, ShipServerConfig
    from steerlab.runtime.udp import is_loopback, parse_hostport
    from steerlab.sim.scenario import default_scenario, load_scenario

    bind = parse_hostport(args.bind, "--bind")
    if not is_loopback(bind[0]) and not args.allow_remote:
        raise InputError("--bind", f"{bind[0]} is not a loopback address; add --allow-remote to expose the ship")
    signalk_ws = parse_hostport(args.signalk_ws, "--signalk-ws") if args.signalk_ws else None
    if signalk_ws is not None and not is_loopback(signalk_ws[0]) and not args.allow_remote:
        raise InputError("--signalk-ws", f"{signalk_ws[0]} is not a loopback address; add --allow-remote to expose it")
    key = load_key(args.key_file, args.key_env)
    origins = allowed_origins(args)
    check_report_every(args)
    scenario = load_scenario(args.scenario) if args.scenario else default_scenario()
    cfg = ShipServerConfig(publish_period=args.publish_period, speedup=args.speedup,
                           cmd_timeout=args.cmd_timeout, centre_after=args.centre_after,
                           duration=args.duration, max_age=args.max_age, nmea_period=args.nmea_period,
                           session_lock=args.session_lock)
    server = ShipServer(scenario, cfg, key=key, bind=bind,
                        publish_to=[parse_hostport(a, "--publish") for a in args.publish],
                        nmea_to=parse_hostport(args.nmea_to, "--nmea-to") if args.nmea_to else None,
                        signalk_to=parse_hostport(args.signalk_to, "--signalk-to") if args.signalk_to else None,
                        origin=_origin(args.origin), signalk_ws=signalk_ws, allow_origins=origins)

    freeze_startup_heap()

    def started(s):
        if not args.quiet:
            host, port = s.address
            sk = ""
            if s.signalk_stream is not None:
                sk = ", Signal K ws://%s:%d/signalk/v1/stream" % tuple(s.signalk_stream.address)
            print(f"serve-ship: {scenario.ship.model} ({scenario.name}) on {host}:{port}, speedup {cfg.speedup:g}, "
                  f"state every {cfg.publish_period:g} s, HMAC {'on' if key else 'off'}{sk}; Ctrl-C stops",
                  file=sys.stderr, flush=True)
            if not key:
                print(no_key_warning("serve-ship", f"ANY process that can reach {host}:{port} can send rudder "
                                     "orders (the first sender holds the rudder while it keeps sending: "
                                     "--session-lock)"), file=sys.stderr, flush=True)
        sources = {"link": lambda: s.filter.counts, "rpm orders": lambda: s.rpm_counts}
        if s.signalk_stream is not None:
            sources["Signal K stream"] = lambda: s.signalk_stream.counts
        start_rejection_report("serve-ship", args, sources)

    try:
        stats = asyncio.run(server.run(started))
    finally:
        if not args.quiet:
            c = dict(server.filter.counts)
            print(f"serve-ship: t = {server.t_sim:.2f} s, published {server.stats.published}, "
                  f"commands {server.stats.commands}, link {c}", file=sys.stderr, flush=True)
            if server.rpm_error:
                print(f"serve-ship: last {server.rpm_error}", file=sys.stderr, flush=True)
    return 0 if stats is not None else 1
