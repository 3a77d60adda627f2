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

In (autopilot): ``HDT``/``THS`` give the heading, and so do the magnetic compass sentences
``HDG``/``HDM`` turned true with the magnetic variation (its own field in HDG, the newest RMC's,
or the configured one: :mod:`steerlab.runtime.nmea_magnetic`); ``RSA`` gives the rudder angle
(feedback, starboard sensor, > 0 to starboard); ``APB ("heading to steer" if given,
else "bearing present position to destination"), ``RMB`` (true bearing to destination) and
``HTC`` (heading to steer) give the set course. A bearing is corrected for the sentence's own
cross-track error ``xte`` with direction to steer L/R: ``course = bearing ± atan(xte / lookahead)``.
``XTE`` is parsed and counted (APB and RMB carry the same error; XTE gives no course).

Checks (plausibility and range, :func:`steering_inputs`): a line needs a valid checksum; in the
sentences the autopilot reads, every direction must be a number in [0, 360] deg (a THS heading of
1e300 or an HTC course of 1e5 is rejected, as is NaN), a cross-track error at most
:data:`MAX_XTE_NMI`, status and mode letters from the standard's set (``V``, data invalid, rejects;
THS modes A/E/M/S), and the course a true one or a magnetic one with a known variation (an APB or HTC that gives only
magnetic bearings while no variation is known is rejected as ``magnetic``, never accepted and
ignored). Each rejected line is counted once under its
reason (:data:`REJECT_REASONS`), lines past :data:`MAX_LINES` in one datagram too; nothing raises.

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
from collections import Counter

import pynmea2
from pynmea2 import TalkerSentence

from steerlab.units import KNOT, deg, rad
from steerlab.guidance.los import los_heading
from steerlab.runtime.nmea_magnetic import MagneticRejected, compass_heading, rmc_variation, true_from_magnetic
from steerlab.runtime.nmea_nav import NAV_SENTENCES, NavRejected, nav_from_sentence

EARTH_RADIUS = 6_371_000.0
MAX_LINE = 96
MAX_LINES = 32
MAX_XTE_NMI = 1000.0   #: a larger cross-track error is implausible [nmi]
THS_VALID_MODES = ("A", "E", "M", "S")   #: autonomous, estimated, manual, simulator (V: invalid)
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
    """``x`` with ``nd`` decimals; a value that rounds to zero is ``0.0``, never ``-0.0`` (a
    rudder angle of -0.01 deg near midships)."""
    text = f"{x:.{nd}f}"
    return text[1:] if text.startswith("-") and float(text) == 0.0 else text


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


class Rejected(ValueError):
    """A sentence with a valid checksum whose content is not usable: ``reason`` names why
    (one of :data:`REJECT_REASONS`)."""

    def __init__(self, reason: str):
        super().__init__(reason)
        self.reason = reason


REJECT_REASONS = {
    "not_ascii": "the datagram is not ASCII text",
    "malformed": "not a sentence, a bad checksum, or longer than 96 characters",
    "too_many_lines": f"a line past the first {MAX_LINES} of one datagram",
    "missing_field": "the field the autopilot needs is empty",
    "bad_field": "a number that does not parse, or a status/mode/unit letter outside the standard's set",
    "out_of_range": f"a direction outside [0, 360] deg or a cross-track error above {MAX_XTE_NMI:g} nmi",
    "invalid_status": "the sender flags the data invalid (status or mode V)",
    "magnetic": "a magnetic direction only and no magnetic variation known (HDG's own, RMC's or --variation)",
    "variation_out_of_range": "a magnetic variation or compass deviation beyond +-30 deg",
    "not_heading_mode": "HTC with manual override in use or a steering mode other than heading/track (H, S, T)",
}
"""Why a line was rejected (the keys of the rejection counts, :func:`steering_inputs`)."""


def _direction(x, required: bool = True):
    """A direction field [deg] checked: a number in [0, 360] (``360`` = north), or None when
    empty and not ``required``."""
    if x is None or (isinstance(x, str) and not x.strip()):
        if required:
            raise Rejected("missing_field")
        return None
    v = _num(x)
    if v is None:
        raise Rejected("bad_field")
    if not 0.0 <= v <= 360.0:
        raise Rejected("out_of_range")
    return v % 360.0


def _status_ok(*flags) -> None:
    """Status letters: ``A`` valid; ``V`` (data invalid) rejects as ``invalid_status``; anything
    else as ``bad_field``; an empty status is taken as valid (older talkers leave it out)."""
    for f in flags:
        f = (f or "").strip()
        if f == "V":
            raise Rejected("invalid_status")
        if f not in ("A", ""):
            raise Rejected("bad_field")


