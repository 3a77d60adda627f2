r"""Health of a heading source (fresh, stale, implausible) and the priority that picks one.

Each heading input the autopilot can steer by is watched by a :class:`HeadingHealth`:

* **unseen**: nothing received yet (no alarm: the source may simply not be fitted);
* **fresh**: the newest plausible heading is at most ``timeout`` old (ship seconds);
* **stale**: it was seen, but nothing plausible for longer than ``timeout``;
* **implausible**: the newest heading jumped further from the previous one than a ship can
  turn: ``|wrap(psi_k - psi_{k-1})| > max_rate * (t_k - t_{k-1}) + tolerance``. The jumped
  value is not used; the source stays implausible until ``recover`` consecutive headings agree
  with each other by the same rule (so a real step, e.g. a compass swapped, is taken after
  ``recover`` readings, and a single glitch never steers the ship).

The autopilot steers by the first **fresh** source of its priority
(:data:`HEADING_PRIORITY`: the NMEA heading sensor, a Signal K server, then the ship-state
datagram; on a signed
link the signed state alone unless ``--nmea-heading-over-signed``), and a seen source of that
priority that is stale or implausible raises the alarm ``heading_<name>`` (cleared when it is
fresh again) naming the source that took over. The state datagram's own freshness is the link
watchdog's (alarm ``link``); its integrity is the link filter's.
"""

from __future__ import annotations

import math
from collections import Counter

from steerlab.angles import wrap_to_pi
from steerlab.units import deg, rad

UNSEEN, FRESH, STALE, IMPLAUSIBLE = "unseen", "fresh", "stale", "implausible"
HEADING_PRIORITY = ("nmea", "signalk", "state")
"""Heading sources, first fresh one wins: ``nmea`` (HDT/THS/HDG/HDM from any NMEA input: UDP,
serial, TCP), ``signalk`` (a Signal K server's ``navigation.headingTrue`` or
``headingMagnetic``, :mod:`steerlab.runtime.signalk_input`), ``state`` (the ship-state datagram)."""
MAX_TURN_RATE = rad(45.0)
"""Default plausibility limit on a heading's rate of change [rad/s]: 45 deg/s is beyond any
displacement ship and a small craft's hardest turn; a compass that jumps faster is faulty."""
JUMP_TOLERANCE = rad(2.0)
"""Jump allowed on top of ``max_rate * dt`` [rad] (sensor noise and 0.1-deg quantisation)."""


def heading_alarm(name: str) -> str:
    """The alarm of heading source ``name`` (``heading_nmea``)."""
    return f"heading_{name}"


class HeadingHealth:
    """One heading source's health; clock [s] and angles [rad] supplied by the caller.

    Parameters
    ----------
    name : str
    timeout : float
        Older than this [s]: stale.
    max_rate : float
        Plausibility limit on the rate of change [rad/s] (:data:`MAX_TURN_RATE`).
    tolerance : float
        Jump allowed on top of ``max_rate * dt`` [rad].
    recover : int
        Consecutive plausible readings that end an implausible spell.
    """

    def __init__(self, name: str, timeout: float, max_rate: float = MAX_TURN_RATE,
                 tolerance: float = JUMP_TOLERANCE, recover: int = 3):
        self.name = name
        self.timeout = float(timeout)
        self.max_rate = float(max_rate)
        self.tolerance = float(tolerance)
        self.recover = int(recover)
        self.last = None          # (psi, t) of the newest reading, plausible or not
        self.good = None          # (psi, t) of the newest usable reading
        self.implausible = False
        self.agreeing = 0         # consecutive plausible readings since the last jump
        self.counts: Counter = Counter()

    def observe(self, psi: float, t: float) -> bool:
        """Take a reading; True when it is usable (plausible and not in an implausible spell)."""
        psi = float(psi)
        if not math.isfinite(psi):
            self.counts["implausible"] += 1
            return False
        jump = False
        if self.last is not None:
            dt = max(0.0, t - self.last[1])
            jump = abs(wrap_to_pi(psi - self.last[0])) > self.max_rate * dt + self.tolerance
        self.last = (psi, t)
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
        self.good = (psi, t)
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

    def heading(self, t: float):
        """The usable heading [rad] if the source is fresh at ``t``, else None."""
        return self.good[0] if self.status(t) == FRESH else None

    def describe(self, t: float) -> str:
        """One line for the alarm: what is wrong with the source."""
        st = self.status(t)
        if st == STALE:
            return f"{self.name} heading stale (nothing plausible for more than {self.timeout:g} s)"
        if st == IMPLAUSIBLE:
            return f"{self.name} heading implausible (jumped faster than {deg(self.max_rate):g} deg/s)"
        return f"{self.name} heading {st}"


def select_heading(t: float, order, sources: dict, fallback: float, alarms=None):
    """``(heading [rad], source name)``: the first fresh source of ``order``.

    ``sources`` maps names to :class:`HeadingHealth`; ``"state"`` (no health of its own: the
    link watchdog's) gives ``fallback``; another name without one is skipped. With an ``alarms`` board
    (:class:`~steerlab.runtime.alarms.AlarmBoard`), each seen source of ``order`` that is
    stale or implausible raises :func:`heading_alarm` (cleared when fresh), naming the source
    that took over.
    """
    chosen = None
    bad = []
    for name in order:
        h = sources.get(name)
        if h is None:
            if chosen is None and name == "state":
                chosen = (fallback, name)
            continue
        st = h.status(t)
        if st in (STALE, IMPLAUSIBLE):
            bad.append(h)
        if chosen is None and st == FRESH:
            chosen = (h.good[0], name)
    if chosen is None:
        chosen = (fallback, "state")
    if alarms is not None:
        for name in order:
            h = sources.get(name)
            if h is not None:
                alarms.set(heading_alarm(name), h in bad, t,
                           f"{h.describe(t)}: steering by the {chosen[1]} heading")
    return chosen
