"""Signal K delta messages (JSON, SI units) for the ship state and the autopilot.

Paths (Signal K specification, ``vessels.self`` context; radians, rad/s, m/s)::

    navigation.headingTrue                   psi wrapped to [0, 2 pi)
    navigation.rateOfTurn                    r (> 0 to starboard)
    navigation.speedThroughWater             u
    steering.rudderAngle                     delta (> 0 turns to starboard, as steerlab)
    steering.rudderAngleTarget               the rudder order in effect / commanded
    steering.autopilot.target.headingTrue    the set course
    steering.autopilot.state                 "auto" | "standby" | "alarm"

A delta is ``{"context": "vessels.self", "updates": [{"source": {...}, "timestamp": ISO 8601,
"values": [{"path": ..., "value": ...}, ...]}]}``, one JSON document per UDP datagram (or
WebSocket message, :mod:`steerlab.runtime.signalk_ws`). :func:`parse_delta` accepts exactly that
shape and returns ``{path: value}`` or None (never raises). :func:`autopilot_put` applies a
Signal K PUT request to the autopilot (the writable paths: :data:`WRITABLE`); a set course the
autopilot would not apply (a route or a chart plotter sets the course) is answered 409 with the
reason, and the autopilot's status deltas over UDP carry that reason as :data:`TARGET_REFUSED`
(what the Signal K plug-in answers its own requests with).
"""

from __future__ import annotations

import json
import math
import time
import uuid

from steerlab.angles import wrap_to_2pi
from steerlab.runtime.path_glob import PathPattern

SOURCE = {"label": "steerlab", "type": "steerlab-runtime"}
MAX_DELTA_BYTES = 65536
TARGET_HEADING = "steering.autopilot.target.headingTrue"
AUTOPILOT_STATE = "steering.autopilot.state"
WRITABLE = (TARGET_HEADING, AUTOPILOT_STATE)   #: paths a PUT may set on the autopilot
TARGET_REFUSED = "steering.autopilot.steerlab.targetRefused"
"""steerlab's own path in the status deltas sent to ``--signalk-to``: why a target heading would
not be applied now (a string), left out while it would be."""
SELF_URN = "urn:mrn:signalk:uuid:" + str(uuid.uuid5(uuid.NAMESPACE_URL, "steerlab:self"))
"""The self vessel's identity (Signal K 1.7 "Vessel identity": a URN; fixed, as steerlab serves one vessel)."""
SELF_ID = "vessels." + SELF_URN      #: what ``GET /signalk/v1/api/self`` and the stream's hello give
SELF_ALIASES = ("vessels.self", SELF_ID)


def is_self_context(ctx) -> bool:
    """True if a subscription context names the self vessel: ``vessels.self``, :data:`SELF_ID`,
    or a pattern matching one of them (``*`` = any characters: ``*``, ``vessels.*``)."""
    if not isinstance(ctx, str) or not 0 < len(ctx) <= 256:
        return False
    pat = PathPattern(ctx)                   # linear time: no user-built regex
    return any(pat.match(a) for a in SELF_ALIASES)


def iso_time(wall: float) -> str:
    return time.strftime("%Y-%m-%dT%H:%M:%S", time.gmtime(wall)) + f".{int((wall % 1) * 1000):03d}Z"


def delta(values: dict, wall: float | None = None) -> dict:
    """A delta message for ``{path: value}`` (None values are left out)."""
    wall = time.time() if wall is None else wall
    return {"context": "vessels.self",
            "updates": [{"source": SOURCE, "timestamp": iso_time(wall),
                         "values": [{"path": p, "value": v} for p, v in values.items() if v is not None]}]}


def state_values(state) -> dict:
    return {"navigation.headingTrue": wrap_to_2pi(state.psi), "navigation.rateOfTurn": state.r,
            "navigation.speedThroughWater": state.u, "steering.rudderAngle": state.delta,
            "steering.rudderAngleTarget": state.delta_cmd}


def state_delta_json(state, wall: float | None = None) -> str:
    return json.dumps(delta(state_values(state), wall))


def autopilot_values(ap) -> dict:
    mode = ap.mode
    return {"steering.autopilot.state": "alarm" if mode == "safe" else mode,
            "steering.autopilot.target.headingTrue": None if ap.psi_set is None else wrap_to_2pi(ap.psi_set),
            "steering.rudderAngleTarget": ap.cmd_sent}


def autopilot_delta_json(ap, wall: float | None = None) -> str:
    """The status delta sent over UDP (``--signalk-to``): :func:`autopilot_values` and, while a
    target heading would not be applied, :data:`TARGET_REFUSED` with the reason."""
    return json.dumps(delta({**autopilot_values(ap), TARGET_REFUSED: ap.course_refusal(ap.clock())}, wall))


def parse_delta(data) -> dict | None:
    """``{path: value}`` from a delta message (bytes or str), or None if it is not one."""
    try:
        if isinstance(data, (bytes, bytearray)):
            if len(data) > MAX_DELTA_BYTES:
                return None
            data = bytes(data).decode("utf-8")
        if len(data) > MAX_DELTA_BYTES:
            return None
        msg = json.loads(data)
        if not isinstance(msg, dict) or not isinstance(msg.get("updates"), list):
            return None
        ctx = msg.get("context", "vessels.self")
        if ctx not in ("vessels.self",) and not (isinstance(ctx, str) and ctx.startswith("vessels.")):
            return None
        out = {}
        for upd in msg["updates"]:
            if not isinstance(upd, dict) or not isinstance(upd.get("values"), list):
                return None
            for v in upd["values"]:
                if not isinstance(v, dict) or not isinstance(v.get("path"), str) or "value" not in v:
                    return None
                val = v["value"]
                if isinstance(val, float) and not math.isfinite(val):
                    return None
                out[v["path"]] = val
        return out
    except (ValueError, TypeError, RecursionError, UnicodeDecodeError):
        return None


def autopilot_put(ap, path, value, t: float) -> tuple[int, str]:
    """Apply a PUT of ``value`` to ``path`` on the autopilot at ship time ``t`` [s].

    ``steering.autopilot.target.headingTrue``: the set course [rad, |value| <= 2 pi];
    ``steering.autopilot.state``: ``"auto"`` (engage) or ``"standby"``. Returns
    ``(HTTP status code, message)``: 200, 400 (bad value), 405 (path not writable) or 409 (a
    heading the autopilot would not apply: it follows a route or a chart plotter's course; the
    message says which: :meth:`steerlab.runtime.autopilot.Autopilot.course_refusal`).
    """
    if path == TARGET_HEADING:
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) \
                or abs(value) > 2 * math.pi:
            return 400, "value must be a heading in radians, |value| <= 2 pi"
        refusal = ap.course_refusal(t)
        if refusal is not None:
            return 409, refusal
        ap.set_course(float(value), t)
        return 200, ""
    if path == AUTOPILOT_STATE:
        if value == "auto":
            ap.engage(t)
        elif value == "standby":
            ap.standby(t)
        else:
            return 400, "value must be 'auto' or 'standby'"
        return 200, ""
    return 405, f"not writable here (writable: {', '.join(WRITABLE)})"
