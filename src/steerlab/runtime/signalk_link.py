"""Signed Signal K deltas over UDP: the link between the autopilot and the Signal K plug-in.

With the link's HMAC key (:mod:`steerlab.runtime.keys`, the key that signs the ship link's
datagrams, :mod:`steerlab.runtime.protocol`), every delta on the plug-in's link is signed in
both directions: the autopilot's status to ``--signalk-to`` (what the plug-in reports to the
Signal K server) and the plug-in's commands to ``--signalk-listen``. A datagram is two lines of
UTF-8::

    <64 hex digits: HMAC-SHA256(key, BODY)>\\n
    BODY = {"session": uint32, "seq": uint, "stamp_ms": int, "delta": "<the delta's JSON text>"}

``session`` is random per sender start, ``seq`` grows by one per datagram within it, and
``stamp_ms`` is the sender's wall clock [ms since 1970]. The receiver (:class:`SignedDeltaFilter`
here, ``verify`` in ``integrations/signalk-plugin-steerlab/index.js``) keeps a datagram only if
the tag is right over the exact BODY bytes (no re-serialisation on either side), the stamp is
within ``max_age`` of its own clock and ``seq`` is larger than the last one taken from that
session; everything else is dropped and counted by reason (``unauthenticated``: not in this
format, ``bad_mac``, ``malformed``, ``stale``, ``replayed``). So a local process that does not
hold the key can neither forge a status (a dead autopilot reported engaged) nor a command, nor
replay a captured one later.
"""

from __future__ import annotations

import hashlib
import hmac
import json
import math
import secrets
from collections import Counter, OrderedDict

TAG_HEX = 64
MAX_SESSIONS = 16
REASONS = ("unauthenticated", "bad_mac", "malformed", "stale", "replayed")


class DeltaSigner:
    """Signs delta texts with ``key`` (one random session; ``seq`` += 1 per datagram)."""

    def __init__(self, key: bytes, session: int | None = None):
        self.key = key
        self.session = secrets.randbits(32) if session is None else int(session) & 0xFFFFFFFF
        self.seq = 0

    def sign(self, delta_text: str, wall: float) -> bytes:
        """The datagram carrying ``delta_text`` stamped at ``wall`` [s since 1970]."""
        self.seq += 1
        body = json.dumps({"session": self.session, "seq": self.seq, "stamp_ms": int(round(wall * 1000.0)),
                           "delta": delta_text}, separators=(",", ":")).encode("utf-8")
        tag = hmac.new(self.key, body, hashlib.sha256).hexdigest()
        return tag.encode("ascii") + b"\n" + body


class SignedDeltaFilter:
    """Keeps only signed, fresh, new datagrams; ``counts`` per outcome (``accepted`` and
    :data:`REASONS`).

    Parameters
    ----------
    key : bytes
        The link's HMAC key.
    max_age : float
        Largest ``|receiver clock - stamp|`` accepted [s].
    """

    def __init__(self, key: bytes, max_age: float = 3.0):
        self.key = key
        self.max_age = float(max_age)
        self.last_seq: OrderedDict = OrderedDict()     # session -> last seq taken (bounded)
        self.counts: Counter = Counter(accepted=0)

    def _reject(self, reason: str):
        self.counts[reason] += 1
        return None, reason

    def accept(self, data: bytes, wall: float):
        """``(delta_text, "ok")`` or ``(None, reason)``; never raises."""
        try:
            data = bytes(data)
        except (TypeError, ValueError):
            return self._reject("malformed")
        if len(data) < TAG_HEX + 2 or data[TAG_HEX:TAG_HEX + 1] != b"\n":
            return self._reject("unauthenticated")
        tag, body = data[:TAG_HEX], data[TAG_HEX + 1:]
        want = hmac.new(self.key, body, hashlib.sha256).hexdigest().encode("ascii")
        if not hmac.compare_digest(want, tag.lower()):
            return self._reject("bad_mac")
        try:
            msg = json.loads(body.decode("utf-8"))
            session, seq, stamp, text = msg["session"], msg["seq"], msg["stamp_ms"], msg["delta"]
        except (ValueError, TypeError, KeyError, UnicodeDecodeError, RecursionError):
            return self._reject("malformed")
        if not all(isinstance(v, int) and not isinstance(v, bool) for v in (session, seq, stamp)) \
                or not isinstance(text, str):
            return self._reject("malformed")
        age = wall - stamp / 1000.0
        if not math.isfinite(age) or abs(age) > self.max_age:
            return self._reject("stale")
        last = self.last_seq.get(session)
        if last is not None and seq <= last:
            return self._reject("replayed")
        self.last_seq[session] = seq
        self.last_seq.move_to_end(session)
        while len(self.last_seq) > MAX_SESSIONS:
            self.last_seq.popitem(last=False)
        self.counts["accepted"] += 1
        return text, "ok"
