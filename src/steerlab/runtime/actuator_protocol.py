r"""steerlab's line-based serial actuator protocol, version 1 (NMEA 0183 proprietary sentences).

A rudder drive (a hydraulic pump or linear drive with its controller and rudder-angle sensor)
speaks two sentences, ASCII lines ending CR LF, each with the NMEA 0183 checksum
(``*hh``, XOR of the characters between ``$`` and ``*``); manufacturer mnemonic ``STL``
(steerlab, not an NMEA-registered code)::

    autopilot -> actuator, every sample (8 per second):
      $PSTLO,<order>,<mode>*hh
        order  rudder order [deg], > 0 to starboard, one decimal; empty in standby
        mode   E = engaged: drive the rudder to the order
               S = standby: release the drive (clutch out), the helm is manual

    actuator -> autopilot, at least 5 per second:
      $PSTLF,<angle>,<status>,<current>*hh
        angle   measured rudder angle [deg], > 0 to starboard
        status  A = valid; V = rudder sensor invalid (angle not usable);
                C = over-current: the drive has stopped itself
        current motor current [A], optional (empty)

The actuator must release its drive (as on ``S``) when no valid ``$PSTLO`` has come for 1 s,
so a dead autopilot never leaves the rudder driven. Lines with a bad checksum or an unknown
sentence are counted and ignored by both ends. Example, engaged, 10 deg to port ordered, the
rudder at 4.2 deg to port, 3.1 A::

    $PSTLO,-10.0,E*23
    $PSTLF,-4.2,A,3.1*19

(:func:`render_order`, :func:`render_feedback` give the checksums.)
"""

from __future__ import annotations

import math
from typing import NamedTuple

import pynmea2

MANUFACTURER = "STL"
ORDER_TIMEOUT = 1.0
"""The actuator releases its drive when no valid order has come for this long [s]."""
STATUS_OK, STATUS_INVALID, STATUS_OVER_CURRENT = "A", "V", "C"


class Order(NamedTuple):
    angle: float | None     #: rudder order [rad], None in standby
    engaged: bool


class Feedback(NamedTuple):
    angle: float | None     #: measured rudder angle [rad] (None: not given or invalid)
    status: str             #: A, V or C
    current: float | None   #: [A]


def _render(kind: str, fields) -> str:
    return pynmea2.ProprietarySentence(MANUFACTURER, [kind, *[str(f) for f in fields]]).render() + "\r\n"


def _deg1(angle: float) -> str:
    text = f"{math.degrees(angle):.1f}"
    return "0.0" if text == "-0.0" else text


def render_order(angle: float | None, engaged: bool) -> str:
    """``$PSTLO`` line for an order [rad] (None or not ``engaged``: standby)."""
    if angle is None or not engaged:
        return _render("O", ["", "S"])
    return _render("O", [_deg1(angle), "E"])


def render_feedback(angle: float | None, status: str = STATUS_OK, current: float | None = None) -> str:
    """``$PSTLF`` line for a measured angle [rad]."""
    return _render("F", ["" if angle is None else _deg1(angle), status,
                         "" if current is None else f"{current:.1f}"])


def _parse(line, kind: str):
    try:
        text = line.decode("ascii") if isinstance(line, (bytes, bytearray)) else str(line)
        s = pynmea2.parse(text.strip(), check=True)
    except Exception:
        return None
    if not isinstance(s, pynmea2.ProprietarySentence) or s.manufacturer != MANUFACTURER:
        return None
    if not s.data or s.data[0] != kind:
        return None
    return s.data[1:]


def _angle(field: str):
    if not field.strip():
        return None
    try:
        v = float(field)
    except ValueError:
        raise ValueError("angle") from None
    if not math.isfinite(v) or abs(v) > 90.0:
        raise ValueError("angle")
    return math.radians(v)


def parse_order(line) -> Order | None:
    """An :class:`Order`, or None for anything else or a bad line (never raises)."""
    f = _parse(line, "O")
    if f is None or len(f) != 2 or f[1] not in ("E", "S"):
        return None
    try:
        a = _angle(f[0])
    except ValueError:
        return None
    if f[1] == "E" and a is None:
        return None
    return Order(a if f[1] == "E" else None, f[1] == "E")


def parse_feedback(line) -> Feedback | None:
    """A :class:`Feedback`, or None for anything else or a bad line (never raises)."""
    f = _parse(line, "F")
    if f is None or len(f) != 3 or f[1] not in (STATUS_OK, STATUS_INVALID, STATUS_OVER_CURRENT):
        return None
    try:
        a = _angle(f[0])
        cur = float(f[2]) if f[2].strip() else None
    except ValueError:
        return None
    if cur is not None and not (math.isfinite(cur) and cur >= 0.0):
        return None
    if f[1] == STATUS_OK and a is None:
        return None
    return Feedback(a if f[1] != STATUS_INVALID else None, f[1], cur)
