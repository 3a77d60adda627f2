"""Receive side of the link: which datagrams may be used (sequence, freshness, auth, rate).

:class:`LinkFilter` is the only gate between a socket and the ship or the autopilot. For each
datagram, in this order (the first failing rule names the rejection; nothing raises):

1. ``rate_limited``  - the source exceeded its token bucket (:class:`RateLimiter`);
2. shape             - :func:`steerlab.runtime.protocol.decode` (``malformed``, ``bad_version``,
   ``out_of_range``; with a key: ``unauthenticated``, ``bad_mac``);
3. ``wrong_type``    - not the message type this end expects;
4. ``stale`` / ``future`` - the sender's stamp is more than ``max_age`` seconds before (after)
   the receiver's wall clock (``max_age <= 0`` turns this off, e.g. for unsynchronised clocks);
5. sequencing within the current sender session:
   ``duplicate`` (already accepted, a copy from the same source: the network duplicated it; on
   an authenticated link a copy from another source is counted as ``replayed``),
   ``reordered`` (older than the newest accepted: it arrived late, a newer one is in use);
   a datagram of another session is accepted only if its stamp is newer than the last
   accepted one (the sender restarted), else ``replayed``.

6. ``locked`` (only with ``lock_types``, the ship server's commands) - a session lock: while the
   sender whose ``lock_types`` message was accepted last (the *holder*: its session and, without
   a key, its source address) has sent one within ``lock_timeout`` wall seconds, such messages
   from any other sender are refused, so a second process cannot take the rudder from a running
   autopilot (and a restarted autopilot takes over once the lock has lapsed). Other messages of
   other senders (a display's HELLO) are still accepted, but leave the holder's sequencing alone.

Accepted datagrams are counted under ``accepted``. With a key, a replayed copy of a signed
datagram is always rejected: by the sequence rules while fresh, by rule 4 once old.
"""

from __future__ import annotations

from collections import Counter, deque

from steerlab.runtime.protocol import decode
from steerlab.runtime.rate_limit import RateLimiter

SEEN_WINDOW = 256


class LinkFilter:
    """Stateful filter for one stream of datagrams of type ``expect_type``.

    Parameters
    ----------
    expect_type : int or tuple of int
        The accepted message type(s), e.g. ``protocol.TYPE_STATE`` or
        ``(protocol.TYPE_COMMAND, protocol.TYPE_HELLO)``.
    key : bytes or None
        Shared HMAC key; when given, unsigned or wrongly signed datagrams are rejected.
    max_age : float
        Freshness limit [s of wall clock] on the sender's stamp; ``<= 0``: off.
    rate, burst : float
        Token bucket per source address [datagrams/s], [datagrams]; ``rate <= 0``: off.
    lock_types : tuple of int
        Message types that take and need the session lock (rule 6); empty: no lock.
    lock_timeout : float
        The lock lapses after this long without a ``lock_types`` message from its holder [wall s].
    """

    def __init__(self, expect_type: int, key: bytes | None = None, max_age: float = 0.5,
                 rate: float = 0.0, burst: float = 20.0, lock_types=(), lock_timeout: float = 0.0):
        self.expect_types = (expect_type,) if isinstance(expect_type, int) else tuple(expect_type)
        self.key = key or None
        self.max_age = float(max_age)
        self.limiter = RateLimiter(rate, burst)
        self.counts: Counter = Counter()
        self.session: int | None = None
        self.session_source = None       # where the current session's accepted datagrams came from
        self.last_seq = -1
        self.last_stamp = 0.0
        self._seen: deque = deque(maxlen=SEEN_WINDOW)
        self._seen_set: set = set()
        self.lock_types = tuple(lock_types) if lock_timeout > 0.0 else ()
        self.lock_timeout = float(lock_timeout)
        self.holder = None           # (session, source or None) of the lock holder
        self.holder_time = 0.0       # wall time of its last lock_types message [s]

    def _reject(self, reason: str):
        self.counts[reason] += 1
        return None, reason

    def accept(self, data: bytes, now: float, source=None):
        """``(Message, "ok")`` if ``data`` may be used now (wall clock ``now`` [s]), else ``(None, reason)``."""
        if not self.limiter.allow(source, now):
            return self._reject("rate_limited")
        msg, reason = decode(data, self.key)
        if msg is None:
            return self._reject(reason)
        h = msg.header
        if h.type not in self.expect_types:
            return self._reject("wrong_type")
        if self.max_age > 0.0:
            if now - h.stamp > self.max_age:
                return self._reject("stale")
            if h.stamp - now > self.max_age:
                return self._reject("future")
        if self.lock_types and self.holder is not None and now - self.holder_time < self.lock_timeout:
            if (h.session, None if self.key else source) != self.holder:
                if h.type in self.lock_types:
                    return self._reject("locked")
                self.counts["accepted"] += 1          # e.g. a display's HELLO: used, sequencing untouched
                return msg, "ok"
        if h.session == self.session:
            if (h.session, h.seq) in self._seen_set:
                return self._reject("replayed" if self.key and source != self.session_source else "duplicate")
            if h.seq < self.last_seq:
                return self._reject("reordered")
        elif self.session is not None and h.stamp <= self.last_stamp:
            return self._reject("replayed")
        if h.session != self.session:
            self.session = h.session
            self._seen.clear()
            self._seen_set.clear()
        self.session_source = source
        self.last_seq = h.seq
        self.last_stamp = max(self.last_stamp, h.stamp)
        if len(self._seen) == self._seen.maxlen:
            self._seen_set.discard(self._seen[0])
        self._seen.append((h.session, h.seq))
        self._seen_set.add((h.session, h.seq))
        if h.type in self.lock_types:
            self.holder = (h.session, None if self.key else source)
            self.holder_time = now
        self.counts["accepted"] += 1
        return msg, "ok"

    def rejected(self) -> int:
        """Datagrams rejected so far (all reasons)."""
        return sum(v for k, v in self.counts.items() if k != "accepted")
