r"""NMEA 0183 over UDP (pynmea2): the ship's sensor sentences out, a chart plotter's route in.

Sentences pynmea2 lacks are registered here as :class:`pynmea2.TalkerSentence` subclasses
(registration is by class name): ``THS`` (true heading and status), ``HTC`` (heading/track
control command) and ``HTD`` (heading/track control data), with the fields of IEC 61162-1
(2000) / NMEA 0183 v3: HTC has 13 fields, HTD those 13 plus rudder, off-heading and off-track
status and the vessel heading.

Out (ship server, every ``nmea_period``): ``HDT``, ``THS``, ``ROT`` (deg/min, < 0 bow to port),
``RSA`` (starboard/single rudder [deg], > 0 turns the bow to starboard = steerlab sign),
``RMC`` and ``VTG`` (position from the model origin on a sphere of radius 6 371 km, an
approximation fine for a few tens of km; course and speed over ground from ``u, v, psi``).
The autopilot can send ``HTD`` (its set course and rudder order).

In (autopilot): ``HDT``/``THS`` give the heading; ``APB`` ("heading to steer" if given,
else "bearing present position to destination"), ``RMB`` (true bearing to destination) and
``HTC`` (heading to steer) give the set course. A bearing is corrected for the sentence's own
cross-track error ``xte`` with direction to steer L/R: ``course = bearing ± atan(xte / lookahead)``.
``XTE`` is parsed and counted (APB and RMB carry the same error; XTE gives no course). Lines need
a valid checksum; anything else is counted as rejected, never raised.

Course source priority (:data:`COURSE_PRIORITY`): **APB > RMB > HTC**. A plotter that sends
both APB and RMB steers by APB alone (it carries the heading to steer and the leg's bearing);
RMB is used only while no fresh APB arrives, HTC only while neither does. Arrival (chart-plotter
convention): APB's "arrival circle entered" or "perpendicular passed" = ``A``, or RMB's arrival
status = ``A``, marks the destination waypoint as reached (``arrived``, ``dest``); the autopilot
then stops steering for it (:meth:`steerlab.runtime.autopilot.Autopilot.sample`).
"""

from __future__ import annotations

import math
import time

import pynmea2
from pynmea2 import TalkerSentence

from steerlab.units import KNOT, deg, rad
from steerlab.guidance.los import los_heading

EARTH_RADIUS = 6_371_000.0
MAX_LINE = 96
MAX_LINES = 32
TALKER = "II"
COURSE_PRIORITY = ("APB", "RMB", "HTC")   #: course sources, the first fresh one wins
DEFAULT_ORIGIN = (54.5, 18.9)
"""Default model origin (lat, lon) [deg]: open water in the Gulf of Gdansk, about 14 km off the
nearest coast (the former default, 54.5 N 18.55 E, is in Gdynia, on land)."""


class THS(TalkerSentence):
    """True heading and status (NMEA 0183 v3+): heading [deg], mode A/E/M/S/V (V = invalid)."""

    fields = (("Heading", "heading", float), ("Mode indicator", "mode"))


_HTC_FIELDS = (
    ("Override", "override"),                              # A in use, V not in use
    ("Commanded rudder angle", "rudder_angle", float),     # deg
    ("Commanded rudder direction", "rudder_direction"),    # L / R
    ("Selected steering mode", "steering_mode"),           # M, S, H, T, R
    ("Turn mode", "turn_mode"),                            # R radius, T rate, N none
    ("Commanded rudder limit", "rudder_limit", float),     # deg
    ("Commanded off-heading limit", "off_heading_limit", float),  # deg
    ("Commanded radius of turn", "radius_of_turn", float),  # nmi
    ("Commanded rate of turn", "rate_of_turn", float),     # deg/min
    ("Commanded heading to steer", "heading_to_steer", float),  # deg
    ("Commanded off-track limit", "off_track_limit", float),  # nmi
    ("Commanded track", "track", float),                   # deg
    ("Heading reference in use", "heading_reference"),     # T / M
)


class HTC(TalkerSentence):
    """Heading/track control command (13 fields, see the module docstring)."""

    fields = _HTC_FIELDS


class HTD(TalkerSentence):
    """Heading/track control data: HTC's fields + status and vessel heading."""

    fields = _HTC_FIELDS + (
        ("Rudder status", "rudder_status"),                # A within limits, V limit reached
        ("Off-heading status", "off_heading_status"),
        ("Off-track status", "off_track_status"),
        ("Vessel heading", "vessel_heading", float),       # deg
    )


def render(sentence_type: str, fields, talker: str = TALKER) -> str:
    """One sentence with its checksum and CRLF."""
    return TalkerSentence(talker, sentence_type, [str(f) for f in fields]).render() + "\r\n"


