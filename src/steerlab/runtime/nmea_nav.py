r"""Position, speed and rate of turn from NMEA 0183 (RMC, GGA, VTG, ROT), checked.

What a boat's GNSS receiver and rate-of-turn sensor send, read by the autopilot when there is no
ship-state datagram (:mod:`steerlab.runtime.boat_sensors`):

* ``RMC``: position and speed over ground (status ``A``; ``V`` rejects as ``invalid_status``;
  mode indicator ``N``, data not valid, too);
* ``GGA``: position (fix quality ``0``, no fix, rejects as ``invalid_status``);
* ``VTG``: speed over ground, knots (or km/h when the knots field is empty; mode ``N`` rejects);
* ``ROT``: rate of turn [deg/min], ``< 0`` bow to port (status ``A``).

Ranges: latitude within +-90 deg (minutes below 60), longitude within +-180 deg, speed over ground
within [0, :data:`MAX_SOG_KN`] kn, rate of turn within +-:data:`MAX_ROT_DEG_MIN` deg/min. A
field outside raises :class:`NavRejected` with the reason (the NMEA rejection counters' keys),
never another exception. Results in SI: degrees of latitude/longitude, m/s, rad/s.
"""

from __future__ import annotations

import math

from steerlab.units import KNOT, rad

MAX_SOG_KN = 60.0
"""Largest speed over ground accepted [kn]: beyond any displacement boat; a faster one is a
faulty receiver."""
MAX_ROT_DEG_MIN = 2700.0
"""Largest rate of turn accepted [deg/min] (45 deg/s, the heading plausibility limit)."""
NAV_SENTENCES = ("RMC", "GGA", "VTG", "ROT")


class NavRejected(ValueError):
    """A navigation sentence that cannot be used; ``reason`` is the rejection counter's key."""

    def __init__(self, reason: str):
        super().__init__(reason)
        self.reason = reason


def _num(x):
    if x is None or (isinstance(x, str) and not x.strip()):
        return None
    try:
        v = float(x)
    except (TypeError, ValueError):
        raise NavRejected("bad_field") from None
    if not math.isfinite(v):
        raise NavRejected("bad_field")
    return v


def _coordinate(value, hemi, lat: bool):
    """``ddmm.mmmm`` (latitude) or ``dddmm.mmmm`` (longitude) and N/S/E/W as signed degrees."""
    v = _num(value)
    if v is None:
        raise NavRejected("missing_field")
    if v < 0 or hemi not in (("N", "S") if lat else ("E", "W")):
        raise NavRejected("bad_field")
    d, m = divmod(v, 100.0)
    if m >= 60.0:
        raise NavRejected("out_of_range")
    out = d + m / 60.0
    if out > (90.0 if lat else 180.0):
        raise NavRejected("out_of_range")
    return -out if hemi in ("S", "W") else out


def _position(s):
    return (_coordinate(s.lat, s.lat_dir, True), _coordinate(s.lon, s.lon_dir, False))


def _sog(knots):
    if knots is None:
        return None
    if not 0.0 <= knots <= MAX_SOG_KN:
        raise NavRejected("out_of_range")
    return knots * KNOT


def nav_from_sentence(s) -> dict:
    """``{"position": (lat, lon) [deg], "sog": [m/s], "rot": [rad/s]}`` (the keys the sentence
    gives) of an RMC, GGA, VTG or ROT sentence; ``{}`` for any other; raises
    :class:`NavRejected` for one that is flagged invalid, incomplete or out of range."""
    kind = type(s).__name__
    if kind == "RMC":
        if (s.status or "").strip() != "A":
            raise NavRejected("invalid_status" if (s.status or "").strip() in ("V", "") else "bad_field")
        if (getattr(s, "mode_indicator", "") or "").strip() == "N":
            raise NavRejected("invalid_status")
        out = {"position": _position(s)}
        sog = _sog(_num(s.spd_over_grnd))
        if sog is not None:
            out["sog"] = sog
        return out
    if kind == "GGA":
        q = _num(s.data[5] if len(s.data) > 5 else None)
        if q is None:
            raise NavRejected("missing_field")
        if q == 0:
            raise NavRejected("invalid_status")
        return {"position": _position(s)}
    if kind == "VTG":
        if (getattr(s, "faa_mode", "") or "").strip() == "N":
            raise NavRejected("invalid_status")
        kn = _num(s.data[4] if len(s.data) > 4 else None)
        if kn is None:
            kmh = _num(s.data[6] if len(s.data) > 6 else None)
            kn = None if kmh is None else kmh / 1.852
        if kn is None:
            raise NavRejected("missing_field")
        return {"sog": _sog(kn)}
    if kind == "ROT":
        st = (s.status or "").strip()
        if st == "V":
            raise NavRejected("invalid_status")
        if st not in ("A", ""):
            raise NavRejected("bad_field")
        v = _num(s.rate_of_turn)
        if v is None:
            raise NavRejected("missing_field")
        if abs(v) > MAX_ROT_DEG_MIN:
            raise NavRejected("out_of_range")
        return {"rot": rad(v / 60.0)}
    return {}
