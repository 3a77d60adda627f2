"""The simulator link as an actuator driver: the COMMAND datagram to ``serve-ship``.

The rudder order leaves as :class:`~steerlab.runtime.protocol.Command` on the autopilot's
UDP link (signed with its key, if any), exactly as before drivers existed; the rudder angle
comes back in the ship-state datagram (``State.delta``). Its feedback is the link itself,
watched by the autopilot's watchdog (alarm ``link``), so this driver reports no faults of its
own; in standby nothing is sent (the ship server holds, then centres, the last order).
"""

from __future__ import annotations

import time

from steerlab.runtime.udp import send


class SimLinkActuator:
    name = "sim"

    def __init__(self, arg: str = ""):
        self.ap = None

    async def start(self, autopilot) -> None:
        self.ap = autopilot

    def order(self, command, t: float) -> None:
        ap = self.ap
        if command is not None:
            send(ap.transport, ap.sender.pack(command, time.time()), ap.connect)

    def rudder(self, t: float):
        st = self.ap.latest if self.ap is not None else None
        return None if st is None else st.delta

    def faults(self, t: float) -> dict:
        return {}

    async def close(self) -> None:
        pass