def _xte_checked(magnitude, unit: str | None, steer) -> float | None:
    """Cross-track error [m] of a magnitude field and its unit (N nmi, K km), range-checked;
    None when empty. ``steer``, the direction to steer, must be ``L``, ``R`` or empty."""
    if magnitude is None or not str(magnitude).strip():
        return None
    m = _num(magnitude)
    if m is None or (unit or "N") not in ("N", "K") or (steer or "") not in ("L", "R", ""):
        raise Rejected("bad_field")
    if not 0.0 <= m <= MAX_XTE_NMI * (1.852 if unit == "K" else 1.0):
        raise Rejected("out_of_range")
    return m * (1000.0 if unit == "K" else 1852.0)


def _course_from(s, lookahead: float, variation=None):
    """The set course [rad] of an APB, RMB or HTC sentence; raises :class:`Rejected` with the
    reason when the sentence is flagged invalid, magnetic only, out of range or not a heading
    command (a plotter's course is never silently dropped). A magnetic direction is turned true
    with ``variation`` [deg, > 0 east] when it is known."""
    kind = type(s).__name__
    if kind == "APB":
        _status_ok(s.status_gen, s.status_cycle_lock)
        xte = _xte_checked(s.cross_track_err_mag, s.cross_track_unit, s.dir_steer)
        kinds = (s.heading_to_dest_type, s.bearing_type, s.bearing_pres_dest_type)
        if any(k not in ("T", "M", "", None) for k in kinds):
            raise Rejected("bad_field")
        def usable(kind_letter):
            return kind_letter == "T" or (kind_letter == "M" and variation is not None)

        def true_deg(value, kind_letter):
            return value if kind_letter == "T" else true_from_magnetic(value, variation)

        if usable(s.heading_to_dest_type) and _direction(s.heading_to_dest, False) is not None:
            return rad(true_deg(_direction(s.heading_to_dest), s.heading_to_dest_type))
        # the LOS law steers by the leg's course (origin -> destination), as the simulator does
        if usable(s.bearing_type) and _direction(s.bearing_to_dest, False) is not None:
            return _corrected(true_deg(_direction(s.bearing_to_dest), s.bearing_type), xte, s.dir_steer, lookahead)
        if usable(s.bearing_pres_dest_type):
            return _corrected(true_deg(_direction(s.bearing_pres_dest), s.bearing_pres_dest_type), xte,
                              s.dir_steer, lookahead)
        raise Rejected("magnetic" if "M" in kinds else "missing_field")
    if kind == "RMB":
        _status_ok(s.status)
        xte = _xte_checked(s.cross_track_error, "N", s.cte_correction_dir)
        return _corrected(_direction(s.dest_true_bearing), xte, s.cte_correction_dir, lookahead)
    if kind == "HTC":
        if (s.override or "V") not in ("A", "V") or (s.heading_reference or "T") not in ("T", "M"):
            raise Rejected("bad_field")
        if s.override == "A" or (s.steering_mode or "") not in ("H", "S", "T"):
            raise Rejected("not_heading_mode")
        if s.heading_reference == "M":
            if variation is None:
                raise Rejected("magnetic")
            return rad(true_from_magnetic(_direction(s.heading_to_steer), variation))
        return rad(_direction(s.heading_to_steer))
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


def _heading_from(s, variation=None):
    """True heading [deg] of an HDT, THS, HDG or HDM sentence, checked (raises
    :class:`Rejected` or :class:`~steerlab.runtime.nmea_magnetic.MagneticRejected`); None for
    other sentences. ``variation`` [deg, > 0 east]: the one in effect for HDG/HDM."""
    kind = type(s).__name__
    if kind in ("HDG", "HDM"):
        return compass_heading(s, _direction(s.heading), variation)[0]
    if kind == "HDT":
        if (s.hdg_true or "T") != "T":
            raise Rejected("bad_field")
        return _direction(s.heading)
    if kind == "THS":
        mode = (s.mode or "").strip()
        if mode == "V":
            raise Rejected("invalid_status")
        if mode not in THS_VALID_MODES:
            raise Rejected("bad_field")
        return _direction(s.heading)
    return None


def _xte_from(s):
    """Cross-track error [m] of an XTE sentence (> 0: steer left), checked; None if empty."""
    _status_ok(s.warning_flag, s.lock_flag)
    x = _xte_checked(s.cross_track_err_dist, s.dist_units, s.correction_dir)
    return None if x is None else x * (1.0 if s.correction_dir == "L" else -1.0)


