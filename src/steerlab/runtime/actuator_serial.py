"""The line-based serial actuator driver (``--actuator serial:PATH[:BAUD]``, 38 400 baud default).

Speaks :mod:`steerlab.runtime.actuator_protocol` over a :class:`~steerlab.runtime.serial_port.SerialLink`:
one ``$PSTLO`` order each sample (standby: release), every ``$PSTLF`` read back as the rudder
angle; the faults come from :class:`~steerlab.runtime.actuator.ActuatorMonitor` (feedback
lost, no movement), the drive's own status (``C``: over-current) and the port (``device_lost``
while it is gone; it is reopened every second). Lines that are not a valid ``$PSTLF`` are
counted (``counts["malformed"]``), never raise.
"""

from __future__ import annotations

from collections import Counter

from steerlab.runtime.actuator import DEVICE_LOST, FAULTS, ActuatorMonitor
from steerlab.runtime.actuator_protocol import STATUS_OVER_CURRENT, parse_feedback, render_order
from steerlab.runtime.line_splitter import LineSplitter

DEFAULT_ACTUATOR_BAUD = 38400


class SerialActuator:
    """Parameters: ``arg`` = ``"PATH[:BAUD]"``; ``monitor``: the fault limits (defaults of
    :class:`~steerlab.runtime.actuator.ActuatorMonitor`)."""

    name = "serial"

    def __init__(self, arg: str, monitor: ActuatorMonitor | None = None, log=None):
        from steerlab.runtime.serial_port import parse_serial_spec

        self.path, self.baud = parse_serial_spec(arg, "--actuator", DEFAULT_ACTUATOR_BAUD)
        self.monitor = monitor or ActuatorMonitor()
        self.splitter = LineSplitter()
        self.counts: Counter = Counter()
        self.log = log
        self.link = None
        self.ap = None
        self.current = None

    async def start(self, autopilot) -> None:
        from steerlab.runtime.serial_port import SerialLink

        self.ap = autopilot
        kw = {} if self.log is None else {"log": self.log}
        self.link = SerialLink(self.path, self.baud, self._on_bytes, name="--actuator", **kw)
        await self.link.start(required=True)

    def _on_bytes(self, data: bytes) -> None:
        t = self.ap.clock()
        for line in self.splitter.feed(data):
            fb = parse_feedback(line)
            if fb is None:
                self.counts["malformed"] += 1
                continue
            self.counts["feedback"] += 1
            self.monitor.report_over_current(fb.status == STATUS_OVER_CURRENT)
            self.monitor.feedback(fb.angle, t)
            self.current = fb.current

    def order(self, command, t: float) -> None:
        engaged = command is not None
        angle = command.delta_cmd if engaged else None
        self.monitor.ordered(angle, t)
        if self.link is not None:
            self.link.write(render_order(angle, engaged).encode("ascii"))

    def rudder(self, t: float):
        return None if self.monitor.angle is None else self.monitor.angle[0]

    def faults(self, t: float) -> dict:
        out = self.monitor.faults(t)
        if self.link is not None and not self.link.connected:
            out[DEVICE_LOST] = f"{self.path}: {FAULTS[DEVICE_LOST]}"
        return out

    async def close(self) -> None:
        if self.link is not None:
            if self.link.connected:
                self.link.write(render_order(None, False).encode("ascii"))   # release the drive
            await self.link.close()
