#!/usr/bin/env python
"""Run speed of the loops that call the law and the guidance by address, against the loops
with them inlined (what every (ship, law) combination compiled before; what a numba outside
the tested versions still runs): :mod:`steerlab.jit.loop_calls`.

Both ways in one process, alternating, on the same setups (a 20 deg course change in waves,
dt 0.1 s): the single compiled run and a batch of ``--runs`` runs (numba's threads), for each
(ship, law) pair. Prints the median wall time of each and the ratio (by address / inlined);
the numbers of the runs are the same both ways (``tests/test_loop_calls.py``), checked here
too. A cheap ship (nomoto1: a few multiplications per RK4 stage) shows the call's cost the
most.

Usage (the machine quiet)::

    PYTHONPATH=src python3 benchmarks/bench_loop_calls.py [--repeats 7] [--runs 256]
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from steerlab.jit import loop_calls
from steerlab.sim import kernels, lanes
from steerlab.sim.batch import simulate_batch, vary_controller
from steerlab.sim.engine import simulate_compiled
from steerlab.sim.scenario import scenario_from_dict
from steerlab.sim.setup import build

PAIRS = (("nomoto1", "pid"), ("nomoto1", "adrc"), ("esso", "pid"), ("mss-mariner", "lq_pd+wf"),
         ("kvlcc2", "pid"))


def _setup(ship: str, law: str, duration: float):
    return build(scenario_from_dict({
        "dt": 0.1, "duration": duration, "ship": {"model": ship}, "controller": {"type": law},
        "guidance": {"psi0_deg": 0.0, "changes": [{"t": 10.0, "psi_deg": 20.0}]},
        "environment": {"waves": True}}))


def _mode(by_address: bool) -> None:
    loop_calls.by_address = (lambda: True) if by_address else (lambda: False)
    for memo in (kernels.closed_loop, kernels.guided_closed_loop, lanes.batch_loop):
        memo.cache_clear()


def _time(fn) -> float:
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--runs", type=int, default=256)
    ap.add_argument("--duration", type=float, default=1200.0)
    args = ap.parse_args()
    real = loop_calls.by_address
    if not real():
        raise SystemExit("this numba is outside the tested versions: the loops inline the law")
    print(f"{'pair':28s} {'single [ms]':>22s} {'ratio':>6s} {'batch [ms]':>22s} {'ratio':>6s}")
    print(f"{'':28s} {'inlined  by address':>22s} {'':>6s} {'inlined  by address':>22s}")
    for ship, law in PAIRS:
        setup = _setup(ship, law, args.duration)
        setups = vary_controller(setup, np.tile(setup.pc, (args.runs, 1)))
        times: dict = {(m, k): [] for m in (False, True) for k in ("single", "batch")}
        finals = {}
        for m in (False, True):                     # compile (or load) both first
            _mode(m)
            finals[m] = (simulate_compiled(setup).states[-1], simulate_batch(setups[:3]).final_states)
        for a, b in zip(finals[False], finals[True]):
            np.testing.assert_array_equal(a, b)
        for k in range(args.repeats):
            for m in ((False, True) if k % 2 == 0 else (True, False)):
                _mode(m)
                times[m, "single"].append(_time(lambda: simulate_compiled(setup)))
                times[m, "batch"].append(_time(lambda: simulate_batch(setups)))
        med = {key: 1000.0 * statistics.median(v) for key, v in times.items()}
        print(f"{ship + ' + ' + law:28s} {med[False, 'single']:9.1f} {med[True, 'single']:12.1f} "
              f"{med[True, 'single'] / med[False, 'single']:6.2f} {med[False, 'batch']:9.1f} "
              f"{med[True, 'batch']:12.1f} {med[True, 'batch'] / med[False, 'batch']:6.2f}")
    loop_calls.by_address = real


if __name__ == "__main__":
    main()