def _rudder_from(s):
    """Rudder angle [deg] of an RSA sentence (starboard or single sensor; > 0 to starboard, the
    steerlab sign), checked: status ``A``, at most 90 deg either way."""
    _status_ok(s.rsa_starboard_status)
    if s.rsa_starboard is None or not str(s.rsa_starboard).strip():
        raise Rejected("missing_field")
    v = _num(s.rsa_starboard)
    if v is None:
        raise Rejected("bad_field")
    if abs(v) > 90.0:
        raise Rejected("out_of_range")
    return v


USED = ("HDT", "THS", "HDG", "HDM", "APB", "RMB", "HTC", "XTE", "RSA") + NAV_SENTENCES
"""The sentences the autopilot reads (RMC, GGA, VTG, ROT: :mod:`steerlab.runtime.nmea_nav`)."""


def steering_inputs(data: bytes, lookahead: float = 500.0, variation: float | None = None) -> dict:
    """Heading [rad] and set course [rad] (the last heading; the course of the highest-priority
    source in the datagram, :data:`COURSE_PRIORITY`), or None.

    ``courses`` has the last course of each source: ``{"APB": {"course", "dest", "arrived"}, ...}``;
    ``course_source`` names the source of ``course``. Every non-empty line is counted once:
    ``accepted`` (a sentence the autopilot reads, :data:`USED`, that passed the checks),
    ``ignored`` (a valid sentence of another type, e.g. GSV) or rejected: ``reasons`` counts the
    rejections by reason (:data:`REJECT_REASONS`: range, status, magnetic-only...), ``rejected``
    is their total. Lines past :data:`MAX_LINES` are counted (``too_many_lines``), not parsed.
    Never raises.

    ``variation`` [rad, > 0 east] is the magnetic variation in effect (a fresh RMC's or the
    configured one; None: unknown) for HDG/HDM and magnetic APB/HTC; an RMC line that carries
    one (counted ``accepted``) applies to the lines after it and is returned as ``variation``
    [rad]. ``rudder`` [rad] is the last RSA rudder angle (> 0 to starboard), or None.
    ``position`` ((lat, lon) [deg], RMC/GGA), ``sog`` (speed over ground [m/s], RMC/VTG) and
    ``rot`` (rate of turn [rad/s], ROT) are the last ones given
    (:func:`steerlab.runtime.nmea_nav.nav_from_sentence`), or None.
    """
    out = {"heading": None, "course": None, "course_source": None, "courses": {}, "xte_m": None,
           "rudder": None, "variation": None, "position": None, "sog": None, "rot": None,
           "accepted": 0, "ignored": 0, "rejected": 0, "reasons": Counter()}
    var_deg = None if variation is None else deg(variation)
    reasons = out["reasons"]
    try:
        text = bytes(data).decode("ascii")
    except Exception:
        reasons["not_ascii"] += 1
        out["rejected"] = 1
        return out
    lines = [ln for ln in text.splitlines() if ln.strip()]
    if len(lines) > MAX_LINES:
        reasons["too_many_lines"] += len(lines) - MAX_LINES
    for line in lines[:MAX_LINES]:
        s = parse_line(line)
        if s is None:
            reasons["malformed"] += 1
            continue
        kind = type(s).__name__
        if kind in NAV_SENTENCES:
            try:
                v = rmc_variation(s) if kind == "RMC" else None
                nav = nav_from_sentence(s)
            except (MagneticRejected, NavRejected) as why:
                reasons[why.reason] += 1
                continue
            except Exception:
                reasons["bad_field"] += 1
                continue
            if v is not None:
                var_deg = v
                out["variation"] = rad(v)
            out.update(nav)
            out["accepted"] += 1
            continue
        if kind not in USED:
            out["ignored"] += 1
            continue
        try:
            h = _heading_from(s, var_deg)
            c = _course_from(s, lookahead, var_deg)
            x = _xte_from(s) if kind == "XTE" else None
            rud = _rudder_from(s) if kind == "RSA" else None
        except (Rejected, MagneticRejected) as why:
            reasons[why.reason] += 1
            continue
        except Exception:                   # a field pynmea2 could not give: never raise
            reasons["bad_field"] += 1
            continue
        out["accepted"] += 1
        if h is not None:
            out["heading"] = rad(h)
        if c is not None and math.isfinite(c):
            dest, arrived = _arrival(s)
            out["courses"][kind] = {"course": c, "dest": dest, "arrived": arrived}
        if x is not None:
            out["xte_m"] = x
        if rud is not None:
            out["rudder"] = rad(rud)
    for kind in COURSE_PRIORITY:
        if kind in out["courses"]:
            out["course"], out["course_source"] = out["courses"][kind]["course"], kind
            break
    out["rejected"] = sum(reasons.values())
    return out
