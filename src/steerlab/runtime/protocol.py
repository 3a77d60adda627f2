r"""steerlab real-time link, wire format version 1: encode and decode datagrams (pure functions).

Every datagram is little-endian and self-describing::

    offset size  field
    0      4     magic      b"SLRT"
    4      1     version    1 (PROTOCOL_VERSION); other versions are rejected
    5      1     type       1 = STATE (ship -> autopilot), 2 = COMMAND (autopilot -> ship),
                            3 = HELLO (autopilot -> ship: "send me your state", no payload)
    6      1     flags      bit 0: a 32-byte HMAC-SHA256 tag follows the payload; other bits 0
    7      1     reserved   0
    8      4     session    uint32, random per sender start (tells a restarted sender apart)
    12     8     seq        uint64, +1 per datagram within a session
    20     8     stamp      float64, sender's wall clock when sent [s since 1970-01-01 UTC]
    28     n     payload    fixed size per type (below)
    28+n   32    tag        HMAC-SHA256(key, bytes 0 .. 28+n), only if flags bit 0

STATE payload (``<10dI``, 84 bytes; SI, radians, heading clockwise from north)::

    t_sim [s], x_n [m], y_e [m], psi [rad], r [rad/s], u [m/s], v [m/s],
    delta [rad] (rudder angle, > 0 turns to starboard), rpm [rev/min] (NaN: model default),
    delta_cmd [rad] (rudder order in effect), status (uint32 bits, STATUS_*)

COMMAND payload (``<2dI``, 20 bytes)::

    delta_cmd [rad] (|.| <= pi/2), rpm_cmd [rev/min] (NaN: unchanged; else 0 .. 1000),
    mode (uint32 bits, MODE_*)

HELLO payload: empty. The ship server publishes its state to every source that sent it a valid
COMMAND or HELLO within the last ``SUBSCRIPTION_TIMEOUT`` seconds (plus fixed targets).

Decoding never raises: :func:`decode` returns ``(message, "ok")`` or ``(None, reason)`` with
one of :data:`REJECT_REASONS`. Sequencing, freshness, authentication and rate limits are
applied by :class:`steerlab.runtime.link_filter.LinkFilter`; this module only checks shape.
"""

from __future__ import annotations

import hashlib
import hmac
import math
import struct
from typing import NamedTuple

MAGIC = b"SLRT"
PROTOCOL_VERSION = 1
TYPE_STATE = 1
TYPE_COMMAND = 2
TYPE_HELLO = 3
SUBSCRIPTION_TIMEOUT = 5.0
FLAG_HMAC = 0x01
TAG_SIZE = 32

HEADER = struct.Struct("<4sBBBBIQd")
STATE_PAYLOAD = struct.Struct("<10dI")
COMMAND_PAYLOAD = struct.Struct("<2dI")
HELLO_PAYLOAD = struct.Struct("<")
PAYLOADS = {TYPE_STATE: STATE_PAYLOAD, TYPE_COMMAND: COMMAND_PAYLOAD, TYPE_HELLO: HELLO_PAYLOAD}
MAX_DATAGRAM = HEADER.size + STATE_PAYLOAD.size + TAG_SIZE

STATUS_CMD_HOLD = 0x01      #: no valid command for a while: last order held
STATUS_CMD_CENTRED = 0x02   #: no valid command for longer: rudder ordered midships
MODE_ENGAGED = 0x01         #: the autopilot is engaged (else the order is a standby/safe order)
MODE_SAFE = 0x02            #: the order is the autopilot's safe action (watchdog alarm)

REJECT_REASONS = ("malformed", "bad_version", "wrong_type", "unauthenticated", "bad_mac",
                  "duplicate", "reordered", "stale", "future", "replayed", "rate_limited",
                  "out_of_range", "locked")
"""Why a datagram was rejected (the counters of :class:`~steerlab.runtime.link_filter.LinkFilter`)."""


class Sender:
    """Numbers and stamps outgoing datagrams: one random session, ``seq`` += 1 per datagram."""

    def __init__(self, key: bytes | None = None, session: int | None = None):
        import secrets

        self.key = key or None
        self.session = secrets.randbits(32) if session is None else int(session)
        self.seq = 0

    def pack(self, body, stamp: float) -> bytes:
        self.seq += 1
        return encode(body, self.session, self.seq, stamp, self.key)


class Header(NamedTuple):
    type: int
    flags: int
    session: int
    seq: int
    stamp: float