def _f(x: float, nd: int = 1) -> str:
    return f"{x:.{nd}f}"


def compass_field(angle: float, nd: int = 1) -> str:
    """A heading or course [rad] as an NMEA field in degrees, ``nd`` decimals, in [0, 360).

    The one place sentences format a direction: wrap first, round second and wrap the rounded
    text again, so a heading just west of north (-1e-9 rad, 359.99999 deg) is ``0.0``, never
    ``360.0`` (NMEA 0183 headings and courses are 0 to 359.9...).
    """
    text = f"{deg(angle) % 360.0:.{nd}f}"
    return f"{0.0:.{nd}f}" if float(text) >= 360.0 else text


def geo_position(x_n: float, y_e: float, origin) -> tuple[float, float]:
    """``(lat, lon)`` [deg] of a point ``x_n`` m north and ``y_e`` m east of ``origin``."""
    lat0, lon0 = origin
    lat = lat0 + deg(x_n / EARTH_RADIUS)
    lon = lon0 + deg(y_e / (EARTH_RADIUS * math.cos(rad(lat0))))
    return lat, ((lon + 180.0) % 360.0) - 180.0


def _ddmm(value: float, lat: bool) -> tuple[str, str]:
    hemi = ("N" if value >= 0 else "S") if lat else ("E" if value >= 0 else "W")
    v = abs(value)
    d = int(v)
    m = (v - d) * 60.0
    if m >= 59.99995:
        d, m = d + 1, 0.0
    return (f"{d:02d}{m:07.4f}" if lat else f"{d:03d}{m:07.4f}"), hemi


def state_sentences(state, origin=DEFAULT_ORIGIN, wall: float | None = None, talker: str = TALKER) -> list[str]:
    """HDT, THS, ROT, RSA, RMC and VTG lines for a :class:`~steerlab.runtime.protocol.State`."""
    wall = time.time() if wall is None else wall
    ut = time.gmtime(wall)
    hhmmss = time.strftime("%H%M%S", ut) + f".{int((wall % 1) * 100):02d}"
    ddmmyy = time.strftime("%d%m%y", ut)
    vn = state.u * math.cos(state.psi) - state.v * math.sin(state.psi)
    ve = state.u * math.sin(state.psi) + state.v * math.cos(state.psi)
    sog = math.hypot(vn, ve) / KNOT
    cog = math.atan2(ve, vn)
    lat, lon = geo_position(state.x_n, state.y_e, origin)
    la, ns = _ddmm(lat, True)
    lo, ew = _ddmm(lon, False)
    return [
        render("HDT", [compass_field(state.psi), "T"], talker),
        render("THS", [compass_field(state.psi, 2), "S"], talker),        # S = simulator mode
        render("ROT", [_f(deg(state.r) * 60.0, 2), "A"], talker),
        render("RSA", [_f(deg(state.delta)), "A", "", "V"], talker),
        render("RMC", [hhmmss, "A", la, ns, lo, ew, _f(sog, 2), compass_field(cog), ddmmyy, "", "", "S"], talker),
        render("VTG", [compass_field(cog), "T", "", "M", _f(sog, 2), "N", _f(sog * 1.852, 2), "K", "S"], talker),
    ]


def htd_sentence(set_course, rudder_cmd, heading, rudder_limit, off_heading_limit, off_course: bool,
                 talker: str = "AG") -> str:
    """The autopilot's HTD line (angles [rad]; ``None`` fields left empty)."""
    def d(x):
        return "" if x is None else compass_field(x)
    rud = "" if rudder_cmd is None else _f(abs(deg(rudder_cmd)))
    rdir = "" if rudder_cmd is None else ("R" if rudder_cmd >= 0 else "L")
    at_limit = rudder_cmd is not None and abs(rudder_cmd) >= rudder_limit - 1e-9
    return render("HTD", ["V", rud, rdir, "H", "N", _f(deg(rudder_limit)), _f(deg(off_heading_limit)),
                          "", "", d(set_course), "", "", "T", "V" if at_limit else "A",
                          "V" if off_course else "A", "A", d(heading)], talker)


def parse_line(line: str):
    """A pynmea2 sentence for a line with a valid checksum, or None (never raises)."""
    try:
        line = line.strip()
        if not line or len(line) > MAX_LINE or not line.startswith(("$", "!")):
            return None
        return pynmea2.parse(line, check=True)
    except Exception:
        return None


def _num(x):
    try:
        v = float(x)
    except (TypeError, ValueError):
        return None
    return v if math.isfinite(v) else None


