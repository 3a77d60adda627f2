"""Ship server: runs a scenario's ship (+ steering gear, disturbances) in real time over UDP.

The plant is advanced by the one RK4 step of :func:`steerlab.sim.kernels.plant_step` (ship +
steering gear, rudder order held between commands), exactly as the simulators do; only the
clock is real: one publish period (0.05 s of ship time by default) is integrated, then the
state is published, paced at ``speedup`` times real time.

Rudder orders come from :data:`~steerlab.runtime.protocol.TYPE_COMMAND` datagrams that pass
the :class:`~steerlab.runtime.link_filter.LinkFilter`. If none arrives in time the server
**holds** the last order (status ``STATUS_CMD_HOLD`` after ``cmd_timeout``) and then
**centres** the rudder (``STATUS_CMD_CENTRED`` after ``centre_after``): :func:`order_in_effect`.

One sender at a time holds the rudder: while the autopilot session whose command was accepted
last keeps sending (a gap shorter than ``session_lock``), commands of any other sender are
refused (counted ``locked``), with or without a key; see :class:`~steerlab.runtime.link_filter.LinkFilter`.
"""

from __future__ import annotations

import asyncio
import math
import time
from collections import Counter
from dataclasses import dataclass, field

import numpy as np

from steerlab.errors import InputError, require_finite_range
from steerlab.runtime import protocol as P
from steerlab.runtime.link_filter import LinkFilter
from steerlab.runtime.udp import LOOPBACK, open_udp, send
from steerlab.ships.state import IPSI, IR, IU, IV, IX, IY


@dataclass(frozen=True)
class ShipServerConfig:
    """Timing and safety settings (ship time [s] unless marked wall)."""

    publish_period: float = 0.05     #: state published every ... [s]
    speedup: float = 1.0             #: ship seconds per wall second
    cmd_timeout: float = 1.0         #: no valid command for longer: the order is held (flagged)
    centre_after: float = 3.0        #: no valid command for longer: rudder ordered midships
    duration: float = 0.0            #: stop after this ship time [s]; 0: run until stopped
    max_age: float = 0.5             #: freshness limit on command stamps [wall s]; 0: off
    rate: float = 40.0               #: commands accepted per source per ship second (token bucket)
    burst: float = 20.0              #: token bucket size [datagrams]
    nmea_period: float = 0.2         #: NMEA 0183 / Signal K output period [s]
    max_subscribers: int = 8
    session_lock: float = 1.0        #: commands of a second sender refused until the holder is silent this long; 0: off

    def validate(self) -> "ShipServerConfig":
        require_finite_range("--publish-period", self.publish_period, 0.001, 10.0)
        require_finite_range("--speedup", self.speedup, 0.01, 1000.0)
        require_finite_range("--cmd-timeout", self.cmd_timeout, 0.0, 3600.0, lo_open=True)
        require_finite_range("--centre-after", self.centre_after, self.cmd_timeout, 3600.0)
        require_finite_range("--duration", self.duration, 0.0, 1e7)
        require_finite_range("--max-age", self.max_age, 0.0, 3600.0)
        require_finite_range("--nmea-period", self.nmea_period, 0.01, 60.0)
        require_finite_range("--session-lock", self.session_lock, 0.0, 3600.0)
        return self


def order_in_effect(age: float | None, last_order: float, cmd_timeout: float, centre_after: float):
    """``(delta_cmd [rad], status bits)`` given the age [s] of the last valid command.

    ``age is None`` (no command yet) or ``age > centre_after``: midships, ``STATUS_CMD_CENTRED``;
    ``cmd_timeout < age <= centre_after``: the last order held, ``STATUS_CMD_HOLD``;
    otherwise the last order, no flag.
    """
    if age is None or age > centre_after:
        return 0.0, P.STATUS_CMD_CENTRED
    if age > cmd_timeout:
        return last_order, P.STATUS_CMD_HOLD
    return last_order, 0


@dataclass
class ShipServerStats:
    published: int = 0
    commands: int = 0
    hellos: int = 0
    steps: int = 0
    late_ticks: int = 0
    status_changes: list = field(default_factory=list)


