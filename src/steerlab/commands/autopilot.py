"""``steerlab autopilot``: steer a ship server with any steerlab controller, in real time."""

from __future__ import annotations

import math
import sys

EXAMPLES = """examples:
  steerlab autopilot --connect 127.0.0.1:47110 --controller pid --heading 20
  steerlab autopilot --connect 127.0.0.1:47110 --controller adrc --scenario examples/scenarios/los-route.toml --route examples/data/route.csv
  steerlab autopilot --connect 127.0.0.1:47110 --controller pid --scenario examples/scenarios/los-route.toml --route examples/data/route.csv --lookahead-L 5 --accept-radius 200
  steerlab autopilot --connect 127.0.0.1:47110 --controller pid --heading 0 --web 127.0.0.1:8080
  steerlab autopilot --connect 127.0.0.1:47110 --controller pid --nmea-listen 127.0.0.1:10111   # follow OpenCPN APB/RMB
  steerlab autopilot --connect 127.0.0.1:47110 --controller pid --signalk-ws 127.0.0.1:3000      # Signal K WebSocket

The controller is designed for the scenario's ship (--scenario, default: the bundled one); use
the same scenario as serve-ship. Every sample is logged to --log (CSV). A compass on a serial
port or NMEA over TCP (--nmea-serial /dev/ttyUSB0:4800 --variation -3.5, --nmea-tcp HOST:10110)
and a rudder drive (--actuator serial:/dev/ttyUSB1:38400); on a boat, without --connect, the sensors
alone (HDG/HDM, ROT, RMC/GGA/VTG or Signal K) measure: docs/runtime.md"""


