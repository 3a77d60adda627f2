"""Runtime message fuzz against a running ship server and autopilot, with the event loop measured.

:func:`fuzz_runtime` starts a ship server and an autopilot (signed link, NMEA and Signal K UDP
listeners, the Signal K WebSocket stream) on loopback, lets the autopilot steer, then sends
``n`` generated messages of each kind through real sockets, one kind after the other:

* **NMEA lines** to the autopilot's NMEA port (one line per datagram; valid sentences with
  characters replaced, implausible values: 1e300, NaN, magnetic, status V; random text; now and
  then a datagram of 40 lines);
* **link datagrams** to the autopilot's state port and the ship's command port (signed and
  unsigned states, commands, hellos with bytes replaced, cut or appended; random bytes);
* **Signal K UDP deltas** to the autopilot's Signal K port (the hostile messages below, and
  deltas of the writable paths with values of every type);
* **WebSocket messages** to the autopilot's Signal K stream (the hostile messages of
  ``test_runtime_web_fuzz._fuzz_message``: deep nesting, many-``*`` subscriptions, PUTs...).

Measured per kind: exceptions (in a handler or reported to the loop), the thread CPU time of
each handler call (outside the garbage collector: see ``_GcClock``), its wall time, and the
event loop's lag (a probe task sleeping 5 ms and recording how late it wakes). The per-source
rate limits are turned off for the run so that every message is parsed (the limits themselves
are tested in ``test_runtime_inputs.py``). The fuzzing clients run in the same event loop and
yield after every message (and wait for the servers to catch up every 32), so the kernel's UDP
buffer does not overflow; ``handled`` counts the fuzz messages that reached a handler, timings
cover every handler call (the normal state/command traffic too). The loop lag includes the
clients' own work and whatever else the machine runs: it is reported, while the bound is
asserted on the CPU time of each handler call, which other processes cannot inflate.
"""

from __future__ import annotations

import asyncio
import math
import random
import socket
import time

from steerlab.runtime import nmea
from steerlab.runtime import protocol as P
from steerlab.runtime.autopilot import Autopilot, AutopilotConfig
from steerlab.runtime.ship_server import ShipServer, ShipServerConfig
from steerlab.sim.scenario import scenario_from_dict

KEY = b"runtime fuzz key, 32 bytes long!"
KINDS = ("NMEA lines", "link datagrams", "Signal K UDP deltas", "WebSocket messages")
MAX_BLOCK_S = 0.05      #: no single message may block the event loop longer (issue 15) [s]

_T0 = 1_700_000_000.0
_STATE = P.State(12.5, 100.0, -20.0, 0.3, -0.01, 8.0, 0.2, 0.05, math.nan, 0.07, 0)
_VALID_LINK = [P.encode(b, 3, 9, _T0, k) for b in (_STATE, P.Command(0.1, 60.0), P.Hello()) for k in (None, KEY)]
_APB = ["A", "A", "0.10", "R", "N", "V", "V", "45.0", "T", "WP1", "44.0", "T", "50.0", "T"]
_GOOD_NMEA = [ln.strip() for ln in nmea.state_sentences(_STATE, wall=_T0)] + [
    nmea.render("APB", _APB).strip(),
    nmea.render("RMB", ["A", "0.05", "L", "A", "B", "5430.00", "N", "01830.00", "E", "1.0", "90.0", "8.0", "V"]).strip(),
    nmea.render("HTC", ["V", "", "", "H", "N", "", "", "", "", "123.4", "", "", "T"]).strip(),
    nmea.render("XTE", ["A", "A", "0.1", "L", "N"]).strip()]
_IMPLAUSIBLE = ["1e300", "-1e300", "nan", "inf", "-5", "361", "100000", "", "V", "M", "X", "1" * 40]
_ALPHABET = "$!*,.-0123456789ABCDEFGHIJKLMNOPQRSTUVWXYZabcdef \t\r\n\x00\xff"


