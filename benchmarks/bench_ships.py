#!/usr/bin/env python
"""Batch throughput of every ship model with a PID, and whether its kernel vectorises.

Usage::

    python benchmarks/bench_ships.py                 # every ship kernel, 256 runs of 600 s
    python benchmarks/bench_ships.py --runs 64 --ships esso,nomoto1
    python benchmarks/bench_ships.py --json > ships.json

One catalogue entry per ship kernel (entries sharing a kernel run at the same speed). Each
row: the compiled batch in ship-steps/s (median of ``--repeats``), the single compiled run in
steps/s, and :func:`steerlab.sim.lanes.vectorisation_report` (4 vectorised stages = every RK4
stage of the batch runs 8 ships per AVX-512 instruction).
"""

from __future__ import annotations

import argparse
import json
import sys
import time

import numpy as np

from steerlab.ships.registry import _discover
from steerlab.sim.batch import simulate_batch, vary_controller
from steerlab.sim.engine import simulate_compiled
from steerlab.sim.lanes import vectorisation_report
from steerlab.sim.scenario import scenario_from_dict
from steerlab.sim.setup import build

PID = {"type": "pid", "Kp": 1.0, "Kd": 10.0, "Ki": 0.0}


def _median_rate(fn, work: float, repeats: int) -> float:
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return work / float(np.median(times))


def bench_ship(name: str, runs: int, duration: float, repeats: int) -> dict:
    setup = build(scenario_from_dict({
        "dt": 0.1, "duration": duration, "ship": {"model": name}, "controller": PID,
        "guidance": {"psi0_deg": 0.0, "changes": [{"t": 10.0, "psi_deg": 10.0}]},
        "environment": {"waves": True}}))
    setups = vary_controller(setup, np.tile(setup.pc, (runs, 1)))
    simulate_batch(setups[:2])
    simulate_compiled(setup)
    batch = _median_rate(lambda: simulate_batch(setups), runs * setup.n_steps, repeats)
    single = _median_rate(lambda: simulate_compiled(setup), setup.n_steps, 5 * repeats)
    report = vectorisation_report(setup.ship.rhs, setup.controller.update, setup.x0.size)
    return {"ship": name, "kernel": setup.ship.rhs.__name__, "batch_ship_steps_per_s": batch,
            "single_steps_per_s": single, **report}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=256, help="runs per batch (default 256)")
    ap.add_argument("--duration", type=float, default=600.0, help="simulated time [s] (default 600)")
    ap.add_argument("--repeats", type=int, default=3, help="timed batches, median reported (default 3)")
    ap.add_argument("--ships", default="", help="comma-separated ship ids (default: one per kernel)")
    ap.add_argument("--json", action="store_true", help="print JSON instead of a table")
    args = ap.parse_args(argv)
    ships = _discover()
    if args.ships:
        names = [s.strip() for s in args.ships.split(",") if s.strip()]
        unknown = [s for s in names if s not in ships]
        if unknown:
            print(f"--ships: unknown ship(s) {unknown}; known: {sorted(ships)}", file=sys.stderr)
            return 2
    else:
        seen, names = set(), []
        for name, spec in sorted(ships.items()):
            if spec.rhs not in seen:
                seen.add(spec.rhs)
                names.append(name)
    rows = []
    for name in names:
        print(f"[bench_ships] {name} ...", file=sys.stderr, flush=True)
        rows.append(bench_ship(name, args.runs, args.duration, args.repeats))
    if args.json:
        print(json.dumps(rows, indent=2))
        return 0
    print(f"{'ship':28s} {'kernel':18s} {'batch M/s':>10s} {'single M/s':>11s}  vectorised")
    for r in rows:
        vec = "yes" if r["vectorised_stages"] >= 4 and not r["per_run_library_calls"] else "no"
        print(f"{r['ship']:28s} {r['kernel']:18s} {r['batch_ship_steps_per_s'] / 1e6:10.1f} "
              f"{r['single_steps_per_s'] / 1e6:11.2f}  {vec}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