def register(sub, formatter_class) -> None:
    from steerlab.commands.serve_ship import add_link_security

    p = sub.add_parser("autopilot", help="run a steerlab controller against a ship server over UDP",
                       description="Sample the ship server's state every 0.125 s, run guidance + a steerlab "
                                   "controller and send rudder orders; watchdog (alarm + safe action), "
                                   "off-course alarm, CSV log, optional NMEA 0183 / Signal K / bridge page.",
                       epilog=EXAMPLES, formatter_class=formatter_class)
    p.add_argument("--connect", metavar="HOST:PORT",
                   help="the ship server (serve-ship); leave it out on a boat: the sensors alone measure "
                        "(--nmea-serial/--nmea-tcp/--signalk-input) and --actuator drives the rudder")
    p.add_argument("--origin", default=None, metavar="LAT,LON",
                   help="where x_n = y_e = 0 is, for GNSS positions (RMC/GGA, Signal K) and --route in metres "
                        "(default 54.5,18.9, serve-ship's)")
    p.add_argument("--controller", help="controller name (default: the scenario's)")
    g = p.add_mutually_exclusive_group()
    g.add_argument("--heading", type=float, help="set course [deg] (default: heading at engagement)")
    g.add_argument("--route", help="CSV of waypoints x_n,y_e [m] (>= 2): follow it with the simulator's LOS "
                                   "guidance (docs/guidance.md)")
    p.add_argument("--lookahead-L", type=float, default=None,
                   help="LOS look-ahead Delta = n L, n in ship lengths (default: the scenario's guidance.lookahead_L)")
    p.add_argument("--accept-radius", type=float, default=None,
                   help="waypoint acceptance radius R [m] (default: the scenario's guidance.accept_radius_m, else L)")
    p.add_argument("--scenario", help="scenario TOML the controller is designed for (ship, speed, gear)")
    p.add_argument("--log", default="autopilot-log.csv", help="CSV log, one row per sample (default autopilot-log.csv)")
    p.add_argument("--speedup", type=float, default=1.0, help="must match serve-ship's (default 1)")
    p.add_argument("--duration", type=float, default=0.0, help="stop after this ship time [s]; 0: until Ctrl-C")
    p.add_argument("--sample-time", type=float, default=0.125, help="controller sample time [s] (default 0.125)")
    p.add_argument("--watchdog", type=float, default=1.0, help="no valid state for longer: alarm + safe action [s]")
    p.add_argument("--safe-action", choices=("midships", "hold"), default="midships")
    p.add_argument("--off-course-deg", type=float, default=10.0, help="off-course alarm limit [deg] (default 10)")
    p.add_argument("--turn-rate", type=float, default=None,
                   help="course-change rate limit [deg/s] (default: the scenario's guidance.rate_max_deg_s)")
    p.add_argument("--rpm", type=float, default=None, help="propeller order [rpm] (default: leave the ship's)")
    p.add_argument("--standby", action="store_true", help="start in standby (engage from the bridge page)")
    p.add_argument("--nmea-listen", metavar="HOST:PORT", help="UDP port for HDT/THS heading and APB/RMB/HTC course")
    p.add_argument("--nmea-to", metavar="HOST:PORT", help="send the autopilot's HTD here each sample")
    p.add_argument("--xte-lookahead", type=float, default=500.0, help="cross-track correction lookahead [m]")
    p.add_argument("--nmea-heading-over-signed", action="store_true",
                   help="steer by a fresh NMEA HDT/THS heading even when the ship state is signed (--key-file/--key-env); "
                        "default: the signed state's heading wins over unauthenticated NMEA")
    p.add_argument("--input-rate", type=float, default=100.0,
                   help="NMEA / Signal K UDP datagrams accepted per source per ship second (burst as many; "
                        "more are counted rate_limited; 0: no limit; default 100)")
    p.add_argument("--nmea-serial", action="append", default=[], metavar="PATH[:BAUD]",
                   help="read NMEA 0183 from a serial port (default 4800 baud; repeatable)")
    p.add_argument("--nmea-tcp", action="append", default=[], metavar="HOST:PORT",
                   help="read NMEA 0183 from a TCP talker (conventionally port 10110; reconnects; repeatable)")
    p.add_argument("--nmea-tcp-listen", metavar="HOST:PORT",
                   help="accept NMEA 0183 talkers on this TCP port (conventionally 10110)")
    p.add_argument("--variation", type=float, default=None,
                   help="magnetic variation [deg], > 0 east, within +-30: turns HDM/HDG and magnetic APB/HTC true "
                        "when neither the HDG sentence nor an RMC gives one")
    p.add_argument("--actuator", default="sim", metavar="NAME[:ARG]",
                   help="rudder drive: 'sim' (COMMAND datagrams to --connect, default), 'serial:PATH[:BAUD]' "
                        "(steerlab's line protocol, docs/runtime.md), or a steerlab.actuators entry point")
    p.add_argument("--signalk-input", metavar="HOST:PORT",
                   help="subscribe to this Signal K server's stream for heading (true or magnetic), variation, "
                        "position, rate of turn and rudder angle")
    p.add_argument("--signalk-listen", metavar="HOST:PORT", help="UDP port for Signal K deltas (target heading, state)")
    p.add_argument("--signalk-to", metavar="HOST:PORT", help="send Signal K autopilot deltas here")
    p.add_argument("--signalk-ws", metavar="HOST:PORT",
                   help="serve the Signal K stream here (WebSocket; ship and autopilot paths; PUT target heading/state)")
    p.add_argument("--web", metavar="HOST:PORT", help="serve the bridge page here (e.g. 127.0.0.1:8080); the "
                                                      "operator's address, with its token (#op=...), is printed at start")
    p.add_argument("--operator-token-env", metavar="NAME",
                   help="environment variable holding the operator's token (URL-safe, >= 16 characters; default: "
                        "a random one per run): a reserved slot on the bridge page and the Signal K stream")
    p.add_argument("--mode", help="steering mode at start: compass, route (needs --route) or plotter (needs "
                                  "--nmea-listen); default: route with --route, else plotter with --nmea-listen, "
                                  "else compass; switchable at run time (docs/runtime.md)")
    p.add_argument("--profiles", metavar="FILE.toml",
                   help="named controller profiles (one table of [controller] settings each, e.g. [calm], [rough]); "
                        "chosen at run time from the bridge page or Signal K")
    p.add_argument("--profile", help="profile at start (default: 'scenario', the scenario's own settings)")
    p.add_argument("--state-file", metavar="PATH",
                   help="keep the set course, mode, profile and gains here; a restart resumes them")
    add_link_security(p)
    p.add_argument("--quiet", action="store_true")
    p.set_defaults(func=run)