def nmea_message(rng: random.Random) -> bytes:
    """One generated NMEA datagram (seeded)."""
    k = rng.randrange(10)
    if k < 4:                                   # a valid sentence with characters replaced
        g = bytearray(rng.choice(_GOOD_NMEA).encode())
        for _ in range(rng.randrange(1, 4)):
            g[rng.randrange(len(g))] = ord(rng.choice(_ALPHABET)) & 0xFF
        return bytes(g) + b"\r\n"
    if k < 8:                                   # valid checksum, implausible field values
        line = rng.choice(_GOOD_NMEA)
        kind, fields = line[3:6], line.split("*")[0].split(",")[1:]
        fields[rng.randrange(len(fields))] = rng.choice(_IMPLAUSIBLE)
        return nmea.render(kind, fields).encode()
    if k == 8:                                  # random text
        return "".join(rng.choice(_ALPHABET) for _ in range(rng.randrange(0, 120))).encode("latin-1")
    return "".join(rng.choice(_GOOD_NMEA) + "\r\n" for _ in range(40)).encode()   # 40 lines


def link_message(rng: random.Random) -> bytes:
    """One generated link datagram (seeded): random bytes or a valid one mutated."""
    if rng.random() < 0.3:
        return rng.randbytes(rng.randrange(0, P.MAX_DATAGRAM + 8))
    d = bytearray(rng.choice(_VALID_LINK))
    for _ in range(rng.randrange(1, 5)):
        d[rng.randrange(len(d))] = rng.randrange(256)
    if rng.random() < 0.3:
        d = d[:rng.randrange(0, len(d) + 1)]
    return bytes(d) + rng.randbytes(rng.randrange(0, 3))


_SIGNALK_SIGNER = []


def signalk_message(rng: random.Random) -> bytes:
    """One generated Signal K UDP datagram (seeded): a delta of a writable path with a value of
    any type, or a hostile message (``test_runtime_web_fuzz._fuzz_message``). The autopilot is
    keyed, so its Signal K link is signed (:mod:`steerlab.runtime.signalk_link`): 9 in 10 are
    signed with :data:`KEY` (their content reaches the checks), the rest are not (refused
    ``unauthenticated``)."""
    import json
    import time

    from steerlab.runtime.signalk import AUTOPILOT_STATE, GAINS, MODE, PROFILE, TARGET_HEADING
    from steerlab.runtime.signalk_link import DeltaSigner
    from test_runtime_web_fuzz import _fuzz_message

    if rng.random() < 0.5:
        value = rng.choice((0.3, -0.3, 7.0, -1e308, 1e300, "auto", "standby", "alarm", None, True, [1], {"v": 2},
                            "route", {"Kp": -1.0}, {"Kp": 1e308}))
        path = rng.choice((TARGET_HEADING, AUTOPILOT_STATE, MODE, PROFILE, GAINS, "navigation.headingTrue", "",
                           "a" * 300))
        msg = json.dumps({"context": rng.choice(("vessels.self", "vessels.x", "*", 5)),
                          "updates": [{"values": [{"path": path, "value": value}]}]}).encode()
    else:
        msg = _fuzz_message(rng)
        msg = (msg.encode("utf-8", "surrogatepass") if isinstance(msg, str) else msg)[:60_000]
    if rng.random() < 0.1:
        return msg
    if not _SIGNALK_SIGNER:
        _SIGNALK_SIGNER.append(DeltaSigner(KEY))
    return _SIGNALK_SIGNER[0].sign(msg.decode("utf-8", "replace"), time.time())


class _Meter:
    """Per-call thread CPU (outside the GC) and wall time of wrapped handlers, and exceptions."""

    def __init__(self, clock):
        self.clock = clock
        self.kind = None
        self.cpu: dict = {k: [] for k in KINDS}
        self.wall: dict = {k: [] for k in KINDS}
        self.errors: dict = {k: [] for k in KINDS}
        self.fuzz_sources: set = set()      #: the fuzzers' socket addresses
        self.handled: dict = {k: 0 for k in KINDS}   #: calls with a fuzz message

    def wrap(self, obj, name, kind, addr_arg: int | None = 1):
        """Time ``obj.name``; calls whose argument ``addr_arg`` is a fuzzer's address (or every
        call, ``addr_arg=None``) count as handled fuzz messages."""
        orig = getattr(obj, name)

        def timed(*a, **k):
            if addr_arg is None or (len(a) > addr_arg and a[addr_arg] in self.fuzz_sources):
                self.handled[kind] += 1
            c, w = self.clock.now(), time.perf_counter()
            try:
                return orig(*a, **k)
            except Exception as err:           # counted, never hidden: the run fails on any
                self.errors[kind].append(f"{type(err).__name__}: {err}"[:200])
                return None
            finally:
                self.cpu[kind].append(self.clock.now() - c)
                self.wall[kind].append(time.perf_counter() - w)

        setattr(obj, name, timed)


