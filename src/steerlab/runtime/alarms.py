"""Bridge alarms: raised by a condition, cleared when it goes away, acknowledged by the officer.

An alarm is *active* while its condition holds; it stays listed (``unacknowledged``) until
acknowledged, even after it cleared, so a brief link outage is not missed. Pure bookkeeping,
clock supplied by the caller.
"""

from __future__ import annotations

from dataclasses import dataclass

LINK = "link"            #: no valid ship state for longer than the watchdog time
OFF_COURSE = "off_course"  #: heading deviates from the set course by more than the limit
ARRIVAL = "arrival"      #: the chart plotter's destination waypoint was reached: the last course is held
ACTUATOR = "actuator"    #: the actuator driver reports a fault: safe action ordered, autopilot disengaged
POSITION = "position"    #: route mode without any fresh position: the route's last reference is held
SIGNALK_INPUT = "signalk_input"  #: the Signal K input's subscription was up and is lost (reconnecting)

SEVERITY = {ARRIVAL: "alert"}
"""Signal K notification state of an alarm (specification 1.7, "Notifications": ``alert`` <
``warn`` < ``alarm`` < ``emergency``); an alarm not listed is an ``alarm``."""


def severity(name: str) -> str:
    """The Signal K notification state an active alarm ``name`` is raised with."""
    return SEVERITY.get(name, "alarm")


@dataclass
class Alarm:
    name: str
    message: str
    since: float
    active: bool = True
    acknowledged: bool = False


class AlarmBoard:
    def __init__(self):
        self.alarms: dict[str, Alarm] = {}
        self.history: list[tuple[float, str, str]] = []   # (t, name, "raised"|"cleared"|"acknowledged")

    def set(self, name: str, condition: bool, t: float, message: str = "") -> None:
        """Raise ``name`` when ``condition`` becomes true; mark it cleared when it becomes false."""
        a = self.alarms.get(name)
        if condition:
            if a is None or not a.active:
                self.alarms[name] = Alarm(name, message, t)
                self.history.append((t, name, "raised"))
        elif a is not None and a.active:
            a.active = False
            self.history.append((t, name, "cleared"))
            if a.acknowledged:
                del self.alarms[name]

    def acknowledge(self, t: float, name: str | None = None) -> None:
        """Acknowledge one alarm (or all); cleared ones then disappear."""
        for n in [name] if name else list(self.alarms):
            a = self.alarms.get(n)
            if a is None:
                continue
            a.acknowledged = True
            self.history.append((t, n, "acknowledged"))
            if not a.active:
                del self.alarms[n]

    def active(self, name: str) -> bool:
        a = self.alarms.get(name)
        return a is not None and a.active

    def first_raised(self, name: str) -> float | None:
        """Time [s] the alarm was first raised, or None."""
        return next((t for t, n, what in self.history if n == name and what == "raised"), None)

    def snapshot(self) -> list[dict]:
        return [{"name": a.name, "message": a.message, "since": a.since, "active": a.active,
                 "acknowledged": a.acknowledged} for a in self.alarms.values()]
