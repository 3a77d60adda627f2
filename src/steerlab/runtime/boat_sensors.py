r"""A boat's own sensors as the autopilot's measured state: position, speed, rate of turn, rudder.

On a boat there is no ship-state datagram (``serve-ship``); the autopilot measures what its laws
need from the sensors it is given (:class:`BoatSensors`):

* **heading**: ``nmea`` (HDT/THS/HDG/HDM) > ``signalk`` > ``state``; on a signed link ``state``
  alone while it is fresh (:mod:`~steerlab.runtime.heading_health`); alarms ``heading_nmea``...
* **rate of turn** (:data:`RATE_PRIORITY`): ``state`` > ``nmea`` (ROT) > ``signalk``
  (``navigation.rateOfTurn``) > ``heading``, the filtered derivative of the heading steered by
  (below); alarms ``rate_nmea``, ``rate_signalk``;
* **position** (:data:`POSITION_PRIORITY`): ``state`` > ``nmea`` (RMC, GGA) > ``signalk``
  (``navigation.position``), turned into metres north/east of the origin (``--origin``,
  serve-ship's default); alarms ``position_nmea``...;
* **speed** (:data:`SPEED_PRIORITY`): ``state`` (surge) > ``nmea`` (RMC, VTG speed over ground) >
  ``signalk`` (``navigation.speedOverGround``) > ``design``, the controller's design speed;
* **rudder angle** (:data:`RUDDER_PRIORITY`): ``nmea`` (RSA) > ``signalk``
  (``steering.rudderAngle``) > ``state`` > ``actuator`` (the driver's feedback) > ``order`` (the
  last order, assumed reached).

The state datagram, when fresh, comes first for rate, position and speed: it carries them all at
one instant with the heading, and on a signed link it is the authenticated source; the sensors
fill in without it. Speed over ground stands for the surge speed ``u`` and the sway ``v`` is taken
as 0 (a boat has no sway sensor); a law designed at a speed reads ``u`` from here, so a
speed-scheduled design follows the measured speed.

Yaw rate without a rate sensor: the heading's wrapped differences filtered by a first-order
low-pass (:class:`HeadingRate`, ``tau`` = :data:`RATE_FILTER_TAU`)::

    r_k = r_{k-1} + h / (tau + h) * (wrap(psi_k - psi_{k-1}) / h - r_{k-1})

(backward-Euler discretisation of ``tau r' + r = psi'``): a 0.1-deg compass step at 8 samples/s,
0.8 deg/s raw, becomes at most 0.1 deg/s. It is used only after two consecutive headings within
:data:`RATE_MAX_GAP` of each other; a longer gap restarts it.

Plausibility (:class:`~steerlab.runtime.source_health.SourceHealth`): a position that moves faster
than :data:`MAX_SPEED` (+ :data:`POSITION_TOLERANCE`), a speed outside [0, MAX_SPEED] or changing
faster than :data:`MAX_ACCEL`, a rate of turn beyond 45 deg/s or changing faster than
:data:`MAX_YAW_ACCEL`, a rudder angle moving faster than :data:`MAX_RUDDER_RATE` is implausible:
not used, alarm raised, the next source takes over.
"""

from __future__ import annotations

import math

from steerlab.angles import wrap_to_pi
from steerlab.runtime.source_health import FRESH, SourceHealth, select_source
from steerlab.units import rad