async def _lag_probe(lags: list, stop: asyncio.Event, period: float = 0.005) -> None:
    loop = asyncio.get_running_loop()
    while not stop.is_set():
        t = loop.time()
        await asyncio.sleep(period)
        lags.append((loop.time() - t - period, t))


async def _udp_phase(kind, make, targets, n, rng, meter):
    """Send ``n`` datagrams round-robin to ``targets``, yielding to the loop after each one and
    waiting for it to catch up every 32 (so the kernel's socket buffer does not overflow)."""
    socks = [socket.socket(socket.AF_INET, socket.SOCK_DGRAM) for _ in targets]
    try:
        for s in socks:
            s.setblocking(False)
            s.bind(("127.0.0.1", 0))
            meter.fuzz_sources.add(s.getsockname()[:2])
        for i in range(n):
            j = i % len(targets)
            try:
                socks[j].sendto(make(rng), targets[j])
            except (BlockingIOError, OSError):
                pass
            await asyncio.sleep(0)
            if i % 32 == 31:
                end = time.monotonic() + 1.0
                while meter.handled[kind] < i + 1 and time.monotonic() < end:
                    await asyncio.sleep(0.001)
        end = time.monotonic() + 5.0                  # let the loop read what is queued
        while meter.handled[kind] < n and time.monotonic() < end:
            await asyncio.sleep(0.01)
    finally:
        for s in socks:
            s.close()


async def _ws_phase(url, n, rng, meter):
    from websockets.asyncio.client import connect
    from websockets.exceptions import ConnectionClosed
    from test_runtime_web_fuzz import _fuzz_message

    sent = 0
    while sent < n:
        try:
            async with connect(url, max_size=2**20, open_timeout=10, close_timeout=1) as ws:
                while sent < n:
                    msg = _fuzz_message(rng)
                    if len(msg) > 60_000:            # (the WebSocket layer closes larger ones)
                        continue
                    await ws.send(msg)
                    sent += 1
                    await asyncio.sleep(0)
                    if sent % 32 == 0:
                        end = time.monotonic() + 2.0
                        while meter.handled["WebSocket messages"] < sent and time.monotonic() < end:
                            await asyncio.sleep(0.001)
                end = time.monotonic() + 10.0
                while meter.handled["WebSocket messages"] < sent and time.monotonic() < end:
                    await asyncio.sleep(0.01)
        except ConnectionClosed:
            continue
    return sent


