"""Signal K delta messages (JSON, SI units) for the ship state and the autopilot.

Paths (Signal K specification, ``vessels.self`` context; radians, rad/s, m/s)::

    navigation.headingTrue                   psi wrapped to [0, 2 pi)
    navigation.rateOfTurn                    r (> 0 to starboard)
    navigation.speedThroughWater             u
    steering.rudderAngle                     delta (> 0 turns to starboard, as steerlab)
    steering.rudderAngleTarget               the rudder order in effect / commanded
    steering.autopilot.target.headingTrue    the set course
    steering.autopilot.state                 "auto" | "standby" | "alarm"

steerlab's own paths (its autopilot's status and commands on the plug-in's link)::

    steering.autopilot.steerlab.mode         "compass" | "route" | "plotter" (steering_modes)
    steering.autopilot.steerlab.modes        the modes available now (list)
    steering.autopilot.steerlab.profile      the controller profile in effect (controller_settings)
    steering.autopilot.steerlab.profiles     the profiles there are (list)
    steering.autopilot.steerlab.gains        settings given on top of the profile ({name: value})
    steering.autopilot.steerlab.alarms       the active alarms: [{"name", "message", "state"}]
    steering.autopilot.steerlab.targetRefused  why a target heading would not be applied now
    steering.autopilot.steerlab.commandId    in a command: its number, answered in the status by
    steering.autopilot.steerlab.reply        the answers to the last 8: [{"id", "code" (HTTP-like:
                                             200, 400, 409), "message"}] (a list, maybe empty)

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
MODE = "steering.autopilot.steerlab.mode"
MODES_AVAILABLE = "steering.autopilot.steerlab.modes"
PROFILE = "steering.autopilot.steerlab.profile"
PROFILES = "steering.autopilot.steerlab.profiles"
GAINS = "steering.autopilot.steerlab.gains"
ALARMS = "steering.autopilot.steerlab.alarms"
COMMAND_ID = "steering.autopilot.steerlab.commandId"
REPLY = "steering.autopilot.steerlab.reply"
WRITABLE = (TARGET_HEADING, AUTOPILOT_STATE, MODE, PROFILE, GAINS)   #: paths a PUT may set on the autopilot
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


def status_values(ap) -> dict:
    """steerlab's own status paths (the module docstring): mode, profile, gains and the active
    alarms, each with its Signal K notification state (:func:`steerlab.runtime.alarms.severity`)."""
    from steerlab.runtime.alarms import severity

    return {MODE: ap.steering_mode, MODES_AVAILABLE: list(ap.available_modes()),
            PROFILE: ap.settings.profile, PROFILES: ap.settings.names(), GAINS: dict(ap.settings.gains),
            ALARMS: [{"name": a["name"], "message": a["message"], "state": severity(a["name"])}
                     for a in ap.alarms.snapshot() if a["active"]]}


def autopilot_delta_json(ap, wall: float | None = None) -> str:
    """The status delta sent over UDP (``--signalk-to``): :func:`autopilot_values`,
    :func:`status_values` and, while a target heading would not be applied,
    :data:`TARGET_REFUSED` with the reason."""
    return json.dumps(delta({**autopilot_values(ap), **status_values(ap),
                             TARGET_REFUSED: ap.course_refusal(ap.clock()),
                             REPLY: list(getattr(ap, "signalk_replies", ()))}, wall))


COMMAND_ORDER = (MODE, PROFILE, GAINS, TARGET_HEADING, AUTOPILOT_STATE)
"""The order the paths of one command delta are applied in (a mode before the course it allows)."""


def apply_commands(ap, values: dict, t: float) -> tuple[str, dict | None]:
    """Apply a command delta's ``{path: value}`` to the autopilot at ship time ``t`` [s].

    Returns ``(outcome, reply)``: the outcome is counted (``accepted``; ``ignored``: no
    command path; ``out_of_range`` / ``bad_field``: a target heading or a state that is not
    one, then nothing is applied; ``not_applied``: a command refused, e.g. a target heading while
    a route sets the course, the rest applied). ``reply`` answers a delta that carried
    :data:`COMMAND_ID` (``{"id", "code", "message"}``, the first refusal's code), else None.
    """
    cid = values.get(COMMAND_ID)
    cid = cid if isinstance(cid, int) and not isinstance(cid, bool) and 0 < cid < 2 ** 53 else None
    paths = [p for p in COMMAND_ORDER if p in values]
    answer = lambda code, msg: None if cid is None else {"id": cid, "code": code, "message": msg}  # noqa: E731
    if not paths:
        return "ignored", answer(400, "no command path in the delta")
    target, state = values.get(TARGET_HEADING), values.get(AUTOPILOT_STATE)
    # the same checks as a PUT (a heading in radians, |value| <= 2 pi; "auto" or "standby")
    if TARGET_HEADING in values and (isinstance(target, bool) or not isinstance(target, (int, float))
                                     or not math.isfinite(target) or abs(target) > 2 * math.pi):
        return "out_of_range", answer(400, "target heading must be radians, |value| <= 2 pi")
    if AUTOPILOT_STATE in values and state not in ("auto", "standby"):
        return "bad_field", answer(400, "state must be 'auto' or 'standby'")
    first = None
    for p in paths:
        code, msg = autopilot_put(ap, p, values[p], t)
        if code != 200 and first is None:
            first = (code, msg)
    if first is None:
        return "accepted", answer(200, "")
    return "not_applied", answer(*first)


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
    ``steering.autopilot.state``: ``"auto"`` (engage) or ``"standby"``;
    :data:`MODE`: a steering mode (:mod:`steerlab.runtime.steering_modes`); :data:`PROFILE`: a
    controller profile's name; :data:`GAINS`: ``{setting: value}`` on top of the profile
    (:mod:`steerlab.runtime.controller_settings`). Returns ``(HTTP status code, message)``: 200,
    400 (bad value: the message names the field and the allowed range), 405 (path not writable)
    or 409 (valid but not applicable now: a heading while a route or a chart plotter sets the
    course, :meth:`steerlab.runtime.autopilot.Autopilot.course_refusal`; a mode whose source
    this autopilot does not have).
    """
    from steerlab.errors import InputError
    from steerlab.runtime.steering_modes import MODES

    if path == MODE:
        why = ap.set_mode(value, t)
        if why is None:
            return 200, ""
        return (409 if value in MODES else 400), why
    if path in (PROFILE, GAINS):
        try:
            if path == PROFILE:
                if not isinstance(value, str):
                    return 400, f"profile must be a name, one of {', '.join(ap.settings.names())}"
                ap.configure(t, profile=value)
            else:
                ap.configure(t, gains=value)
        except InputError as err:
            return 400, str(err)
        return 200, ""
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