def _checked_settings(args, scenario):
    """``--mode``, ``--profiles`` and ``--profile`` checked before the controller compiles: the
    :class:`~steerlab.runtime.controller_settings.ControllerSettings` (every profile validated
    against the runtime scenario's schema)."""
    from steerlab.errors import InputError
    from steerlab.runtime.controller_runtime import runtime_scenario
    from steerlab.runtime.controller_settings import ControllerSettings, load_profiles
    from steerlab.runtime.steering_modes import mode_refusal

    if args.mode is not None:
        nmea_input = bool(args.nmea_listen or args.nmea_tcp or args.nmea_serial or args.nmea_tcp_listen)
        why = mode_refusal(args.mode, bool(args.route), nmea_input)     # as the autopilot decides (plotter_input)
        if why is not None:
            raise InputError("--mode", why)
    try:
        rt = runtime_scenario(scenario, args.controller, args.sample_time)
    except InputError as err:            # named as the user gave it
        if err.field == "controller.type" and args.controller is not None:
            raise InputError("--controller", err.message) from None
        raise
    settings = ControllerSettings(rt.model_dump()["controller"], load_profiles(args.profiles) if args.profiles else None)
    settings.check(rt)
    if args.profile is not None and args.profile not in settings.names():
        raise InputError("--profile", f"unknown profile {args.profile!r}; known: {', '.join(settings.names())}")
    return settings


