"""``steerlab serve-ship``: run a scenario's ship in real time over UDP."""

from __future__ import annotations

import sys

EXAMPLES = """examples:
  steerlab serve-ship                                  # bundled default scenario (Esso), 127.0.0.1:47110
  steerlab serve-ship examples/scenarios/esso-pid.toml --bind 127.0.0.1:47110 --speedup 5
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
    p.add_argument("--origin", default="54.5,18.55", help="LAT,LON [deg] of the model origin for RMC")
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
    scenario = load_scenario(args.scenario) if args.scenario else default_scenario()
    cfg = ShipServerConfig(publish_period=args.publish_period, speedup=args.speedup,
                           cmd_timeout=args.cmd_timeout, centre_after=args.centre_after,
                           duration=args.duration, max_age=args.max_age, nmea_period=args.nmea_period)
    server = ShipServer(scenario, cfg, key=key, bind=bind,
                        publish_to=[parse_hostport(a, "--publish") for a in args.publish],
                        nmea_to=parse_hostport(args.nmea_to, "--nmea-to") if args.nmea_to else None,
                        signalk_to=parse_hostport(args.signalk_to, "--signalk-to") if args.signalk_to else None,
                        origin=_origin(args.origin), signalk_ws=signalk_ws)

    def started(s):
        if not args.quiet:
            host, port = s.address
            sk = ""
            if s.signalk_stream is not None:
                sk = ", Signal K ws://%s:%d/signalk/v1/stream" % tuple(s.signalk_stream.address)
            print(f"serve-ship: {scenario.ship.model} ({scenario.name}) on {host}:{port}, speedup {cfg.speedup:g}, "
                  f"state every {cfg.publish_period:g} s, HMAC {'on' if key else 'off'}{sk}; Ctrl-C stops",
                  file=sys.stderr, flush=True)

    try:
        stats = asyncio.run(server.run(started))
    finally:
        if not args.quiet:
            c = dict(server.filter.counts)
            print(f"serve-ship: t = {server.t_sim:.2f} s, published {server.stats.published}, "
                  f"commands {server.stats.commands}, link {c}", file=sys.stderr, flush=True)
    return 0 if stats is not None else 1