def _xte_m(magnitude, unit: str | None) -> float | None:
    m = _num(magnitude)
    if m is None:
        return None
    return m * (1000.0 if unit == "K" else 1852.0)


def _corrected(bearing_deg, xte_m, steer, lookahead: float):
    """The simulator's LOS law (:func:`steerlab.guidance.los.los_heading`) on a plotter's leg
    course (or bearing) and cross-track error: steer ``R`` means the ship is to port of the
    track (``e < 0``), ``L`` to starboard."""
    b = _num(bearing_deg)
    if b is None:
        return None
    c = rad(b)
    if xte_m is not None and steer in ("L", "R") and lookahead > 0:
        e = abs(xte_m) if steer == "L" else -abs(xte_m)
        return float(los_heading(c, e, lookahead))
    return c


def _course_from(s, lookahead: float):
    kind = type(s).__name__
    if kind == "APB":
        if getattr(s, "status_gen", "A") == "V":
            return None
        if getattr(s, "heading_to_dest_type", "") == "T" and _num(getattr(s, "heading_to_dest", None)) is not None:
            return rad(_num(s.heading_to_dest))
        xte = _xte_m(s.cross_track_err_mag, s.cross_track_unit)
        # the LOS law steers by the leg's course (origin -> destination), as the simulator does
        if getattr(s, "bearing_type", "") == "T" and _num(getattr(s, "bearing_to_dest", None)) is not None:
            return _corrected(s.bearing_to_dest, xte, s.dir_steer, lookahead)
        if getattr(s, "bearing_pres_dest_type", "") != "T":
            return None
        return _corrected(s.bearing_pres_dest, xte, s.dir_steer, lookahead)
    if kind == "RMB":
        if getattr(s, "status", "A") != "A":
            return None
        return _corrected(s.dest_true_bearing, _xte_m(s.cross_track_error, "N"),
                          s.cte_correction_dir, lookahead)
    if kind == "HTC":
        if getattr(s, "override", "V") == "A" or getattr(s, "steering_mode", "") not in ("H", "S", "T"):
            return None
        h = _num(getattr(s, "heading_to_steer", None))
        return None if h is None else rad(h)
    return None


def _arrival(s) -> tuple[str, bool]:
    """``(destination waypoint id, reached?)`` of an APB/RMB sentence (``("", False)`` otherwise)."""
    kind = type(s).__name__
    dest = str(getattr(s, "dest_waypoint_id", "") or "")
    if kind == "APB":
        return dest, getattr(s, "arr_circle_entered", "") == "A" or getattr(s, "perp_passed", "") == "A"
    if kind == "RMB":
        return dest, getattr(s, "arrival_alarm", "") == "A"
    return "", False


def _heading_from(s):
    kind = type(s).__name__
    if kind == "HDT":
        return None if getattr(s, "hdg_true", "T") not in ("T", "") else _num(s.heading)
    if kind == "THS":
        return None if getattr(s, "mode", "V") == "V" else _num(s.heading)
    return None


def steering_inputs(data: bytes, lookahead: float = 500.0) -> dict:
    """Heading [rad] and set course [rad] (the last heading; the course of the highest-priority
    source in the datagram, :data:`COURSE_PRIORITY`), or None.

    ``courses`` has the last course of each source: ``{"APB": {"course", "dest", "arrived"}, ...}``;
    ``course_source`` names the source of ``course``. Counts ``accepted`` (parsed with a valid
    checksum) and ``rejected`` lines; never raises.
    """
    out = {"heading": None, "course": None, "course_source": None, "courses": {}, "xte_m": None,
           "accepted": 0, "rejected": 0}
    try:
        text = bytes(data).decode("ascii")
    except Exception:
        out["rejected"] += 1
        return out
    for line in text.splitlines()[:MAX_LINES]:
        if not line.strip():
            continue
        s = parse_line(line)
        if s is None:
            out["rejected"] += 1
            continue
        out["accepted"] += 1
        try:
            h = _heading_from(s)
            if h is not None:
                out["heading"] = rad(h % 360.0)
            c = _course_from(s, lookahead)
            if c is not None and math.isfinite(c):
                dest, arrived = _arrival(s)
                out["courses"][type(s).__name__] = {"course": c, "dest": dest, "arrived": arrived}
            if type(s).__name__ == "XTE":
                x = _xte_m(s.cross_track_err_dist, s.dist_units)
                if x is not None:
                    out["xte_m"] = x * (1.0 if s.correction_dir == "L" else -1.0)
        except Exception:
            out["rejected"] += 1
            out["accepted"] -= 1
    for kind in COURSE_PRIORITY:
        if kind in out["courses"]:
            out["course"], out["course_source"] = out["courses"][kind]["course"], kind
            break
    return out
