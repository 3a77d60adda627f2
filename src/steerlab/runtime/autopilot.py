"""Autopilot client: a steerlab controller steering a ship server over UDP, with a watchdog.

Every ``sample_time`` (0.125 s of ship time by default, as in the berthing paper's client) the
autopilot takes the newest accepted state (:class:`~steerlab.runtime.link_filter.LinkFilter`:
duplicates, reordered, stale, forged and replayed datagrams never reach it), evaluates the
guidance and the controller kernel, and sends a rudder order. On packet loss the last state is
**held**; once no valid state has arrived for ``watchdog_timeout`` (default 1 s) the state is no
longer used: the ``link`` alarm is raised and the **safe action** is ordered (``midships`` or
``hold`` the last order). The **off-course** alarm is raised when ``|wrap(psi - psi_set)|``
exceeds its limit; after a course change it is armed only once the heading has come within
half the limit (:data:`OFF_COURSE_ARM_FRACTION`) of the new course with the reference settled, so a
commanded turn does not trip it, not even one exactly as large as the limit (armed at once by the
old rule "within the limit", the ship's momentum then carried it past the limit).

Guidance: a set course (``--heading``; ``course_reference`` slews the reference at the turn-rate
limit), a route (the simulator's LOS kernel ``guide(t, x, gd, gz, ref, h)`` called with the
received state, :mod:`steerlab.runtime.route`; the route is then the only course source) or a
chart plotter's APB/RMB/HTC sentences (:mod:`steerlab.runtime.nmea`). The heading may come
from NMEA HDT/THS instead of the state datagram, but on a signed link (a key) the signed state's
heading wins unless ``nmea_heading_over_signed`` (``--nmea-heading-over-signed``) is set. NMEA and
Signal K UDP input is rate limited per source (``input_rate``) and checked (range, status,
magnetic-only); rejections are counted per reason (``nmea_counts``, ``signalk_counts``).

Plotter course: one source steers, by priority APB > RMB > HTC (the first with a sentence younger
than ``nmea_timeout``; no alternation when a plotter sends both APB and RMB). **Arrival**: once
the winning source reports its destination waypoint reached (arrival circle or perpendicular
passed), the autopilot stops steering for that waypoint: it holds the set course in effect and
raises the ``arrival`` alarm, until the plotter names another destination (it advanced to the
next leg: steering resumes, the alarm clears). At a route's end the ship so keeps the last course
instead of circling the passed waypoint.

Clock: ship time ``t = speedup * (wall time since start)``; all periods and timeouts are in
ship seconds (freshness limits on datagram stamps are in wall seconds). Samples are due at
``t = k * sample_time``; after a stall (the process or the event loop blocked for more than a
sample) the missed samples are **skipped**, not replayed: one sample runs at once with the
newest state, at the latest due slot, so the sample clock keeps its phase and the ship never
gets a burst of orders computed from one old state (``skipped`` counts them).

From the simulator to a boat (issue 33): NMEA also comes over a serial port or TCP
(``nmea_streams``, :mod:`steerlab.runtime.nmea_streams`); magnetic compasses (HDG/HDM) and
magnetic plotter courses are turned true with the variation (:mod:`steerlab.runtime.nmea_magnetic`);
each heading source has a health state and the first fresh one of the priority steers
(:mod:`steerlab.runtime.heading_health`); an RSA rudder angle, while fresh, is the measured
rudder angle; orders go out through an actuator driver (:mod:`steerlab.runtime.actuator`,
the simulator link by default), and a fault it reports while engaged gives the ``actuator``
alarm and the safe state: the safe action ordered, disengaged.
"""

from __future__ import annotations

import asyncio
import csv
import math
import os
import time
from collections import Counter, deque
from dataclasses import dataclass

import numpy as np

from steerlab.angles import wrap_to_2pi, wrap_to_pi
from steerlab.errors import InputError, require_finite_range
from steerlab.guidance.reference_models import course_reference, course_schedule
from steerlab.guidance.reference_vector import REF_LEG, REF_PSI, REF_R, REF_XTE, initial_reference
from steerlab.runtime import protocol as P
from steerlab.runtime.alarms import ACTUATOR, ARRIVAL, LINK, OFF_COURSE, POSITION, SIGNALK_INPUT, AlarmBoard
from steerlab.runtime.heading_health import HEADING_PRIORITY, MAX_TURN_RATE, HeadingHealth, select_heading
from steerlab.runtime.link_filter import LinkFilter
from steerlab.runtime.rate_limit import RateLimiter
from steerlab.runtime.steering_modes import COMPASS, MODES, PLOTTER, ROUTE, available_modes, default_mode, mode_refusal
from steerlab.runtime.udp import local_bind_for, open_udp, send
from steerlab.units import deg, rad

SAFE_ACTIONS = ("midships", "hold")
OFF_COURSE_ARM_FRACTION = 0.5
"""After a course change the off-course alarm arms once the heading is within this fraction of
its limit of the new set course (a hysteresis band: a heading still swinging on from the turn,
within the limit, does not trip it)."""

LOG_COLUMNS = ("t", "wall", "t_sim", "state_age", "link_ok", "mode", "psi_deg", "r_deg_s",
               "delta_deg", "u", "x_n", "y_e", "psi_set_deg", "psi_ref_deg", "r_ref_deg_s",
               "delta_cmd_deg", "heading_source", "alarms", "accepted", "rejected", "xte_m", "leg",
               "nmea_rejected", "signalk_rejected")
"""CSV log columns (one row per sample; ship time ``t`` [s], degrees at this edge; ``xte_m``
cross-track error [m], > 0 to starboard of the leg, and ``leg`` only with a route; ``accepted``,
``rejected``: link datagrams so far; ``nmea_rejected``, ``signalk_rejected``: NMEA lines and
Signal K UDP deltas rejected so far, all reasons, rate limiting included)."""