EARTH_RADIUS = 6_371_000.0        #: as serve-ship's NMEA position (:mod:`steerlab.runtime.nmea`) [m]
MAX_SPEED = 30.0                  #: fastest plausible boat [m/s] (58 kn)
POSITION_TOLERANCE = 50.0         #: GNSS jump allowed on top of MAX_SPEED * dt [m]
MAX_ACCEL = 3.0                   #: speed change limit [m/s^2]
SPEED_TOLERANCE = 1.0             #: on top of that [m/s]
MAX_YAW_RATE = rad(45.0)          #: rate of turn range [rad/s]
MAX_YAW_ACCEL = rad(30.0)         #: rate-of-turn change limit [rad/s^2]
YAW_RATE_TOLERANCE = rad(3.0)     #: on top of that [rad/s]
MAX_RUDDER_RATE = rad(90.0)       #: rudder angle change limit [rad/s] (hard over to hard over in < 1 s)
RUDDER_TOLERANCE = rad(2.0)       #: on top of that [rad]
RATE_FILTER_TAU = 1.0             #: heading-derivative low-pass time constant [s]
RATE_MAX_GAP = 1.0                #: headings further apart restart the derivative [s]

POSITION_PRIORITY = ("state", "nmea", "signalk")
SPEED_PRIORITY = ("state", "nmea", "signalk", "design")
RATE_PRIORITY = ("state", "nmea", "signalk", "heading")
RUDDER_PRIORITY = ("nmea", "signalk", "state", "actuator", "order")
SENSOR_SOURCES = ("nmea", "signalk")


def local_position(lat: float, lon: float, origin) -> tuple[float, float]:
    """``(x_n, y_e)`` [m] north and east of ``origin`` (lat, lon) [deg]: the inverse of
    :func:`steerlab.runtime.nmea.geo_position` (a sphere, fine for a few tens of km)."""
    lat0, lon0 = origin
    dlon = ((lon - lon0 + 180.0) % 360.0) - 180.0
    return (EARTH_RADIUS * math.radians(lat - lat0),
            EARTH_RADIUS * math.cos(math.radians(lat0)) * math.radians(dlon))


def _metres_between(a, b) -> float:
    """Distance [m] between two (lat, lon) [deg] (equirectangular, fine for jumps)."""
    x, y = local_position(a[0], a[1], b)
    return math.hypot(x, y)


class HeadingRate:
    """The filtered derivative of a heading [rad/s] (module docstring); ``value`` None until ready."""

    def __init__(self, tau: float = RATE_FILTER_TAU, max_gap: float = RATE_MAX_GAP):
        self.tau, self.max_gap = float(tau), float(max_gap)
        self.prev = None          # (psi, t)
        self.value = None

    def update(self, psi, t: float):
        if psi is None or not math.isfinite(psi):
            return self.value
        if self.prev is not None and 0.0 < t - self.prev[1] <= self.max_gap:
            h = t - self.prev[1]
            raw = wrap_to_pi(psi - self.prev[0]) / h
            self.value = raw if self.value is None else self.value + h / (self.tau + h) * (raw - self.value)
        elif self.prev is None or t - self.prev[1] > self.max_gap:
            self.value = None
        self.prev = (float(psi), float(t))
        return self.value