class ShipServer:
    """A ship model driven by UDP commands, publishing its state.

    Parameters
    ----------
    scenario : steerlab.sim.scenario.Scenario
        Ship, speed, options, gear, initial heading, disturbances and ``dt`` (the integration
        step is the largest divisor of ``publish_period`` not above ``dt``).
    config : ShipServerConfig
    key : bytes or None
        HMAC key; when given, only signed commands are accepted and states are signed.
    bind : (host, port)
        Local address (loopback by default; port 0 picks a free one: see ``address``).
    publish_to : sequence of (host, port)
        Fixed state receivers in addition to the subscribers (senders of HELLO/COMMAND).
    nmea_to, signalk_to : (host, port) or None
        Where to send NMEA 0183 sentences / Signal K deltas every ``nmea_period``.
    signalk_ws : (host, port) or None
        Serve the Signal K stream here (WebSocket, read-only), updated every ``nmea_period``.
    origin : (lat_deg, lon_deg)
        Geographic position of the model's origin (for RMC); None: at sea in the Gulf of Gdansk
        (:data:`steerlab.runtime.nmea.DEFAULT_ORIGIN`).
    allow_origins : sequence of str
        Browser origins allowed on the Signal K stream besides loopback pages.
    """

    def __init__(self, scenario, config: ShipServerConfig = ShipServerConfig(), key=None,
                 bind=(LOOPBACK, 0), publish_to=(), nmea_to=None, signalk_to=None,
                 origin=None, signalk_ws=None, allow_origins=()):
        from steerlab.sim.kernels import plant_step
        from steerlab.sim.setup import build

        self.config = config.validate()
        self.scenario = scenario
        self.setup = s = build(scenario)
        self.rk4_step = plant_step(s.ship.rhs)
        self.speed = scenario.ship.speed()
        self.ship_options = s.ship.options(scenario.ship.options)
        self.ps = s.ps.copy()
        self.rpm = float(scenario.ship.rpm) if scenario.ship.rpm is not None else math.nan
        self.rpm_ordered = self.rpm      # the last rpm order seen (applied or not)
        self.rpm_counts: Counter = Counter(accepted=0)
        self.rpm_error = ""
        self.x = s.x0.copy()
        self.work = np.empty((5, self.x.shape[0]))
        n_sub = max(1, math.ceil(self.config.publish_period / s.dt - 1e-9))
        self.h = self.config.publish_period / n_sub
        self.n_sub = n_sub
        self.t_sim = 0.0
        self.order = 0.0
        self.last_cmd_t: float | None = None
        self.delta_cmd, self.status = order_in_effect(None, 0.0, config.cmd_timeout, config.centre_after)
        self.key = key
        self.sender = P.Sender(key)
        self.filter = LinkFilter((P.TYPE_COMMAND, P.TYPE_HELLO), key=key, max_age=config.max_age,
                                 rate=config.rate * config.speedup, burst=config.burst,
                                 lock_types=(P.TYPE_COMMAND,), lock_timeout=config.session_lock / config.speedup)
        self.bind = bind
        self.publish_to = list(publish_to)
        self.subscribers: dict = {}
        self.nmea_to = nmea_to
        self.signalk_to = signalk_to
        self.signalk_ws = signalk_ws
        self.signalk_stream = None
        self.allow_origins = tuple(allow_origins)
        if origin is None:
            from steerlab.runtime.nmea import DEFAULT_ORIGIN as origin
        self.origin = origin
        self.stats = ShipServerStats()
        self.rk4_step(0.0, self.x.copy(), 0.0, s.w[0], self.ps, s.pg, self.h, self.work)  # compile now
        self.transport = None
        self.out_transport = None
        self._stop = None
        self._next_nmea = 0.0

    # ------------------------------------------------------------ the plant (no I/O)
    def advance(self) -> None:
        """Integrate one publish period with the order in effect (hold, then centre)."""
        age = None if self.last_cmd_t is None else self.t_sim - self.last_cmd_t
        cmd, status = order_in_effect(age, self.order, self.config.cmd_timeout, self.config.centre_after)
        if status != self.status:
            self.stats.status_changes.append((self.t_sim, status))
        self.delta_cmd, self.status = cmd, status
        s = self.setup
        n_w = s.w.shape[0]
        for _ in range(self.n_sub):
            k = int(self.t_sim / s.dt + 1e-9) % n_w      # the sampled sea repeats after `duration`
            self.rk4_step(self.t_sim, self.x, cmd, s.w[k], self.ps, s.pg, self.h, self.work)
            self.t_sim += self.h
            self.stats.steps += 1

    def state(self) -> P.State:
        x = self.x
        return P.State(self.t_sim, x[IX], x[IY], math.remainder(x[IPSI], 2 * math.pi), x[IR], x[IU], x[IV],
                       x[-1], self.rpm, self.delta_cmd, self.status)

    def apply_command(self, cmd: P.Command) -> None:
        self.order = float(cmd.delta_cmd)
        self.last_cmd_t = self.t_sim
        if not math.isnan(cmd.rpm_cmd) and cmd.rpm_cmd != self.rpm_ordered:
            self.order_rpm(float(cmd.rpm_cmd))

    def order_rpm(self, rpm: float) -> bool:
        """Apply a propeller order [rev/min] (0 included: the propeller stopped) to the model.

        The ship's own ``pack`` takes it, as a scenario's ``[ship] rpm`` would; a ship indexed
        by propeller rate (the Capella catalogue entries) takes it as ``[ship.options] rpm``.
        An order the model refuses (outside its range, e.g. Capella's 110-220 rpm) or that does
        not change it (a model without a propeller) leaves the ship as it is and is counted in
        ``rpm_counts`` (``refused`` with the message in ``rpm_error``; ``no_effect``), once per
        new order value (the autopilot repeats its order in every datagram). Never raises.
        """
        self.rpm_ordered = rpm
        ship = self.setup.ship
        try:
            if "rpm" in getattr(ship.options_model, "model_fields", {}):
                options = ship.options({**dict(self.scenario.ship.options or {}), "rpm": rpm})
                ps = ship.pack(self.speed, None, options)
            else:
                ps = ship.pack(self.speed, rpm, self.ship_options)
        except InputError as err:
            self.rpm_counts["refused"] += 1
            self.rpm_error = f"rpm order {rpm:g} refused: {err}"
            return False
        if ps.shape == self.ps.shape and np.array_equal(ps, self.ps, equal_nan=True):
            self.rpm_counts["no_effect"] += 1
            return False
        self.ps = ps
        self.rpm = rpm
        self.rpm_counts["accepted"] += 1
        return True

    # ------------------------------------------------------------ I/O
    def on_datagram(self, data: bytes, addr) -> None:
        msg, _ = self.filter.accept(data, time.time(), addr)
        if msg is None:
            return
        if addr is not None and (addr in self.subscribers or len(self.subscribers) < self.config.max_subscribers):
            self.subscribers[addr] = time.monotonic()
        if isinstance(msg.body, P.Command):
            self.stats.commands += 1
            self.apply_command(msg.body)
        else:
            self.stats.hellos += 1

    def publish(self) -> None:
        st = self.state()
        data = self.sender.pack(st, time.time())
        now = time.monotonic()
        for addr, seen in list(self.subscribers.items()):
            if now - seen > P.SUBSCRIPTION_TIMEOUT:
                del self.subscribers[addr]
            else:
                send(self.transport, data, addr)
        for addr in self.publish_to:
            send(self.transport, data, addr)
        self.stats.published += 1
        if (self.nmea_to or self.signalk_to or self.signalk_stream) and self.t_sim + 1e-9 >= self._next_nmea:
            self._next_nmea = self.t_sim + self.config.nmea_period
            self._publish_marine(st)

    def _publish_marine(self, st: P.State) -> None:
        if self.nmea_to:
            from steerlab.runtime.nmea import state_sentences

            for line in state_sentences(st, self.origin, time.time()):
                send(self.out_transport, line.encode("ascii"), self.nmea_to)
        if self.signalk_to:
            from steerlab.runtime.signalk import state_delta_json

            send(self.out_transport, state_delta_json(st, time.time()).encode(), self.signalk_to)
        if self.signalk_stream is not None:
            from steerlab.runtime.signalk import state_values

            self.signalk_stream.publish(state_values(st), time.time())

    @property
    def address(self):
        """The bound ``(host, port)`` (after :meth:`run` started)."""
        return self.transport.get_extra_info("sockname")[:2] if self.transport else None

    def stop(self) -> None:
        if self._stop is not None:
            self._stop.set()

    async def run(self, started=None) -> ShipServerStats:
        """Serve until ``duration`` (ship time) or :meth:`stop`; ``started(server)`` once bound."""
        loop = asyncio.get_running_loop()
        self._stop = asyncio.Event()
        try:
            self.transport = await open_udp(self.on_datagram, self.bind)
        except OSError as err:
            raise InputError("--bind", f"cannot bind {self.bind[0]}:{self.bind[1]}: {err.strerror}") from None
        if self.nmea_to or self.signalk_to:
            self.out_transport = await open_udp(lambda d, a: None, (LOOPBACK if self.bind[0] == LOOPBACK else "0.0.0.0", 0))
        if self.signalk_ws is not None:
            from steerlab.runtime.signalk_ws import SignalKStreamServer

            try:
                self.signalk_stream = await SignalKStreamServer(*self.signalk_ws,
                                                         allow_origins=self.allow_origins).start()
            except InputError:
                self.transport.close()
                raise
        if started is not None:
            started(self)
        cfg = self.config
        wall_period = cfg.publish_period / cfg.speedup
        t0 = loop.time()
        k = 0
        try:
            self.publish()
            while not self._stop.is_set():
                if cfg.duration > 0 and self.t_sim >= cfg.duration - 1e-9:
                    break
                k += 1
                delay = t0 + k * wall_period - loop.time()
                if delay > 0:
                    await asyncio.sleep(delay)
                    if self._stop.is_set():
                        break
                else:
                    self.stats.late_ticks += 1
                    await asyncio.sleep(0)
                self.advance()
                self.publish()
        finally:
            self.transport.close()
            if self.out_transport is not None:
                self.out_transport.close()
            if self.signalk_stream is not None:
                await self.signalk_stream.close()
        return self.stats