def open_log(path) -> tuple:
    """``(file, csv.DictWriter)`` of the autopilot's CSV log at ``path``, opened to append: a
    restart continues the log of the runs before it (the ``wall`` column tells them apart),
    never truncates it. A new or empty file gets the header; a file whose first line is not
    this log's header (another program's file, a log of other columns) is refused with
    :class:`InputError` on ``--log``, untouched; a last row cut short (the process killed
    mid-write) is ended before the new rows."""
    header = ",".join(LOG_COLUMNS)
    try:
        with open(path, "rb") as f:
            first = f.readline().decode("utf-8", "replace").rstrip("\r\n")
            f.seek(0, os.SEEK_END)
            size = f.tell()
            if size:
                f.seek(size - 1)
            last = f.read(1)
    except FileNotFoundError:
        first, size, last = "", 0, b""
    except OSError as err:
        raise InputError("--log", f"cannot read {str(path)!r}: {err.strerror}") from None
    if size and first != header:
        raise InputError("--log", f"{str(path)!r} exists and is not an autopilot log (its first line is "
                                  f"{first[:40]!r}); give a new file, or the log of an earlier run to continue it")
    try:
        file = open(path, "a", newline="", encoding="utf-8")
    except OSError as err:
        raise InputError("--log", f"cannot write {str(path)!r}: {err.strerror}") from None
    if size and last != b"\n":
        file.write("\n")
    writer = csv.DictWriter(file, fieldnames=LOG_COLUMNS)
    if not size:
        writer.writeheader()
    return file, writer



def _csv_float(column: str, v: float) -> str:
    """A log value: 6 significant digits, but the wall clock [s since 1970] to the millisecond
    (``%.6g`` wrote ``1.79544e+09``, 10 s resolution)."""
    return f"{v:.3f}" if column == "wall" else f"{v:.6g}"


def _rejected(counts) -> int:
    """Rejections in an input's counts (every key but the normal traffic)."""
    return sum(v for k, v in counts.items() if k not in ("accepted", "ignored"))


@dataclass(frozen=True)
class AutopilotConfig:
    sample_time: float = 0.125          #: controller sample time [s]
    speedup: float = 1.0                #: ship seconds per wall second (match the server's)
    watchdog_timeout: float = 1.0       #: no valid state for longer: alarm + safe action [s]
    safe_action: str = "midships"       #: "midships" or "hold"
    off_course_limit: float = rad(10.0)  #: off-course alarm limit [rad]
    turn_rate: float = 0.0              #: reference turn-rate limit [rad/s]; 0: step
    max_age: float = 0.5                #: freshness limit on state stamps [wall s]; 0: off
    hello_period: float = 0.5           #: subscription refresh [s]
    rpm_cmd: float = math.nan           #: propeller order [rpm]; NaN: leave the ship's
    nmea_timeout: float = 2.0           #: NMEA heading/course older than this is not used [s]
    #: steer by a fresh NMEA HDT/THS heading even when the ship state is signed (HMAC); default:
    #: on a keyed link the signed state's heading wins over the unauthenticated NMEA one
    nmea_heading_over_signed: bool = False
    input_rate: float = 100.0           #: NMEA / Signal K UDP datagrams per source per ship second
    input_burst: float = 100.0          #: token bucket size of that limit [datagrams]
    xte_lookahead: float = 500.0        #: cross-track correction lookahead for RMB/XTE [m]
    variation: float = math.nan         #: configured magnetic variation [rad], > 0 east; NaN: none
    heading_max_rate: float = MAX_TURN_RATE  #: a heading source changing faster is implausible [rad/s]

    def validate(self) -> "AutopilotConfig":
        require_finite_range("--sample-time", self.sample_time, 0.001, 60.0)
        require_finite_range("--speedup", self.speedup, 0.01, 1000.0)
        require_finite_range("--watchdog", self.watchdog_timeout, 0.0, 3600.0, lo_open=True)
        if self.safe_action not in SAFE_ACTIONS:
            raise InputError("--safe-action", f"must be one of {SAFE_ACTIONS}, got {self.safe_action!r}")
        require_finite_range("--off-course-deg", self.off_course_limit, 0.0, math.pi, lo_open=True)
        require_finite_range("--turn-rate", self.turn_rate, 0.0, 1.0)
        require_finite_range("--max-age", self.max_age, 0.0, 3600.0)
        if not math.isnan(self.rpm_cmd):
            require_finite_range("--rpm", self.rpm_cmd, 0.0, 1000.0)   # 0: propeller stopped
        require_finite_range("--xte-lookahead", self.xte_lookahead, 1.0, 1e5)
        require_finite_range("--input-rate", self.input_rate, 0.0, 1e6)
        require_finite_range("--input-burst", self.input_burst, 1.0, 1e6)
        if not math.isnan(self.variation):
            from steerlab.runtime.nmea_magnetic import check_variation_option

            check_variation_option(deg(self.variation))
        require_finite_range("--heading-max-rate", self.heading_max_rate, 0.0, 10.0, lo_open=True)
        return self