class State(NamedTuple):
    """Ship state as published by the ship server (SI, radians)."""

    t_sim: float
    x_n: float
    y_e: float
    psi: float
    r: float
    u: float
    v: float
    delta: float
    rpm: float
    delta_cmd: float
    status: int = 0


class Command(NamedTuple):
    """Rudder (and optional rpm) order from the autopilot."""

    delta_cmd: float
    rpm_cmd: float = math.nan
    mode: int = MODE_ENGAGED


class Hello(NamedTuple):
    """Subscription request (no fields)."""


class Message(NamedTuple):
    header: Header
    body: object          # State, Command or Hello
    signed: bool


def encode(body, session: int, seq: int, stamp: float, key: bytes | None = None) -> bytes:
    """One datagram carrying ``body`` (:class:`State` or :class:`Command`); signed if ``key``."""
    if isinstance(body, State):
        mtype, payload = TYPE_STATE, STATE_PAYLOAD.pack(*body[:10], int(body.status))
    elif isinstance(body, Command):
        mtype, payload = TYPE_COMMAND, COMMAND_PAYLOAD.pack(body.delta_cmd, body.rpm_cmd, int(body.mode))
    elif isinstance(body, Hello):
        mtype, payload = TYPE_HELLO, b""
    else:
        raise TypeError(f"cannot encode {type(body).__name__}")
    flags = FLAG_HMAC if key else 0
    data = HEADER.pack(MAGIC, PROTOCOL_VERSION, mtype, flags, 0, session & 0xFFFFFFFF,
                       seq & 0xFFFFFFFFFFFFFFFF, float(stamp)) + payload
    if key:
        data += hmac.new(key, data, hashlib.sha256).digest()
    return data


def _finite(*xs) -> bool:
    return all(math.isfinite(x) for x in xs)


def _check_state(s: State) -> bool:
    return (_finite(s.t_sim, s.x_n, s.y_e, s.psi, s.r, s.u, s.v, s.delta, s.delta_cmd)
            and (math.isnan(s.rpm) or math.isfinite(s.rpm))
            and abs(s.psi) <= 4 * math.pi and abs(s.delta) <= math.pi and abs(s.delta_cmd) <= math.pi)


def _check_command(c: Command) -> bool:
    return (math.isfinite(c.delta_cmd) and abs(c.delta_cmd) <= 0.5 * math.pi
            and (math.isnan(c.rpm_cmd) or 0.0 <= c.rpm_cmd <= 1000.0))


def decode(data: bytes, key: bytes | None = None):
    """``(Message, "ok")`` or ``(None, reason)``; never raises on any input bytes.

    With ``key``, the datagram must carry a valid tag (else ``unauthenticated`` / ``bad_mac``);
    without one, a tag present is ignored (not verified) and ``signed`` is False.
    """
    try:
        return _decode(bytes(data), key)
    except Exception:  # pragma: no cover - _decode checks sizes first; belt and braces
        return None, "malformed"


def _decode(data: bytes, key):
    if len(data) < HEADER.size:
        return None, "malformed"
    magic, version, mtype, flags, reserved, session, seq, stamp = HEADER.unpack_from(data)
    if magic != MAGIC:
        return None, "malformed"
    if version != PROTOCOL_VERSION:
        return None, "bad_version"
    if reserved != 0 or flags & ~FLAG_HMAC:
        return None, "malformed"
    payload = PAYLOADS.get(mtype)
    if payload is None:
        return None, "malformed"
    tagged = bool(flags & FLAG_HMAC)
    size = HEADER.size + payload.size + (TAG_SIZE if tagged else 0)
    if len(data) != size:
        return None, "malformed"
    signed = False
    if key:
        if not tagged:
            return None, "unauthenticated"
        body_end = size - TAG_SIZE
        want = hmac.new(key, data[:body_end], hashlib.sha256).digest()
        if not hmac.compare_digest(want, data[body_end:]):
            return None, "bad_mac"
        signed = True
    if not (math.isfinite(stamp) and stamp > 0.0):
        return None, "malformed"
    fields = payload.unpack_from(data, HEADER.size)
    if mtype == TYPE_STATE:
        body = State(*fields)
        ok = _check_state(body)
    elif mtype == TYPE_HELLO:
        body, ok = Hello(), True
    else:
        body = Command(*fields)
        ok = _check_command(body)
    if not ok:
        return None, "out_of_range"
    return Message(Header(mtype, flags, session, seq, stamp), body, signed), "ok"
