r"""Health of any sensor source (fresh, stale, implausible) and the priority that picks one.

A boat's autopilot measures heading, rate of turn, position, speed and rudder angle, each from
one of several sources (an NMEA 0183 talker, a Signal K server, the ship-state datagram of the
simulator link, ...). Each source of each quantity is watched by a :class:`SourceHealth`:

* **unseen**: nothing received yet (no alarm: the source may simply not be fitted);
* **fresh**: the newest plausible reading is at most ``timeout`` old (ship seconds);
* **stale**: it was seen, but nothing plausible for longer than ``timeout``;
* **implausible**: the newest reading is out of its range, or it moved further from the previous
  one than the quantity can: ``distance(x_k, x_{k-1}) > max_rate * (t_k - t_{k-1}) + tolerance``.
  The reading is not used; the source stays implausible until ``recover`` consecutive readings
  agree with each other by the same rule (a single glitch never steers the ship).

:func:`select_source` takes the first **fresh** source of a stated priority and raises the
alarm ``<quantity>_<source>`` (e.g. ``position_nmea``) for every seen source of that priority
that is stale or implausible, naming the source that took over; the alarm clears when the
source is fresh again. The heading's own class (:class:`~steerlab.runtime.heading_health.
HeadingHealth`) is this one with the angle wrapped.
"""

from __future__ import annotations

import math
from collections import Counter

UNSEEN, FRESH, STALE, IMPLAUSIBLE = "unseen", "fresh", "stale", "implausible"


def source_alarm(quantity: str, name: str) -> str:
    """The alarm of source ``name`` of ``quantity`` (``position_nmea``)."""
    return f"{quantity}_{name}"


def _absolute(a, b) -> float:
    return abs(float(a) - float(b))


class SourceHealth:
    """One source's health for one quantity; clock [s] supplied by the caller.

    Parameters
    ----------
    name : str
        The source (``nmea``, ``signalk``...).
    timeout : float
        Older than this [s]: stale.
    max_rate : float
        Plausibility limit on the rate of change [quantity units / s]; ``inf``: no limit.
    tolerance : float
        Change allowed on top of ``max_rate * dt`` [quantity units] (noise, quantisation).
    recover : int
        Consecutive plausible readings that end an implausible spell.
    distance : callable
        ``distance(new, old) -> float`` between two readings (default ``|new - old|``).
    valid_range : (float, float) or None
        Readings outside ``[lo, hi]`` (scalar quantities) are implausible.
    quantity : str
        What is measured (for the messages): ``heading``, ``position``...
    """

    def __init__(self, name: str, timeout: float, max_rate: float = math.inf, tolerance: float = 0.0,
                 recover: int = 3, distance=_absolute, valid_range=None, quantity: str = "value"):
        self.name = name
        self.timeout = float(timeout)
        self.max_rate = float(max_rate)
        self.tolerance = float(tolerance)
        self.recover = int(recover)
        self.distance = distance
        self.valid_range = valid_range
        self.quantity = quantity
        self.last = None          # (value, t) of the newest reading, plausible or not
        self.good = None          # (value, t) of the newest usable reading
        self.implausible = False
        self.agreeing = 0         # consecutive plausible readings since the last jump
        self.counts: Counter = Counter()

    def _finite(self, value) -> bool:
        vals = value if isinstance(value, tuple) else (value,)
        return all(isinstance(v, (int, float)) and math.isfinite(v) for v in vals)

    def observe(self, value, t: float) -> bool:
        """Take a reading; True when it is usable (plausible and not in an implausible spell)."""
        if not self._finite(value) or (self.valid_range is not None
                                        and not self.valid_range[0] <= value <= self.valid_range[1]):
            self.counts["implausible"] += 1
            self.implausible, self.agreeing = True, 0
            self.last = (self.last[0] if self.last else None, t)
            return False
        jump = False
        if self.last is not None and self.last[0] is not None and math.isfinite(self.max_rate):
            dt = max(0.0, t - self.last[1])
            jump = self.distance(value, self.last[0]) > self.max_rate * dt + self.tolerance
        self.last = (value, t)
        if jump:
            self.implausible = True
            self.agreeing = 0
            self.counts["implausible"] += 1
            return False
        if self.implausible:
            self.agreeing += 1
            if self.agreeing < self.recover:
                self.counts["implausible"] += 1
                return False
            self.implausible = False
        self.good = (value, t)
        self.counts["accepted"] += 1
        return True

    def status(self, t: float) -> str:
        """:data:`UNSEEN`, :data:`FRESH`, :data:`STALE` or :data:`IMPLAUSIBLE` at time ``t``."""
        if self.last is None:
            return UNSEEN
        if self.implausible and t - self.last[1] <= self.timeout:
            return IMPLAUSIBLE
        if self.good is not None and t - self.good[1] <= self.timeout:
            return FRESH
        return STALE

    def value(self, t: float):
        """The usable reading if the source is fresh at ``t``, else None."""
        return self.good[0] if self.status(t) == FRESH else None

    def describe(self, t: float) -> str:
        """One line for the alarm: what is wrong with the source."""
        st = self.status(t)
        if st == STALE:
            return f"{self.name} {self.quantity} stale (nothing plausible for more than {self.timeout:g} s)"
        if st == IMPLAUSIBLE:
            return f"{self.name} {self.quantity} implausible (out of range or changing faster than possible)"
        return f"{self.name} {self.quantity} {st}"


def select_source(t: float, quantity: str, order, sources: dict, fixed: dict | None = None, alarms=None):
    """``(value, source name)``: the first fresh source of ``order``, or ``(None, None)``.

    ``sources`` maps names to :class:`SourceHealth`; ``fixed`` maps names of sources without a
    health of their own (the state datagram, whose freshness is the link watchdog's; a derived
    value; an assumed one) to their value, or None when they have none now. With an ``alarms``
    board each seen source of ``order`` that is stale or implausible raises
    :func:`source_alarm` (cleared when fresh), naming the source that took over.
    """
    fixed = fixed or {}
    chosen = (None, None)
    bad = []
    for name in order:
        h = sources.get(name)
        if h is None:
            v = fixed.get(name)
            if chosen[1] is None and v is not None:
                chosen = (v, name)
            continue
        st = h.status(t)
        if st in (STALE, IMPLAUSIBLE):
            bad.append(name)
        if chosen[1] is None and st == FRESH:
            chosen = (h.good[0], name)
    if alarms is not None:
        for name in order:
            h = sources.get(name)
            if h is not None:
                alarms.set(source_alarm(quantity, name), name in bad, t,
                           f"{h.describe(t)}: using the {chosen[1] or 'no'} {quantity}")
    return chosen
