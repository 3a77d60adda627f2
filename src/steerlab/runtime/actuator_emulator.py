r"""A rudder drive on a serial line, for tests and bench set-ups: ``python -m
steerlab.runtime.actuator_emulator --port /dev/pts/N`` (or ``--fd N``, an open descriptor
such as a pseudo-terminal's master side).

It speaks :mod:`steerlab.runtime.actuator_protocol`: reads ``$PSTLO`` orders and answers
``$PSTLF`` feedback every ``1 / --feedback-hz`` seconds (wall clock). The rudder follows the
order with first-order dynamics and a rate limit, as a steering gear does (``T_sg``, ``rate``)::

    d delta / dt = clip((delta_c - delta) / T_sg, -rate, rate),   |delta| <= limit

and holds still in standby or when no valid order has come for
:data:`~steerlab.runtime.actuator_protocol.ORDER_TIMEOUT` (the drive released). Injected
faults, each triggered by the rudder's own motion so a test needs no clock:

* ``--lose-feedback-above DEG``: once ``|delta|`` passes DEG, no more feedback (a broken
  rudder-angle sensor cable), the rudder still moving;
* ``--stall-above DEG``: once ``|delta|`` passes DEG the rudder stops (jammed), feedback goes on;
* ``--over-current-above DEG``: once past DEG the drive stops and reports status ``C``.

Prints ``actuator emulator: ready`` once it serves, and one line per fault injected, on stdout; ends when a --port device goes or on
a signal (on ``--fd``, a pseudo-terminal's master, it waits while no one has the other side open).
"""

from __future__ import annotations

import argparse
import math
import os
import select
import sys
import time

from steerlab.runtime.actuator_protocol import (ORDER_TIMEOUT, STATUS_OK, STATUS_OVER_CURRENT,
                                                parse_order, render_feedback)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python -m steerlab.runtime.actuator_emulator", description=__doc__.split("\n\n")[0])
    g = p.add_mutually_exclusive_group(required=True)
    g.add_argument("--port", help="serial device to open (pyserial)")
    g.add_argument("--fd", type=int, help="an open file descriptor (a pseudo-terminal master)")
    p.add_argument("--baud", type=int, default=38400)
    p.add_argument("--time-constant", type=float, default=0.5, help="T_sg [s]")
    p.add_argument("--rate", type=float, default=10.0, help="rate limit [deg/s]")
    p.add_argument("--limit", type=float, default=35.0, help="rudder limit [deg]")
    p.add_argument("--feedback-hz", type=float, default=20.0)
    p.add_argument("--lose-feedback-above", type=float, default=None, metavar="DEG")
    p.add_argument("--stall-above", type=float, default=None, metavar="DEG")
    p.add_argument("--over-current-above", type=float, default=None, metavar="DEG")
    a = p.parse_args(argv)
    for name in ("time_constant", "rate", "limit", "feedback_hz"):
        if not (math.isfinite(getattr(a, name)) and getattr(a, name) > 0):
            print(f"--{name.replace('_', '-')}: must be > 0", file=sys.stderr)
            return 2
    port = None
    if a.port:
        import serial

        try:
            port = serial.Serial(a.port, a.baud, timeout=0)
        except (serial.SerialException, OSError) as err:
            print(f"--port: cannot open {a.port!r}: {err}", file=sys.stderr)
            return 2
        fd = port.fileno()
    else:
        fd = a.fd
    os.set_blocking(fd, False)
    delta = 0.0                      # [rad]
    order, engaged, last_order = 0.0, False, -math.inf
    fault = {"lost": False, "stalled": False, "over": False}
    buf = b""
    period = 1.0 / a.feedback_hz
    tau, rate, limit = a.time_constant, math.radians(a.rate), math.radians(a.limit)
    t_prev = time.monotonic()
    next_fb = t_prev
    print("actuator emulator: ready", flush=True)
    while True:
        now = time.monotonic()
        r, _, _ = select.select([fd], [], [], max(0.0, next_fb - now))
        if r:
            try:
                data = os.read(fd, 4096)
            except BlockingIOError:
                data = None
            except OSError:
                if a.port:
                    return 0                              # the device is gone
                time.sleep(period)                        # a pty master: no slave open (yet, or again)
                data = None
            if data == b"" and a.port:
                return 0
            if data:
                buf = (buf + data)[-4096:]
                *lines, buf = buf.split(b"\n")
                for ln in lines:
                    o = parse_order(ln)
                    if o is not None:
                        engaged, last_order = o.engaged, time.monotonic()
                        order = o.angle if o.engaged else order
        now = time.monotonic()
        dt, t_prev = now - t_prev, now
        driving = engaged and now - last_order <= ORDER_TIMEOUT and not (fault["stalled"] or fault["over"])
        if driving:
            delta += max(-rate, min(rate, (order - delta) / tau)) * dt
            delta = max(-limit, min(limit, delta))
        mag = math.degrees(abs(delta))
        for flag, above, what in (("lost", a.lose_feedback_above, "feedback lost"),
                                  ("stalled", a.stall_above, "rudder stalled"),
                                  ("over", a.over_current_above, "over-current")):
            if above is not None and mag > above and not fault[flag]:
                fault[flag] = True
                print(f"fault injected: {what} at rudder {math.degrees(delta):.2f} deg", flush=True)
        if now >= next_fb:
            next_fb = now + period
            if not fault["lost"]:
                line = render_feedback(delta, STATUS_OVER_CURRENT if fault["over"] else STATUS_OK,
                                       2.0 + 10.0 * abs(order - delta) if driving else 0.0)
                try:
                    os.write(fd, line.encode("ascii"))
                except BlockingIOError:
                    pass                                   # nobody reads: drop, as a UART would
                except OSError:
                    return 0


if __name__ == "__main__":
    sys.exit(main())