async def fuzz_runtime(controller, scenario: dict, n: int = 1000, seed: int = 15, speedup: float = 10.0,
                       clock=None) -> dict:
    """Run the fuzz (see the module docstring); returns ``{kind: stats}`` and ``"autopilot"``.

    ``controller``: a :class:`~steerlab.runtime.controller_runtime.ControllerRuntime` for
    ``scenario`` (sample time 0.125 s). ``clock``: an object with ``now()`` giving thread CPU
    time outside the GC (``test_runtime_web_fuzz._GcClock``); default: a new one.
    """
    from test_runtime_web_fuzz import _GcClock

    own_clock = clock is None
    clock = clock or _GcClock()
    rng = random.Random(seed)
    meter = _Meter(clock)
    loop = asyncio.get_running_loop()
    loop_errors = []
    loop.set_exception_handler(lambda lp, ctx: loop_errors.append(str(ctx.get("message"))[:200]))
    server = ShipServer(scenario_from_dict(scenario), ShipServerConfig(speedup=speedup, centre_after=2.0), key=KEY)
    meter.wrap(server, "on_datagram", "link datagrams")
    srv = asyncio.create_task(server.run())
    while server.transport is None:
        await asyncio.sleep(0.001)
    lo = ("127.0.0.1", 0)
    ap = Autopilot(controller, server.address,
                   AutopilotConfig(speedup=speedup, watchdog_timeout=3.0, input_rate=0.0), heading=0.0, key=KEY,
                   nmea_listen=lo, signalk_listen=lo, signalk_ws=lo)
    meter.wrap(ap, "on_state_datagram", "link datagrams")
    meter.wrap(ap, "on_nmea_datagram", "NMEA lines")
    meter.wrap(ap, "on_signalk_datagram", "Signal K UDP deltas")
    started = asyncio.Event()
    run = asyncio.create_task(ap.run(0.0, started=lambda a: started.set()))
    await started.wait()
    stream = ap.signalk_stream
    stream.limiter.rate = stream.put_limiter.rate = 0.0      # every message parsed (limits: own tests)
    ap.filter.limiter.rate = server.filter.limiter.rate = 0.0
    meter.wrap(stream, "handle_message", "WebSocket messages", addr_arg=None)
    await asyncio.sleep(1.0 / speedup * 5)                     # steering before the fuzz
    samples0 = ap.samples + ap.skipped
    lags: list = []
    stop = asyncio.Event()
    probe = asyncio.create_task(_lag_probe(lags, stop))
    phases = {}
    nmea_port = ap._listeners[0].get_extra_info("sockname")[:2]
    signalk_port = ap._listeners[1].get_extra_info("sockname")[:2]
    link_targets = [ap.transport.get_extra_info("sockname")[:2], server.address]
    try:
        for kind in KINDS:
            t0, lag0 = time.perf_counter(), len(lags)
            if kind == "NMEA lines":
                await _udp_phase(kind, nmea_message, [nmea_port], n, rng, meter)
                sent = n
            elif kind == "link datagrams":
                await _udp_phase(kind, link_message, link_targets, n, rng, meter)
                sent = n
            elif kind == "Signal K UDP deltas":
                await _udp_phase(kind, signalk_message, [signalk_port], n, rng, meter)
                sent = n
            else:
                url = "ws://%s:%d/signalk/v1/stream?subscribe=none" % tuple(stream.address)
                sent = await _ws_phase(url, n, rng, meter)
            phases[kind] = (sent, time.perf_counter() - t0, [lg for lg, _ in lags[lag0:]])
    finally:
        stop.set()
        await probe
        ap.stop()
        await run
        server.stop()
        await srv
        if own_clock:
            clock.close()
    out = {}
    for kind in KINDS:
        sent, seconds, lag = phases[kind]
        cpu, wall = meter.cpu[kind], meter.wall[kind]
        out[kind] = {"sent": sent, "handled": meter.handled[kind], "calls": len(cpu), "exceptions": len(meter.errors[kind]),
                     "errors": meter.errors[kind][:5], "seconds": seconds,
                     "max_cpu_ms": 1e3 * max(cpu, default=0.0), "p99_cpu_ms": 1e3 * _pct(cpu, 99),
                     "max_wall_ms": 1e3 * max(wall, default=0.0),
                     "max_lag_ms": 1e3 * max(lag, default=0.0), "p99_lag_ms": 1e3 * _pct(lag, 99)}
    out["autopilot"] = {"samples_during_fuzz": ap.samples + ap.skipped - samples0, "skipped": ap.skipped,
                        "loop_exceptions": loop_errors, "nmea": dict(ap.nmea_counts),
                        "signalk_udp": dict(ap.signalk_counts), "link": dict(ap.filter.counts), "ship_link": dict(server.filter.counts),
                        "signalk_ws": {k: v for k, v in stream.counts.items() if v},
                        "link_alarm": ap.alarms.first_raised("link")}
    return out


def _pct(xs, q: float) -> float:
    if not xs:
        return 0.0
    s = sorted(xs)
    return s[min(len(s) - 1, int(math.ceil(q / 100.0 * len(s))) - 1)]


def table(res: dict) -> str:
    """A Markdown table of :func:`fuzz_runtime`'s result."""
    rows = ["| messages | sent | handled | exceptions | max CPU per message [ms] | p99 CPU [ms] "
            "| max wall per message [ms] | max loop lag [ms] | p99 loop lag [ms] |",
            "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"]
    for kind in KINDS:
        r = res[kind]
        rows.append(f"| {kind} | {r['sent']} | {r['handled']} | {r['exceptions']} | {r['max_cpu_ms']:.2f} "
                    f"| {r['p99_cpu_ms']:.3f} | {r['max_wall_ms']:.2f} | {r['max_lag_ms']:.1f} | {r['p99_lag_ms']:.1f} |")
    return "\n".join(rows)
