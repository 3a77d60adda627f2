"""Long runtime message fuzz: ``python benchmarks/fuzz_runtime.py [--n 10000] [--seed 15]``.

Starts a ship server and an autopilot (signed link, NMEA/Signal K listeners, Signal K
WebSocket stream) on loopback and sends ``--n`` generated NMEA lines, link datagrams and
WebSocket messages each through real sockets (``tests/runtime_fuzz.py``; the CI-sized run is
``tests/test_runtime_fuzz_loop.py``). Prints the table of docs/reliability.md: per kind the
messages sent and handled, exceptions, the largest and 99th-percentile thread CPU time of one
handler call (outside the GC), the largest wall time of one call and the event loop's lag.
Exits 1 if any exception was raised or any handler call took 50 ms of CPU or more.
"""

from __future__ import annotations

import argparse
import asyncio
import gc
import json
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(ROOT / "src"))

from runtime_fuzz import KINDS, MAX_BLOCK_S, fuzz_runtime, table  # noqa: E402


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=10_000, help="messages of each kind (default 10000)")
    ap.add_argument("--seed", type=int, default=15)
    ap.add_argument("--speedup", type=float, default=10.0, help="ship seconds per wall second (default 10)")
    args = ap.parse_args()
    from test_runtime_e2e import SCENARIO

    from steerlab.runtime.controller_runtime import ControllerRuntime
    from steerlab.sim.scenario import scenario_from_dict

    ctrl = ControllerRuntime(scenario_from_dict(SCENARIO), "pid", 0.125)
    gc.freeze()                       # as the runtime commands do (freeze_startup_heap)
    t0 = time.perf_counter()
    res = asyncio.run(fuzz_runtime(ctrl, SCENARIO, n=args.n, seed=args.seed, speedup=args.speedup))
    print(f"runtime fuzz: {args.n} messages of each kind, seed {args.seed}, speedup {args.speedup:g}, "
          f"{time.perf_counter() - t0:.0f} s\n")
    print(table(res))
    print("\nautopilot during the fuzz: " + json.dumps(res["autopilot"], default=str))
    bad = [k for k in KINDS if res[k]["exceptions"] or res[k]["max_cpu_ms"] >= 1e3 * MAX_BLOCK_S]
    for k in bad:
        print(f"FAILED {k}: {res[k]}")
    return 1 if bad or res["autopilot"]["loop_exceptions"] else 0


if __name__ == "__main__":
    sys.exit(main())