def build_autopilot(args):
    """The :class:`~steerlab.runtime.autopilot.Autopilot` (and web bind) for parsed ``args``."""
    from steerlab.commands.serve_ship import allowed_origins, check_report_every
    from steerlab.errors import InputError, require_finite_range
    from steerlab.runtime.autopilot import Autopilot, AutopilotConfig
    from steerlab.runtime.controller_runtime import ControllerRuntime
    from steerlab.runtime.keys import load_key
    from steerlab.runtime.route import route_guidance
    from steerlab.runtime.udp import check_resolvable, is_loopback, parse_hostport
    from steerlab.sim.scenario import default_scenario, load_scenario
    from steerlab.units import rad

    from steerlab.commands.serve_ship import _origin

    connect = parse_hostport(args.connect, "--connect") if args.connect else None
    if connect is not None:
        check_resolvable(*connect, "--connect")
    if connect is not None and connect[1] == 0:
        raise InputError("--connect", "port must be in [1, 65535]")
    origin = _origin(args.origin) if args.origin is not None else None
    from steerlab.runtime.operator_session import OperatorSession

    operator = OperatorSession.from_env(args.operator_token_env)
    key = load_key(args.key_file, args.key_env)
    origins = allowed_origins(args)
    check_report_every(args)
    scenario = load_scenario(args.scenario) if args.scenario else default_scenario()
    if args.route:   # before the controller compiles: a missing file is one line, nothing else
        try:
            with open(args.route, "rb"):
                pass
        except OSError as err:
            raise InputError("--route", f"cannot read {args.route!r}: {err.strerror}") from None
    if args.heading is not None:
        require_finite_range("--heading", args.heading, -360.0, 360.0)
    streams, actuator, variation = boat_inputs(args)
    if connect is None and getattr(actuator, "name", "") == "sim":
        raise InputError("--connect", "give the ship server (--connect HOST:PORT), or on a boat a rudder drive "
                                      "(--actuator serial:PATH[:BAUD] or a steerlab.actuators entry point)")
    if connect is None and not (streams or args.nmea_listen or args.signalk_input):
        raise InputError("--connect", "without a ship server the autopilot needs a heading sensor: "
                                      "--nmea-serial, --nmea-tcp, --nmea-tcp-listen, --nmea-listen or --signalk-input")
    turn = scenario.guidance.rate_max_deg_s if args.turn_rate is None else args.turn_rate
    require_finite_range("--turn-rate", turn, 0.0, 30.0)
    require_finite_range("--off-course-deg", args.off_course_deg, 0.0, 180.0, lo_open=True)
    cfg = AutopilotConfig(sample_time=args.sample_time, speedup=args.speedup, watchdog_timeout=args.watchdog,
                          safe_action=args.safe_action, off_course_limit=rad(args.off_course_deg),
                          turn_rate=rad(turn), max_age=args.max_age,
                          rpm_cmd=math.nan if args.rpm is None else args.rpm, xte_lookahead=args.xte_lookahead,
                          nmea_heading_over_signed=args.nmea_heading_over_signed, input_rate=args.input_rate,
                          input_burst=max(1.0, args.input_rate),
                          variation=math.nan if variation is None else rad(variation)).validate()
    settings = _checked_settings(args, scenario)
    ctrl = ControllerRuntime(scenario, args.controller, args.sample_time)   # compiles on first use: checks first
    route = (route_guidance(scenario, ctrl.setup.ship, ctrl.setup.ps, args.route, args.lookahead_L,
                            args.accept_radius) if args.route else None)
    web = parse_hostport(args.web, "--web") if args.web else None
    if web is not None and not is_loopback(web[0]):
        print(f"autopilot: warning: the bridge page on {web[0]} is reachable from the network and has no login",
              file=sys.stderr)
    hp = lambda v, f: parse_hostport(v, f) if v else None  # noqa: E731
    signalk_ws = hp(args.signalk_ws, "--signalk-ws")
    if signalk_ws is not None and not is_loopback(signalk_ws[0]):
        print(f"autopilot: warning: the Signal K stream on {signalk_ws[0]} accepts course/state PUTs from the "
              "network without authentication", file=sys.stderr)
    for value, opt, what in ((args.nmea_listen, "--nmea-listen", "heading and course sentences"),
                             (args.signalk_listen, "--signalk-listen", "course and engage/standby deltas")):
        if value and not is_loopback(hp(value, opt)[0]):
            print(f"autopilot: warning: {opt} on {hp(value, opt)[0]} takes {what} from the network "
                  "without authentication", file=sys.stderr)
    ap = Autopilot(ctrl, connect, cfg, heading=None if args.heading is None else rad(args.heading),
                   route=route, key=key, log_path=args.log, engaged=not args.standby,
                   nmea_listen=hp(args.nmea_listen, "--nmea-listen"), nmea_to=hp(args.nmea_to, "--nmea-to"),
                   signalk_listen=hp(args.signalk_listen, "--signalk-listen"),
                   signalk_to=hp(args.signalk_to, "--signalk-to"), signalk_ws=signalk_ws,
                   allow_origins=origins, nmea_streams=streams, actuator=actuator,
                   signalk_input=hp(args.signalk_input, "--signalk-input"),
                   mode=args.mode, settings=settings, state_file=args.state_file, origin=origin,
                   operator=operator)
    if args.profile is not None:
        try:
            ap.configure(0.0, profile=args.profile)
        except InputError as err:
            raise InputError("--profile", f"profile {args.profile!r}: {err}") from None
    if args.state_file:
        from steerlab.runtime.pilot_state import read_state, resume

        doc, why = read_state(args.state_file)
        if why is not None:
            print(f"autopilot: warning: --state-file {args.state_file!r} not used: {why}", file=sys.stderr)
        elif doc is not None:
            for note in resume(ap, doc, keep_course=args.heading is not None or bool(args.route),
                               keep_mode=args.mode is not None, keep_profile=args.profile is not None):
                print(f"autopilot: warning: --state-file: {note}", file=sys.stderr)
    return ap, web


