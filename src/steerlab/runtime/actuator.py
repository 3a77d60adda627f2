r"""The actuator interface: rudder order out, rudder angle in, faults in.

The autopilot drives its rudder through one **actuator driver** (``steerlab autopilot
--actuator NAME[:ARG]``)::

    class Actuator(Protocol):
        name: str
        async def start(self, autopilot) -> None     # open ports; the autopilot's clock and link
        def order(self, command, t) -> None          # each sample: a Command, or None (standby)
        def rudder(self, t) -> float | None          # newest measured rudder angle [rad], > 0 stbd
        def faults(self, t) -> dict[str, str]        # active faults: name -> one-line reason
        async def close(self) -> None

Built in: ``sim`` (:class:`~steerlab.runtime.actuator_sim.SimLinkActuator`, the COMMAND
datagram to ``serve-ship``; the default) and ``serial`` (:class:`~steerlab.runtime.
actuator_serial.SerialActuator`, the line protocol of :mod:`steerlab.runtime.actuator_protocol`).
Other packages add drivers through the entry-point group ``steerlab.actuators``: the entry
point names a factory ``factory(arg: str) -> Actuator``::

    [project.entry-points."steerlab.actuators"]
    mydrive = "my_package.drive:MyDrive"      # steerlab autopilot --actuator mydrive:/dev/ttyS1

Faults (:data:`FAULTS`) are what the driver reports or what :class:`ActuatorMonitor` finds
from its orders and feedback. Any fault while engaged puts the autopilot in its **safe state**
(:meth:`steerlab.runtime.autopilot.Autopilot.sample`): the ``actuator`` alarm, the safe
action ordered (midships or hold), disengaged -- it does not re-engage by itself.
"""

from __future__ import annotations

from typing import Protocol

from steerlab.errors import InputError
from steerlab.units import deg, rad

FEEDBACK_LOST = "feedback_lost"
NO_MOVEMENT = "no_movement"
OVER_CURRENT = "over_current"
DEVICE_LOST = "device_lost"
FAULTS = {
    FEEDBACK_LOST: "no valid rudder angle while orders are given",
    NO_MOVEMENT: "the rudder does not move toward an order it is away from",
    OVER_CURRENT: "the drive reports over-current (it has stopped)",
    DEVICE_LOST: "the actuator's port is gone",
}
ENTRY_POINT_GROUP = "steerlab.actuators"
BUILTIN = {"sim": "steerlab.runtime.actuator_sim:SimLinkActuator",
           "serial": "steerlab.runtime.actuator_serial:SerialActuator"}


class Actuator(Protocol):
    name: str

    async def start(self, autopilot) -> None: ...

    def order(self, command, t: float) -> None: ...

    def rudder(self, t: float) -> float | None: ...

    def faults(self, t: float) -> dict: ...

    async def close(self) -> None: ...


class ActuatorMonitor:
    """Faults found from orders and feedback (ship time [s], angles [rad]).

    * ``feedback_lost``: orders are being given and no valid angle came for ``feedback_timeout``;
    * ``no_movement``: the angle has stayed more than ``stall_error`` from the order for
      ``stall_time`` while moving less than ``stall_move`` (a jammed rudder, a dead pump);
    * ``over_current``: reported by the driver (:meth:`report_over_current`).
    """

    def __init__(self, feedback_timeout: float = 0.5, stall_time: float = 2.0, stall_error: float = rad(2.0),
                 stall_move: float = rad(0.5)):
        self.feedback_timeout = float(feedback_timeout)
        self.stall_time = float(stall_time)
        self.stall_error = float(stall_error)
        self.stall_move = float(stall_move)
        self.angle = None            # (angle, t)
        self.order_since = None      # t of the first order of the present engaged spell
        self.order = None
        self.stall = None            # (t, angle) when the error first exceeded stall_error
        self.over_current = False

    def feedback(self, angle: float | None, t: float) -> None:
        if angle is not None:
            self.angle = (float(angle), t)

    def report_over_current(self, on: bool) -> None:
        self.over_current = bool(on)

    def ordered(self, angle: float | None, t: float) -> None:
        """The order given at ``t`` (None: standby, nothing driven)."""
        if angle is None:
            self.order_since = self.order = self.stall = None
            return
        if self.order_since is None:
            self.order_since = t
        self.order = float(angle)
        if self.angle is None:
            return
        a = self.angle[0]
        if abs(self.order - a) <= self.stall_error:
            self.stall = None
        elif self.stall is None or abs(a - self.stall[1]) > self.stall_move:
            self.stall = (t, a)

    def faults(self, t: float) -> dict:
        out = {}
        if self.over_current:
            out[OVER_CURRENT] = FAULTS[OVER_CURRENT]
        if self.order_since is not None:
            last = self.angle[1] if self.angle is not None else -float("inf")
            since = max(last, self.order_since)
            if t - since > self.feedback_timeout:
                out[FEEDBACK_LOST] = (f"no valid rudder angle for more than {self.feedback_timeout:g} s")
            elif self.stall is not None and t - self.stall[0] > self.stall_time:
                out[NO_MOVEMENT] = (f"rudder at {deg(self.angle[0]):.1f} deg, ordered {deg(self.order):.1f} deg, "
                                    f"not moving for {self.stall_time:g} s")
        return out


def load_actuator(spec: str, field: str = "--actuator"):
    """The driver for ``"NAME[:ARG]"``: a built-in one (:data:`BUILTIN`) or an entry point of
    :data:`ENTRY_POINT_GROUP`, called with ``ARG`` (``""`` if none)."""
    from importlib import import_module
    from importlib.metadata import entry_points

    name, _, arg = str(spec).strip().partition(":")
    factory = None
    if name in BUILTIN:
        mod, _, attr = BUILTIN[name].partition(":")
        factory = getattr(import_module(mod), attr)
    else:
        for ep in entry_points(group=ENTRY_POINT_GROUP):
            if ep.name == name:
                try:
                    factory = ep.load()
                except Exception as err:
                    raise InputError(field, f"actuator {name!r} ({ep.value}) failed to load: {err}") from None
                break
    if factory is None:
        known = sorted(set(BUILTIN) | {ep.name for ep in entry_points(group=ENTRY_POINT_GROUP)})
        raise InputError(field, f"unknown actuator {name!r}; known: {', '.join(known)}")
    return factory(arg)