class BoatSensors:
    """Health and choice of the position, speed, rate-of-turn and rudder sources.

    Parameters
    ----------
    timeout : float
        A sensor reading older than this is stale [s] (the autopilot's ``nmea_timeout``).
    origin : (float, float)
        (lat, lon) [deg] that ``x_n = y_e = 0`` stands for.
    design_speed : float
        The controller's design speed [m/s] (the speed when nothing measures one).
    """

    def __init__(self, timeout: float, origin, design_speed: float = math.nan):
        self.origin = (float(origin[0]), float(origin[1]))
        self.design_speed = float(design_speed)
        self.sources = {
            "position": {n: SourceHealth(n, timeout, MAX_SPEED, POSITION_TOLERANCE, distance=_metres_between,
                                         quantity="position") for n in SENSOR_SOURCES},
            "speed": {n: SourceHealth(n, timeout, MAX_ACCEL, SPEED_TOLERANCE, valid_range=(0.0, MAX_SPEED),
                                      quantity="speed") for n in SENSOR_SOURCES},
            "rate": {n: SourceHealth(n, timeout, MAX_YAW_ACCEL, YAW_RATE_TOLERANCE,
                                     valid_range=(-MAX_YAW_RATE, MAX_YAW_RATE), quantity="rate of turn")
                     for n in SENSOR_SOURCES},
            "rudder": {n: SourceHealth(n, timeout, MAX_RUDDER_RATE, RUDDER_TOLERANCE,
                                       valid_range=(-math.pi / 2, math.pi / 2), quantity="rudder angle")
                       for n in SENSOR_SOURCES},
        }
        self.heading_rate = HeadingRate()
        self.chosen: dict = {}    # quantity -> source name of the last measure()

    def observe(self, quantity: str, source: str, value, t: float) -> bool:
        """A reading of ``quantity`` from ``source`` at ship time ``t``; True when usable."""
        return self.sources[quantity][source].observe(value, t)

    def observe_nmea(self, got: dict, t: float, counts) -> None:
        """The position, speed, rate and rudder of :func:`steerlab.runtime.nmea.steering_inputs`;
        an implausible one counted in ``counts``."""
        for quantity, key in (("position", "position"), ("speed", "sog"), ("rate", "rot"), ("rudder", "rudder")):
            if got.get(key) is not None and not self.observe(quantity, "nmea", got[key], t):
                counts["implausible"] += 1

    def observe_signalk(self, values: dict, t: float, counts) -> None:
        """The same from a Signal K input's checked values (:mod:`steerlab.runtime.signalk_input`)."""
        for quantity, path in (("position", "navigation.position"), ("speed", "navigation.speedOverGround"),
                               ("rate", "navigation.rateOfTurn"), ("rudder", "steering.rudderAngle")):
            if values.get(path) is not None and not self.observe(quantity, "signalk", values[path], t):
                counts["implausible"] += 1

    def status(self, t: float) -> dict:
        """``{quantity: {source: status}}`` of the sensor sources, and the source chosen last."""
        out = {q: {n: h.status(t) for n, h in srcs.items()} for q, srcs in self.sources.items()}
        out["chosen"] = dict(self.chosen)
        return out

    def measure(self, t: float, psi: float, state=None, actuator_rudder=None, last_order: float = 0.0,
                alarms=None) -> dict:
        """The measured state at ship time ``t`` [s] with heading ``psi`` [rad] (the one steered
        by): ``{"x_n", "y_e", "u", "v", "r", "delta"}`` (SI; position None when no source has
        one) and ``"sources"`` naming each one's source. ``state``: a fresh ship-state datagram
        (:class:`~steerlab.runtime.protocol.State`) or None."""
        derived = self.heading_rate.update(psi, t)
        st = state
        src = self.sources
        pos, pos_src = select_source(t, "position", POSITION_PRIORITY, src["position"],
                                     {"state": None if st is None else (st.x_n, st.y_e)}, alarms)
        if pos is not None and pos_src != "state":
            pos = local_position(pos[0], pos[1], self.origin)
        u, u_src = select_source(t, "speed", SPEED_PRIORITY, src["speed"],
                                 {"state": None if st is None else st.u,
                                  "design": self.design_speed if math.isfinite(self.design_speed) else 0.0}, alarms)
        r, r_src = select_source(t, "rate", RATE_PRIORITY, src["rate"],
                                 {"state": None if st is None else st.r, "heading": derived}, alarms)
        delta, d_src = select_source(t, "rudder", RUDDER_PRIORITY, src["rudder"],
                                     {"state": None if st is None else st.delta, "actuator": actuator_rudder,
                                      "order": float(last_order)}, alarms)
        self.chosen = {"position": pos_src, "speed": u_src, "rate": r_src, "rudder": d_src}
        return {"x_n": None if pos is None else float(pos[0]), "y_e": None if pos is None else float(pos[1]),
                "u": float(u), "v": st.v if u_src == "state" else 0.0, "r": 0.0 if r is None else float(r),
                "delta": float(delta), "sources": dict(self.chosen)}

    def fresh(self, quantity: str, source: str, t: float) -> bool:
        return self.sources[quantity][source].status(t) == FRESH