def boat_inputs(args):
    """``(nmea stream factories, actuator driver, variation [deg] or None)`` of ``args``
    (--nmea-serial, --nmea-tcp, --nmea-tcp-listen, --actuator, --variation), every one checked
    before the controller compiles: a missing device or a bad value is one line."""
    import os

    from steerlab.errors import InputError
    from steerlab.runtime.actuator import load_actuator
    from steerlab.runtime.nmea_magnetic import check_variation_option
    from steerlab.runtime.nmea_streams import NmeaSerialInput, NmeaTcpClient, NmeaTcpServer
    from steerlab.runtime.serial_port import parse_serial_spec
    from steerlab.runtime.udp import is_loopback, parse_hostport

    variation = check_variation_option(args.variation)
    streams = []
    for spec in args.nmea_serial:
        path, baud = parse_serial_spec(spec, "--nmea-serial")
        if not os.path.exists(path):
            raise InputError("--nmea-serial", f"no such device {path!r}")
        streams.append(lambda cb, path=path, baud=baud: NmeaSerialInput(path, baud, cb))
    for spec in args.nmea_tcp:
        host, port = parse_hostport(spec, "--nmea-tcp")
        if port == 0:
            raise InputError("--nmea-tcp", "port must be in [1, 65535] (NMEA over TCP: conventionally 10110)")
        streams.append(lambda cb, host=host, port=port: NmeaTcpClient(host, port, cb))
    if args.nmea_tcp_listen:
        host, port = parse_hostport(args.nmea_tcp_listen, "--nmea-tcp-listen")
        if not is_loopback(host):
            print(f"autopilot: warning: --nmea-tcp-listen on {host} takes heading and course sentences from the "
                  "network without authentication", file=sys.stderr)
        streams.append(lambda cb, host=host, port=port: NmeaTcpServer(host, port, cb))
    actuator = load_actuator(args.actuator)
    path = getattr(actuator, "path", None)
    if path is not None and not os.path.exists(path):
        raise InputError("--actuator", f"no such device {path!r}")
    return streams, actuator, variation


async def run_with_web(ap, web, duration, started=None):
    """Run the autopilot (and its bridge page, if ``web``) until ``duration`` or stop."""
    bridge = None
    if web is not None:
        from steerlab.runtime.web import BridgeServer

        bridge = await BridgeServer(ap, web[0], web[1], allow_origins=ap.allow_origins).start()
    try:
        await ap.run(duration, started=lambda a: started(a, bridge) if started else None)
    finally:
        if bridge is not None:
            await bridge.close()
    return ap


def run(args) -> int:
    import asyncio

    from steerlab.commands.serve_ship import freeze_startup_heap

    ap, web = build_autopilot(args)
    freeze_startup_heap()

    ran = []                                  # set once the autopilot is up (its ports bound)

    def started(a, bridge):
        ran.append(True)
        if not args.quiet:
            page = f", bridge page {a.operator.url(*bridge.address)}" if bridge else ""
            if a.signalk_stream is not None:
                page += (", Signal K ws://%s:%d/signalk/v1/stream" % tuple(a.signalk_stream.address)
                         + f" (operator: ?op={a.operator.token})")
            drive = getattr(a.actuator, "name", "?")
            to = f"{a.connect[0]}:{a.connect[1]}" if a.connect else f"actuator {drive} (sensors only)"
            print(f"autopilot: {a.ctrl.name} -> {to}, sample {a.config.sample_time:g} s, "
                  f"watchdog {a.config.watchdog_timeout:g} s ({a.config.safe_action}), log {args.log}{page}; "
                  "Ctrl-C stops", file=sys.stderr, flush=True)
            if not a.key:
                from steerlab.commands.serve_ship import no_key_warning

                print(no_key_warning("autopilot", "any process can forge ship states to this autopilot and, "
                                     "while it is silent, take the ship's rudder"), file=sys.stderr, flush=True)
        from steerlab.commands.serve_ship import start_rejection_report

        sources = {"link": lambda: a.filter.counts, "NMEA": lambda: a.nmea_counts,
                   "Signal K UDP": lambda: a.signalk_counts}
        if a.signalk_stream is not None:
            sources["Signal K stream"] = lambda: a.signalk_stream.counts
        if bridge is not None:
            sources["bridge page"] = lambda: bridge.counts
        start_rejection_report("autopilot", args, sources)

    try:
        asyncio.run(run_with_web(ap, web, args.duration, started))
    finally:
        if not args.quiet and ran:            # (a port that could not be bound: its error line alone)
            print(f"autopilot: {ap.samples} samples, mode {ap.mode}, {ap.skipped} skipped after stalls, "
                  f"link {dict(ap.filter.counts)}, NMEA {dict(ap.nmea_counts)}, Signal K UDP {dict(ap.signalk_counts)}, "
                  f"alarms raised {[n for _, n, w in ap.alarms.history if w == 'raised']}",
                  file=sys.stderr, flush=True)
    return 0
