"""Signal K as an input source: the autopilot subscribes to a Signal K server's stream.

``steerlab autopilot --signalk-input HOST:PORT`` connects (WebSocket,
``ws://HOST:PORT/signalk/v1/stream?subscribe=none``, reconnecting every second) and subscribes,
for ``vessels.self`` with policy ``instant`` (every update as it comes), to :data:`INPUT_PATHS`: ``navigation.headingTrue`` and
``navigation.headingMagnetic`` (+ ``navigation.magneticVariation`` to turn it true),
``navigation.position``, ``navigation.rateOfTurn``, ``navigation.speedOverGround`` and
``steering.rudderAngle`` (SI: radians, rad/s, m/s, degrees of latitude/longitude). Every delta is checked (:func:`input_values`: finite,
headings in [0, 2 pi], variation within +-30 deg, rudder within +-90 deg) and handed to
``on_values({path: value})`` (:meth:`steerlab.runtime.autopilot.Autopilot.on_signalk_values`);
what fails is counted by reason, never raises. A signalk-server, or ``serve-ship
--signalk-ws``, is such a source.
"""

from __future__ import annotations

import asyncio
import json
import math
from collections import Counter

from steerlab.runtime.nmea_magnetic import MAX_VARIATION_DEG
from steerlab.runtime.reconnecting_input import ReconnectingInput
from steerlab.runtime.reconnecting_input import stderr_line as _stderr

INPUT_PATHS = ("navigation.headingTrue", "navigation.headingMagnetic", "navigation.magneticVariation",
               "navigation.position", "navigation.rateOfTurn", "navigation.speedOverGround",
               "steering.rudderAngle")




def _finite(x) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


def input_values(values: dict, counts: Counter) -> dict:
    """The usable subset of a delta's ``{path: value}`` (SI); each value left out is counted
    (``bad_field`` not a number, ``out_of_range``); ``accepted`` counts the rest."""
    out = {}
    limits = {"navigation.headingTrue": (0.0, 2 * math.pi), "navigation.headingMagnetic": (0.0, 2 * math.pi),
              "navigation.magneticVariation": (-math.radians(MAX_VARIATION_DEG), math.radians(MAX_VARIATION_DEG)),
              "navigation.rateOfTurn": (-math.pi, math.pi), "navigation.speedOverGround": (0.0, 50.0),
              "steering.rudderAngle": (-math.pi / 2, math.pi / 2)}
    for path, v in values.items():
        if path not in INPUT_PATHS or v is None:
            continue
        if path == "navigation.position":
            if not (isinstance(v, dict) and _finite(v.get("latitude")) and _finite(v.get("longitude"))):
                counts["bad_field"] += 1
                continue
            if abs(v["latitude"]) > 90.0 or abs(v["longitude"]) > 180.0:
                counts["out_of_range"] += 1
                continue
            out[path] = (float(v["latitude"]), float(v["longitude"]))
        elif not _finite(v):
            counts["bad_field"] += 1
            continue
        else:
            lo, hi = limits[path]
            if not lo <= v <= hi:
                counts["out_of_range" if path != "navigation.magneticVariation" else "variation_out_of_range"] += 1
                continue
            out[path] = float(v)
        counts["accepted"] += 1
    return out


class SignalKInput(ReconnectingInput):
    """A subscription to a Signal K server's stream (``connected``, ``counts``; ``lost()`` is
    the ``signalk_input`` alarm: up once and down now)."""

    def __init__(self, host: str, port: int, on_values, reconnect_period: float = 1.0, log=_stderr):
        super().__init__(host, port, reconnect_period, log)
        self.on_values = on_values

    async def _run(self) -> None:
        from websockets.asyncio.client import connect

        from steerlab.runtime.signalk import parse_delta

        url = f"ws://{self.host}:{self.port}/signalk/v1/stream?subscribe=none"
        said = False
        # policy "instant": every update as it comes (the specification's default, "ideal" with a
        # 1000 ms period, would give the heading once a second, far too late to steer by)
        sub = json.dumps({"context": "vessels.self",
                          "subscribe": [{"path": p, "policy": "instant"} for p in INPUT_PATHS]})
        while True:
            try:
                async with connect(url, open_timeout=10, max_size=1 << 20) as ws:
                    self.connected, said, self.ever_connected = True, False, True
                    self.counts["connected"] += 1
                    await ws.send(sub)
                    async for msg in ws:
                        values = parse_delta(msg)
                        if values is None:
                            self.counts["not_delta"] += 1       # hello, or not a delta
                            continue
                        got = input_values(values, self.counts)
                        if got:
                            self.on_values(got)
            except asyncio.CancelledError:
                raise
            except Exception as err:                          # refused, closed, bad handshake
                self.counts["connect_failed" if not self.connected else "disconnected"] += 1
                if not said:
                    self.log(f"--signalk-input: {url}: {err}; retrying every {self.reconnect_period:g} s")
                    said = True
            self.connected = False
            await asyncio.sleep(self.reconnect_period)
