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

from steerlab.angles import wrap_to_pi
from steerlab.runtime.source_health import FRESH, IMPLAUSIBLE, STALE, UNSEEN, SourceHealth
from steerlab.units import deg, rad

__all__ = ["FRESH", "HEADING_PRIORITY", "IMPLAUSIBLE", "JUMP_TOLERANCE", "MAX_TURN_RATE", "STALE", "UNSEEN",
           "HeadingHealth", "heading_alarm", "select_heading"]
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


def _wrapped(a, b) -> float:
    return abs(wrap_to_pi(float(a) - float(b)))


class HeadingHealth(SourceHealth):
    """One heading source's health (:class:`~steerlab.runtime.source_health.SourceHealth` with
    the angle difference wrapped); clock [s] and angles [rad] supplied by the caller.

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
        super().__init__(name, timeout, max_rate, tolerance, recover, distance=_wrapped, quantity="heading")

    def heading(self, t: float):
        """The usable heading [rad] if the source is fresh at ``t``, else None."""
        return self.value(t)

    def describe(self, t: float) -> str:
        """One line for the alarm: what is wrong with the source."""
        if self.status(t) == IMPLAUSIBLE:
            return f"{self.name} heading implausible (jumped faster than {deg(self.max_rate):g} deg/s)"
        return super().describe(t)


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
                then = (f"steering by the {chosen[1]} heading" if chosen[0] is not None
                        else "no heading left to steer by")       # (on a boat without a ship state)
                alarms.set(heading_alarm(name), h in bad, t, f"{h.describe(t)}: {then}")
    return chosen