class Autopilot:
    """The client. ``sample(t)`` is the whole per-sample logic (no sockets); ``run`` adds I/O.

    Parameters
    ----------
    controller : steerlab.runtime.controller_runtime.ControllerRuntime
    connect : (host, port)
        The ship server.
    heading : float or None
        Initial set course [rad]; None: the heading at engagement (or the route's course).
    route : steerlab.guidance.plan.GuidancePlan or None
        Route guidance (:func:`steerlab.runtime.route.route_guidance`): its kernel gives the
        reference every sample; the set course is its ``psi_ref``.
    key : bytes or None
        HMAC key (states must be signed; commands are signed).
    log_path : path or None
        CSV log, one row per sample (:data:`LOG_COLUMNS`).
    engaged : bool
        Start engaged (else standby: no rudder orders are sent).
    nmea_listen, signalk_listen : (host, port) or None
        UDP ports for NMEA 0183 sentences (HDT/THS heading; APB/RMB/XTE route) and Signal K
        deltas (``steering.autopilot.target.headingTrue``, ``steering.autopilot.state``).
    signalk_to, nmea_to : (host, port) or None
        Where to send the autopilot's Signal K delta / NMEA HTD sentence each sample.
    signalk_ws : (host, port) or None
        Serve the Signal K stream here (WebSocket, :mod:`steerlab.runtime.signalk_ws`): the
        ship state and autopilot paths each sample; PUT of the target heading and state.
    allow_origins : sequence of str
        Browser origins allowed on the Signal K stream besides loopback pages.
    nmea_streams : sequence
        NMEA inputs over byte streams, each a factory ``f(on_datagram)`` of an object with
        ``async start()`` / ``async close()`` (:mod:`steerlab.runtime.nmea_streams`: serial,
        TCP client, TCP server); their lines go to :meth:`on_nmea_datagram`.
    actuator : steerlab.runtime.actuator.Actuator or None
        The rudder drive; None: the simulator link (COMMAND datagrams to ``connect``).
    signalk_input : (host, port) or None
        Subscribe to this Signal K server's stream for heading, variation, position, rate of
        turn and rudder angle (:mod:`steerlab.runtime.signalk_input`).
    mode : str or None
        Steering mode at start (:mod:`steerlab.runtime.steering_modes`); None: what the
        arguments imply (``route`` with a route, else ``plotter`` with ``nmea_listen``, else
        ``compass``). Switchable at run time (:meth:`set_mode`).
    settings : steerlab.runtime.controller_settings.ControllerSettings or None
        Named profiles and gains changeable at run time (:meth:`configure`).
    origin : (float, float) or None
        (lat, lon) [deg] of ``x_n = y_e = 0`` for GNSS positions (default: serve-ship's).
    operator : steerlab.runtime.operator_session.OperatorSession or None
        The operator's token (reserved slots on the bridge page and the Signal K stream);
        None: a random one.
    state_file : path or None
        Where the set course, mode, profile and gains are kept across restarts
        (:mod:`steerlab.runtime.pilot_state`).
    plotter_input : bool or None
        Whether a chart plotter's course sentences can arrive (mode ``plotter`` available);
        None: when ``nmea_listen`` or an NMEA stream (serial, TCP) is given.
    """

    def __init__(self, controller, connect, config: AutopilotConfig = AutopilotConfig(),
                 heading=None, route=None, key=None, log_path=None, engaged=True,
                 nmea_listen=None, signalk_listen=None, signalk_to=None, nmea_to=None, bind=None,
                 signalk_ws=None, allow_origins=(), nmea_streams=(), actuator=None, signalk_input=None,
                 mode=None, settings=None, state_file=None, plotter_input=None, origin=None, operator=None):
        self.ctrl = controller
        self.connect = connect
        self.config = cfg = config.validate()
        if abs(cfg.sample_time - controller.h) > 1e-12:
            raise InputError("--sample-time", "differs from the controller's sample time")
        self.route_plan = route        # the route loaded (--route), followed in mode "route"
        self.plotter_input = ((nmea_listen is not None or bool(nmea_streams)) if plotter_input is None
                              else bool(plotter_input))
        self.steering_mode = default_mode(route is not None, self.plotter_input) if mode is None else mode
        why = mode_refusal(self.steering_mode, route is not None, self.plotter_input)
        if why is not None:
            raise InputError("--mode", why)
        self.route = route if self.steering_mode == ROUTE else None    # the route steering now
        self._mode_chosen = mode is not None     # by --mode or at run time (else the default)
        self.gz = None if route is None else route.gz0.copy()
        self.key = key
        self.sender = P.Sender(key)
        # states come at 20/s of ship time; allow 5x that per source before rate limiting
        self.filter = LinkFilter(P.TYPE_STATE, key=key, max_age=cfg.max_age,
                                 rate=100.0 * cfg.speedup, burst=50.0)
        self.log_path = log_path
        self.alarms = AlarmBoard()
        self.psi_set = None if heading is None else wrap_to_pi(float(heading))
        self.gd = None
        self.ref = initial_reference()
        self.want_engaged = bool(engaged)
        self.engaged = False           # controlling (engaged and reset on a valid state)
        self.off_course_armed = False
        self.latest: P.State | None = None
        self.latest_t = -math.inf
        self.last_cmd = 0.0
        self.cmd_sent = None
        self.mode = "standby"
        self.samples = 0
        self.skipped = 0               # samples skipped after stalls (not replayed)
        self.nmea_heading = None       # (psi [rad], t)
        self.nmea_course = None        # (psi_set [rad], t) of the last course sentence, any source
        self.nmea_courses: dict = {}   # source -> (psi_set [rad], t, dest, arrived)
        self.arrived: dict = {}        # source -> the destination id it reported reached
        self.course_source = None      # what the set course came from last ("APB", "RMB", "HTC", ...)
        self.steered = (None, None)    # (heading [rad] the last sample steered by, its source)
        # per reason (steerlab.runtime.nmea.REJECT_REASONS, rate_limited, ...), shown live in
        # status() and by the rejection report; ``accepted`` and ``ignored`` are normal traffic
        self.nmea_counts: Counter = Counter(accepted=0)
        self.signalk_counts: Counter = Counter(accepted=0)
        self.nmea_limiter = RateLimiter(cfg.input_rate * cfg.speedup, cfg.input_burst)
        self.signalk_limiter = RateLimiter(cfg.input_rate * cfg.speedup, cfg.input_burst)
        self.heading_health = {n: HeadingHealth(n, cfg.nmea_timeout, cfg.heading_max_rate) for n in ("nmea", "signalk")}
        self.signalk_input = signalk_input
        self.signalk_source = None
        self.signalk_nav: dict = {}    # the newest Signal K input values by path (position, rate of turn)
        self.rmc_variation = None      # (variation [rad], t) of the newest RMC that gave one
        self.rudder_feedback = None    # (rudder angle [rad], t) of the newest RSA
        from steerlab.runtime.boat_sensors import BoatSensors
        from steerlab.runtime.nmea import DEFAULT_ORIGIN

        # position, speed, rate of turn and rudder angle from the sensors, each with its health
        self.sensors = BoatSensors(cfg.nmea_timeout, DEFAULT_ORIGIN if origin is None else origin,
                                   getattr(controller, "design_speed", math.nan))
        self.measured: dict = {}       # the last sample's measured state and its sources
        self.nmea_stream_factories = tuple(nmea_streams)
        self.nmea_stream_inputs: list = []
        if actuator is None:
            from steerlab.runtime.actuator_sim import SimLinkActuator

            actuator = SimLinkActuator()
        if connect is None and getattr(actuator, "name", "") == "sim":
            raise InputError("--connect", "the sim actuator sends its orders to a ship server: give --connect "
                                          "HOST:PORT, or a rudder drive with --actuator")
        self.actuator = actuator
        self.actuator_safe = False     # latched by an actuator fault while engaged
        self.track: deque = deque(maxlen=4000)
        self.last_row: dict = {}
        self.nmea_listen = nmea_listen
        self.signalk_listen = signalk_listen
        self.signalk_to = signalk_to
        self.nmea_to = nmea_to
        self.signalk_ws = signalk_ws
        self.signalk_stream = None
        self.allow_origins = tuple(allow_origins)
        from steerlab.runtime.operator_session import OperatorSession

        #: the operator's token: a reserved slot on the bridge page and the Signal K stream
        self.operator = operator if operator is not None else OperatorSession()
        if settings is None:
            from steerlab.runtime.controller_settings import ControllerSettings

            settings = ControllerSettings(getattr(controller, "settings", {}))
        self.settings = settings
        self.state_file = state_file
        self.signalk_link = None       # SignedDeltaFilter on --signalk-listen when keyed (run)
        self.signalk_signer = None     # DeltaSigner of the status to --signalk-to when keyed (run)
        self.signalk_replies: deque = deque(maxlen=8)   # answers to the plug-in's last commands, in the status
        # loopback peer: loopback socket, same family; on a boat (no ship server) the outputs' peer
        peer = connect or signalk_to or nmea_to
        self.bind = bind or (local_bind_for(peer[0]) if peer else ("127.0.0.1", 0))
        self.transport = None
        self._t0 = None
        self._stop = None
        self._listeners = []
        self._log_file = None
        self._log = None
        # compile the guidance kernels now, not at the first steering sample (with a cold numba
        # cache that costs about a second, while the ship keeps moving)
        course_reference(0.0, course_schedule(0.0, [(0.0, 0.1)], cfg.turn_rate), np.zeros(2))
        if route is not None:
            route.guide(0.0, np.zeros(controller.nx), route.gd, route.gz0.copy(), initial_reference(),
                        cfg.sample_time)
        wrap_to_pi(0.0)

    # ------------------------------------------------------------ clock and inputs
    def clock(self) -> float:
        """Ship time [s] since :meth:`run` started."""
        if self._t0 is None:
            return 0.0
        return (time.monotonic() - self._t0) * self.config.speedup

    def on_state_datagram(self, data: bytes, addr=None, t: float | None = None) -> None:
        if self.connect is None:          # a boat: no ship server, a state datagram is forged
            self.filter.counts["no_ship_server"] += 1
            return
        msg, _ = self.filter.accept(data, time.time(), addr)
        if msg is not None:
            self.latest = msg.body
            self.latest_t = self.clock() if t is None else t

    def on_nmea_datagram(self, data: bytes, addr=None, t: float | None = None) -> None:
        """NMEA 0183 lines (:func:`steerlab.runtime.nmea.steering_inputs`: range, status and
        plausibility checks), after a per-source rate limit; every line counted by outcome."""
        from steerlab.runtime.nmea import steering_inputs

        if not self.nmea_limiter.allow(addr, time.monotonic()):
            self.nmea_counts["rate_limited"] += 1
            return
        from steerlab.runtime.nmea_magnetic import variation_in_effect

        t = self.clock() if t is None else t
        got = steering_inputs(data, self.config.xte_lookahead,
                              variation_in_effect(self.rmc_variation, self.config.variation, t))
        self.nmea_counts["accepted"] += got["accepted"]
        if got["ignored"]:
            self.nmea_counts["ignored"] += got["ignored"]
        self.nmea_counts.update(got["reasons"])
        if got["variation"] is not None:
            self.rmc_variation = (got["variation"], t)
        if got["rudder"] is not None:
            self.rudder_feedback = (got["rudder"], t)
        self.sensors.observe_nmea(got, t, self.nmea_counts)
        if got["heading"] is not None:
            if self.heading_health["nmea"].observe(got["heading"], t):
                self.nmea_heading = (got["heading"], t)
            else:
                self.nmea_counts["implausible"] += 1
        if got["course"] is not None:
            self.nmea_course = (got["course"], t)
        for kind, c in got.get("courses", {}).items():
            self.nmea_courses[kind] = (c["course"], t, c["dest"], c["arrived"])
            if c["arrived"]:
                self.arrived[kind] = c["dest"]
        if got.get("courses") and not self.plotter_input:
            # a chart plotter's course on an NMEA input not declared as one: the plotter mode is
            # there now, and taken unless the operator chose a mode
            self.plotter_input = True
            if not self._mode_chosen and self.steering_mode == COMPASS:
                self.steering_mode = PLOTTER

    def on_signalk_values(self, values: dict, t: float | None = None) -> None:
        """Checked values of the Signal K input (:func:`steerlab.runtime.signalk_input.input_values`):
        a true heading, or a magnetic one turned true with the variation in effect, goes to the
        ``signalk`` heading source; ``navigation.magneticVariation`` is held as an RMC's is; the
        rudder angle is rudder feedback."""
        from steerlab.runtime.nmea_magnetic import variation_in_effect

        t = self.clock() if t is None else t
        self.signalk_nav.update(values)
        if "navigation.magneticVariation" in values:
            self.rmc_variation = (values["navigation.magneticVariation"], t)
        psi = values.get("navigation.headingTrue")
        if psi is None and "navigation.headingMagnetic" in values:
            var = variation_in_effect(self.rmc_variation, self.config.variation, t)
            if var is None:
                self.signalk_counts["magnetic"] += 1
            else:
                psi = values["navigation.headingMagnetic"] + var
        if psi is not None and not self.heading_health["signalk"].observe(wrap_to_pi(psi), t):
            self.signalk_counts["implausible"] += 1
        if "steering.rudderAngle" in values:
            self.rudder_feedback = (values["steering.rudderAngle"], t)
        self.sensors.observe_signalk(values, t, self.signalk_counts)

    def on_signalk_datagram(self, data: bytes, addr=None, t: float | None = None) -> None:
        """A Signal K delta on ``--signalk-listen`` (the plug-in's commands): signed with the
        link's key when there is one (:mod:`steerlab.runtime.signalk_link`; else refused and
        counted by reason), then applied by :func:`steerlab.runtime.signalk.apply_commands`;
        the answer goes back in the next status delta (``steering.autopilot.steerlab.reply``)."""
        from steerlab.runtime.signalk import apply_commands, parse_delta

        if not self.signalk_limiter.allow(addr, time.monotonic()):
            self.signalk_counts["rate_limited"] += 1
            return
        t = self.clock() if t is None else t
        if self.key:
            if self.signalk_link is None:
                from steerlab.runtime.signalk_link import SignedDeltaFilter

                self.signalk_link = SignedDeltaFilter(self.key, max(self.config.max_age, 2.0))
            data, why = self.signalk_link.accept(data, time.time())
            if data is None:
                self.signalk_counts[why] += 1
                return
        values = parse_delta(data)
        if values is None:
            self.signalk_counts["malformed"] += 1
            return
        outcome, reply = apply_commands(self, values, t)
        self.signalk_counts[outcome] += 1
        if reply is not None:
            self.signalk_replies.append(reply)

    # ------------------------------------------------------------ operator actions
    def set_course(self, psi: float, t: float, source: str = "operator") -> None:
        """New set course [rad]; the reference slews to it at the turn-rate limit.

        ``source`` names where it came from (``operator``: bridge page, Signal K, ``--heading``;
        ``APB``/``RMB``/``HTC``: the chart plotter; ``heading``: the heading at engagement).
        Ignored while following a route (the route guidance is the only course source).
        """
        if self.route is not None:
            return
        self.course_source = source
        psi = wrap_to_pi(float(psi))
        if self.psi_set is not None and abs(wrap_to_pi(psi - self.psi_set)) < 1e-9 and self.gd is not None:
            return
        self.psi_set = psi
        start = self.ref[REF_PSI] if self.gd is not None else psi
        if self.gd is None and self._heading_now() is not None:
            start = self._heading_now()
        self.gd = course_schedule(float(start), [(max(t, 0.0), psi)], self.config.turn_rate)
        self.off_course_armed = False

    def course_refusal(self, t: float) -> str | None:
        """Why a set course from the operator (bridge page, Signal K PUT or delta) would not be
        applied at ship time ``t`` [s], or None when it would.

        With a route (``--route``) the route guidance is the only course source; with a fresh
        course from the chart plotter (``--nmea-listen``: APB/RMB/HTC, not one holding at a
        reached waypoint) the plotter's course replaces any other at the next sample.
        """
        if self.steering_mode == ROUTE:
            return ("mode route: following a route (--route), the route is the only course source; "
                    "target not applied (switch to mode compass to steer a set course)")
        if self.steering_mode != PLOTTER:
            return None
        from steerlab.runtime.nmea import COURSE_PRIORITY

        for kind in COURSE_PRIORITY:                     # the choice of _plotter_course, read only
            c = self.nmea_courses.get(kind)
            if c is None or t - c[1] > self.config.nmea_timeout:
                continue
            _, _, dest, arrived = c
            if arrived or (kind in self.arrived and dest == self.arrived[kind]):
                return None                              # holding: the set course stays in effect
            return (f"mode plotter: the chart plotter's {kind} course sets the course (--nmea-listen); "
                    "target not applied (switch to mode compass to steer a set course)")
        return None

    def adjust(self, ddeg: float, t: float) -> None:
        """Change the set course by ``ddeg`` degrees (the bridge page's ±1/±10 buttons)."""
        here = self._heading_now()
        base = self.psi_set if self.psi_set is not None else (here if here is not None else 0.0)
        self.set_course(base + rad(float(ddeg)), t)

    def engage(self, t: float) -> None:
        self.want_engaged = True

    def available_modes(self) -> tuple:
        """The steering modes this autopilot can switch to (:mod:`steerlab.runtime.steering_modes`)."""
        return available_modes(self.route_plan is not None, self.plotter_input)

    def set_mode(self, mode, t: float) -> str | None:
        """Switch the steering mode at ship time ``t`` [s]; returns why it cannot (nothing
        changed) or None. Leaving ``route`` holds the course the route was steering (the
        reference slews on from where it is); leaving ``plotter`` clears its arrival alarm."""
        why = mode_refusal(mode, self.route_plan is not None, self.plotter_input)
        if why is None:
            self._mode_chosen = True
        if why is not None or mode == self.steering_mode:
            return why
        prev, self.steering_mode = self.steering_mode, mode
        self.route = self.route_plan if mode == ROUTE else None
        if prev == ROUTE and self.psi_set is not None:
            start = float(self.ref[REF_PSI]) if self.gd is not None else self.psi_set
            self.gd = course_schedule(start, [(max(t, 0.0), self.psi_set)], self.config.turn_rate)
            self.course_source = "route (held)"
        elif prev == ROUTE:
            self.gd = None
        if mode != PLOTTER:
            self.alarms.set(ARRIVAL, False, t)
        self.off_course_armed = False
        return None

    def configure(self, t: float, profile: str | None = None, gains: dict | None = None) -> dict:
        """Change the controller's settings at ship time ``t`` [s]: a named ``profile`` (its
        gains replace any given before) and/or ``gains`` on top of the profile in effect
        (:mod:`steerlab.runtime.controller_settings`). The controller is rebuilt through the
        design path and starts its next sample as a fresh controller with those settings would
        (its state reset from the measured state, as at engagement). Bad settings raise
        :class:`InputError` naming the field; nothing changes then. Returns the settings in effect."""
        from steerlab.runtime.controller_settings import check_gains

        st = self.settings
        new_profile = st.profile if profile is None else profile
        new_gains = {} if profile is not None else dict(st.gains)
        if gains is not None:
            new_gains.update(check_gains(gains))
        applied = self.ctrl.reconfigure(st.resolve(new_profile, new_gains))
        st.profile, st.gains = new_profile, new_gains
        self.engaged = False             # the next sample resets the controller, as at engagement
        return applied

    def standby(self, t: float) -> None:
        self.want_engaged = False
        self.engaged = False

    def acknowledge(self, t: float, name: str | None = None) -> None:
        self.alarms.acknowledge(t, name)

    # ------------------------------------------------------------ one sample
    def _plotter_course(self, t: float):
        """``(course [rad] or None, source, holding)`` from the chart plotter's sentences.

        The first source in :data:`steerlab.runtime.nmea.COURSE_PRIORITY` with a fresh sentence
        wins. ``holding``: it is steering for a waypoint it reported reached (course None: keep
        the set course in effect).
        """
        from steerlab.runtime.nmea import COURSE_PRIORITY

        for kind in COURSE_PRIORITY:
            c = self.nmea_courses.get(kind)
            if c is None or t - c[1] > self.config.nmea_timeout:
                continue
            course, _, dest, arrived = c
            if arrived or (kind in self.arrived and dest == self.arrived[kind]):
                return None, kind, True
            self.arrived.pop(kind, None)          # a new destination: the plotter advanced
            return course, kind, False
        return None, None, False

    def _heading_now(self):
        """The newest ship state's heading [rad], else (a boat) the one the last sample steered
        by, else None."""
        if self.latest is not None:
            return self.latest.psi
        return self.steered[0]

    def _heading(self, t: float, state_fresh: bool = True):
        """``(heading [rad], source)``: a fresh NMEA HDT/THS heading, unless the ship state is
        signed (a key) and ``nmea_heading_over_signed`` is off: then the signed state's heading,
        so an unauthenticated sender on the NMEA port cannot steer the ship by a false heading.
        Without a fresh state (a boat: no ship server) the sensors' priority without ``state``."""
        if not state_fresh:
            order = tuple(n for n in HEADING_PRIORITY if n != "state")
            return select_heading(t, order, self.heading_health, None, self.alarms)
        order = HEADING_PRIORITY if (not self.key or self.config.nmea_heading_over_signed) else ("state",)
        return select_heading(t, order, self.heading_health, self.latest.psi, self.alarms)

    def _sensor_heading_fresh(self, t: float) -> bool:
        """Whether a sensor (NMEA, Signal K) gives a fresh heading at ``t``."""
        return any(h.heading(t) is not None for h in self.heading_health.values())

    def sample(self, t: float, now: float | None = None) -> dict:
        """Run one sample at ship time ``t`` (the clock reads ``now``, default ``t``).

        Returns the log row; the order is in ``cmd_sent`` (None: nothing to send).
        """
        cfg = self.config
        st = self.latest
        age = (t if now is None else now) - self.latest_t
        # no ship server (a boat): a state datagram is nobody's, never a measurement
        state_fresh = self.connect is not None and st is not None and age <= cfg.watchdog_timeout
        if self.connect is not None:
            # the ship server's link (its orders go over it too): its watchdog decides
            link_ok = state_fresh
            self.alarms.set(LINK, not link_ok and (st is not None or t > cfg.watchdog_timeout), t,
                            f"no valid ship state for more than {cfg.watchdog_timeout:g} s")
        else:
            # a boat: the sensors alone; steering needs a fresh heading from one of them
            link_ok = self._sensor_heading_fresh(t)
            if not link_ok:
                self._heading(t, False)          # the heading sources' own alarms, kept current
            self.alarms.set(LINK, not link_ok and t > cfg.watchdog_timeout, t,
                            "no fresh heading from any sensor (NMEA, Signal K)")
        if self.signalk_source is not None:
            self.alarms.set(SIGNALK_INPUT, self.signalk_source.lost(), t,
                            f"Signal K input {self.signalk_input[0]}:{self.signalk_input[1]}: connection lost, "
                            "reconnecting")
        cmd = None
        psi = src = None
        if link_ok:
            psi, src = self._heading(t, state_fresh)
            self.steered = (psi, src)
            m = self.measured = self.sensors.measure(t, psi, st if state_fresh else None,
                                                     self.actuator.rudder(t), self.last_cmd, self.alarms)
            has_pos = m["x_n"] is not None
            x = self.ctrl.measured_state(m["x_n"] if has_pos else 0.0, m["y_e"] if has_pos else 0.0, psi,
                                         m["u"], m["v"], m["r"], m["delta"])
            if has_pos:
                self.track.append((m["x_n"], m["y_e"]))
            self.alarms.set(POSITION, self.route is not None and not has_pos, t,
                            "route mode needs a position (state, NMEA RMC/GGA or Signal K): holding the set course")
            if self.route is not None and not has_pos:     # the route's last reference, held
                if self.psi_set is None:
                    self.psi_set = self.ref[REF_PSI] = psi
                self.ref[REF_R] = 0.0
            elif self.route is not None:       # the simulator's guidance kernel, same call
                self.route.guide(t, x, self.route.gd, self.gz, self.ref, cfg.sample_time)
                self.psi_set = float(self.ref[REF_PSI])
                self.gd = self.route.gd
                self.course_source = "route"
            else:
                course, source, holding = (self._plotter_course(t) if self.steering_mode == PLOTTER
                                           else (None, None, False))
                if course is not None:
                    self.set_course(course, t, source)
                if source is not None:               # a stale plotter leaves the alarm as it was
                    self.alarms.set(ARRIVAL, holding, t,
                                    f"{source}: destination waypoint reached, holding the last course")
                if self.psi_set is None:
                    self.set_course(psi, t, "heading")
                if self.gd is None:
                    self.set_course(self.psi_set, t, self.course_source or "operator")
                course_reference(t, self.gd, self.ref)
            if self.want_engaged and not self.engaged:
                self.ctrl.reset(x, self.ref)
                self.engaged = True
            if self.engaged:
                cmd = self.ctrl.update(t, x, self.ref)
                self.mode = "auto"
            else:
                self.mode = "standby"
            dev = abs(wrap_to_pi(psi - self.psi_set))
            if dev <= OFF_COURSE_ARM_FRACTION * cfg.off_course_limit \
                    and abs(wrap_to_pi(self.ref[REF_PSI] - self.psi_set)) < 1e-6:
                self.off_course_armed = True
            self.alarms.set(OFF_COURSE, self.off_course_armed and dev > cfg.off_course_limit, t,
                            f"heading off the set course by more than {deg(cfg.off_course_limit):g} deg")
        elif self.want_engaged:
            cmd = 0.0 if cfg.safe_action == "midships" else self.last_cmd
            self.mode = "safe"
            self.engaged = False          # reset the controller on the next valid state
        else:
            self.mode = "standby"
        cmd = self._actuator_guard(t, cmd)
        if cmd is not None:
            self.last_cmd = cmd
        self.cmd_sent = cmd
        self.samples += 1
        m = self.measured if link_ok else {}
        row = {
            "t": t, "wall": time.time(), "t_sim": st.t_sim if st else math.nan,
            "state_age": age if st else math.nan, "link_ok": int(link_ok), "mode": self.mode,
            "psi_deg": deg(psi) if psi is not None else math.nan,
            "r_deg_s": deg(m["r"]) if link_ok else math.nan,
            "delta_deg": deg(st.delta if state_fresh else m["delta"]) if link_ok else math.nan,
            "u": m["u"] if link_ok else math.nan,
            "x_n": m["x_n"] if link_ok and m["x_n"] is not None else math.nan,
            "y_e": m["y_e"] if link_ok and m["y_e"] is not None else math.nan,
            "psi_set_deg": deg(self.psi_set) if self.psi_set is not None else math.nan,
            "psi_ref_deg": deg(self.ref[REF_PSI]) if self.gd is not None else math.nan,
            "r_ref_deg_s": deg(self.ref[REF_R]) if self.gd is not None else math.nan,
            "delta_cmd_deg": deg(cmd) if cmd is not None else math.nan,
            "heading_source": src or "",
            "alarms": ";".join(a["name"] for a in self.alarms.snapshot() if a["active"]),
            "accepted": self.filter.counts["accepted"], "rejected": self.filter.rejected(),
            "xte_m": float(self.ref[REF_XTE]) if link_ok and self.route is not None else math.nan,
            "leg": int(self.ref[REF_LEG]) if link_ok and self.route is not None else "",
            "nmea_rejected": _rejected(self.nmea_counts), "signalk_rejected": _rejected(self.signalk_counts),
        }
        self.last_row = row
        return row

    def _actuator_guard(self, t: float, cmd):
        """The order after the actuator's faults: a fault while engaged (or while the safe state
        it caused lasts) gives the ``actuator`` alarm, the safe action and disengagement; the
        safe state ends (standby) when the faults clear."""
        faults = self.actuator.faults(t)
        self.alarms.set(ACTUATOR, bool(faults), t, "actuator: " + "; ".join(faults.values()))
        if faults and (self.engaged or self.actuator_safe):
            self.actuator_safe = True
            self.want_engaged = self.engaged = False
            self.mode = "safe"
            return 0.0 if self.config.safe_action == "midships" else self.last_cmd
        if self.actuator_safe:
            self.actuator_safe = False
            self.mode = "standby"
            return None
        return cmd

    def order(self):
        """The datagram body for the last sample's order, or None (standby: nothing sent)."""
        if self.cmd_sent is None:
            return None
        mode = (P.MODE_ENGAGED if self.mode == "auto" else 0) | (P.MODE_SAFE if self.mode == "safe" else 0)
        return P.Command(self.cmd_sent, self.config.rpm_cmd, mode)

    def _track_summary(self, max_points: int = 400) -> list:
        """The autopilot's own track history (x_n, y_e) [m], every k-th sample so that at most
        ``max_points`` (+ the newest) are sent: the page draws it whenever it was opened."""
        pts = list(self.track)
        if not pts:
            return []
        step = -(-len(pts) // max_points)
        out = pts[::step]
        if out[-1] != pts[-1]:
            out.append(pts[-1])
        return [[float(x), float(y)] for x, y in out]

    def status(self) -> dict:
        """Everything the bridge page shows (SI; the page converts to degrees).

        ``heading`` is the ship state's; ``steered_heading`` the one the last sample steered by
        and ``heading_source`` where it came from (``nmea``: HDT/THS, ``state``: the state
        datagram); ``course_source`` what set the set course (``operator``, ``APB``, ``route``...);
        ``track`` the autopilot's track history (:meth:`_track_summary`).
        """
        st = self.latest
        r = self.last_row
        # no ship state: the sensors' measurement of the last sample, but only while it was taken
        # (without a heading none is, and the last one would freeze on the page, rudder too)
        m = self.measured if r.get("link_ok") else {}
        boat = st is None and bool(m)
        live_rudder = self.actuator.rudder(r.get("t", 0.0))   # the drive's own feedback, or None
        return {
            "t": r.get("t", 0.0), "mode": self.mode, "link_ok": bool(r.get("link_ok", 0)),
            "state_age": r.get("state_age"),
            "heading": None if st is None else wrap_to_2pi(st.psi),
            "steered_heading": None if self.steered[0] is None else wrap_to_2pi(self.steered[0]),
            "heading_source": self.steered[1], "course_source": self.course_source,
            "set_course": None if self.psi_set is None else wrap_to_2pi(self.psi_set),
            "reference": None if self.gd is None else wrap_to_2pi(float(self.ref[REF_PSI])),
            "yaw_rate": m["r"] if boat else (None if st is None else st.r),
            "rudder": m["delta"] if boat else (live_rudder if st is None else st.delta),
            "rudder_cmd": self.cmd_sent, "speed": m["u"] if boat else (None if st is None else st.u),
            "position": ((None if m["x_n"] is None else [m["x_n"], m["y_e"]]) if boat
                         else (None if st is None else [st.x_n, st.y_e])),
            "alarms": self.alarms.snapshot(), "controller": self.ctrl.name,
            "link": {k: v for k, v in self.filter.counts.items()},
            "nmea": dict(self.nmea_counts), "signalk": dict(self.signalk_counts),
            "route": self.route_plan.route.tolist() if self.route_plan is not None else [],
            "track": self._track_summary(),
            "off_course_limit": self.config.off_course_limit,
            "ship_status": None if st is None else st.status,
            "heading_sources": {n: h.status(r.get("t", 0.0)) for n, h in self.heading_health.items()},
            "sensor_sources": self.sensors.status(r.get("t", 0.0)),
            "variation": self._variation_now(),
            "rudder_feedback": None if self.rudder_feedback is None else self.rudder_feedback[0],
            "actuator": {"name": self.actuator.name, "rudder": live_rudder,
                         "faults": self.actuator.faults(r.get("t", 0.0))},
            "steering_mode": self.steering_mode, "modes": list(self.available_modes()),
            "profile": self.settings.profile, "profiles": self.settings.names(),
            "gains": dict(self.settings.gains), "settings": dict(getattr(self.ctrl, "settings", {})),
        }

    def _variation_now(self):
        from steerlab.runtime.nmea_magnetic import variation_in_effect

        return variation_in_effect(self.rmc_variation, self.config.variation, self.last_row.get("t", 0.0))

    # ------------------------------------------------------------ I/O
    def _send_order(self, t: float) -> None:
        self.actuator.order(self.order(), t)
        if self.nmea_to is not None:
            from steerlab.runtime.nmea import htd_sentence

            line = htd_sentence(self.psi_set, self.cmd_sent, self.latest.psi if self.latest else None,
                                self.ctrl.delta_max, self.config.off_course_limit,
                                self.alarms.active(OFF_COURSE))
            send(self.transport, line.encode("ascii"), self.nmea_to)
        if self.signalk_to is not None:
            from steerlab.runtime.signalk import autopilot_delta_json

            wall = time.time()
            data = autopilot_delta_json(self, wall).encode()
            if self.key:                  # signed like the ship link: a forged status is refused
                if self.signalk_signer is None:
                    from steerlab.runtime.signalk_link import DeltaSigner

                    self.signalk_signer = DeltaSigner(self.key)
                data = self.signalk_signer.sign(data.decode(), wall)
            send(self.transport, data, self.signalk_to)
        if self.signalk_stream is not None:
            from steerlab.runtime.signalk import autopilot_values, state_values

            values = state_values(self.latest) if self.last_row.get("link_ok") and self.latest is not None else {}
            self.signalk_stream.publish({**values, **autopilot_values(self)}, time.time())

    def _open_log(self):
        if self.log_path is None:
            return
        self._log_file, self._log = open_log(self.log_path)

    def _write_log(self, row: dict) -> None:
        if self._log is not None:
            self._log.writerow({k: (_csv_float(k, v) if isinstance(v, float) else v) for k, v in row.items()})
            if self.samples % 16 == 0:
                self._log_file.flush()

    def _next_sample(self, k: int, elapsed: float) -> int:
        """The next sample's index after sample ``k``, ``elapsed`` sample periods since start.

        Normally ``k + 1``. After a stall, slots ``k + 1 .. due - 1`` have passed unserved:
        they are skipped (counted in ``skipped``) and slot ``due = floor(elapsed)``, the latest
        one already due, runs at once with the newest state; later ones keep the phase.
        """
        due = int(math.floor(elapsed))
        if due > k + 1:
            self.skipped += due - (k + 1)
            return due
        return k + 1

    def stop(self) -> None:
        if self._stop is not None:
            self._stop.set()

    async def run(self, duration: float = 0.0, started=None) -> "Autopilot":
        """Sample until ``duration`` ship seconds (0: until :meth:`stop`)."""
        loop = asyncio.get_running_loop()
        self._stop = asyncio.Event()
        self._open_log()
        keeper = None
        if self.state_file is not None:
            import sys

            from steerlab.runtime.pilot_state import StateKeeper

            keeper = StateKeeper(self.state_file, warn=lambda m: print(m, file=sys.stderr, flush=True))
        try:
            self.transport = await open_udp(self.on_state_datagram, self.bind)
            for addr, cb, field in ((self.nmea_listen, self.on_nmea_datagram, "--nmea-listen"),
                                    (self.signalk_listen, self.on_signalk_datagram, "--signalk-listen")):
                if addr is not None:
                    try:
                        self._listeners.append(await open_udp(cb, addr))
                    except OSError as err:
                        raise InputError(field, f"cannot bind {addr[0]}:{addr[1]}: {err.strerror}") from None
            for make in self.nmea_stream_factories:
                stream = make(self.on_nmea_datagram)
                self.nmea_stream_inputs.append(stream)
                await stream.start()
            await self.actuator.start(self)
            if self.signalk_input is not None:
                from steerlab.runtime.signalk_input import SignalKInput

                self.signalk_source = await SignalKInput(*self.signalk_input, self.on_signalk_values).start()
            if self.signalk_ws is not None:
                from steerlab.runtime.signalk import autopilot_put
                from steerlab.runtime.signalk_ws import SignalKStreamServer

                self.signalk_stream = await SignalKStreamServer(
                    *self.signalk_ws, on_put=lambda path, v: autopilot_put(self, path, v, self.clock()),
                    allow_origins=self.allow_origins, operator=self.operator).start()
            # the whole controller registry loaded now, not inside the loop: the first refused
            # setting's message (the scenario schema's) reads it, which blocked the loop ~2 s
            from steerlab.control.registry import CONTROLLERS

            self._registry_loaded = "" in CONTROLLERS
            self._t0 = time.monotonic()
            if started is not None:
                started(self)
            cfg = self.config
            wall_h = cfg.sample_time / cfg.speedup
            hello_every = max(1, round(cfg.hello_period / cfg.sample_time))
            t_start = loop.time()
            k = 0
            while not self._stop.is_set():
                t = k * cfg.sample_time
                if duration > 0 and t > duration + 1e-9:
                    break
                if k % hello_every == 0 and self.connect is not None:
                    send(self.transport, self.sender.pack(P.Hello(), time.time()), self.connect)
                row = self.sample(t, self.clock())
                self._send_order(t)
                self._write_log(row)
                if keeper is not None:
                    keeper.update(self)
                k = self._next_sample(k, (loop.time() - t_start) / wall_h)
                await asyncio.sleep(max(0.0, t_start + k * wall_h - loop.time()))
        finally:
            if keeper is not None:
                keeper.update(self, force=True)
            try:
                await self.actuator.close()
            except Exception:           # a port already gone: nothing more to release
                pass
            for stream in self.nmea_stream_inputs:
                await stream.close()
            if self.signalk_source is not None:
                await self.signalk_source.close()
            for tr in [self.transport, *self._listeners]:
                if tr is not None:
                    tr.close()
            if self._log_file is not None:
                self._log_file.close()
            if self.signalk_stream is not None:
                await self.signalk_stream.close()
        return self
