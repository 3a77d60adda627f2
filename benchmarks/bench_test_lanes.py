#!/usr/bin/env python
"""The test suite's wall time with the real-time lane against pytest-xdist's own scheduling.

Usage::

    python benchmarks/bench_test_lanes.py                 # 2 alternating pairs, medians
    python benchmarks/bench_test_lanes.py --repeats 3 --json > lanes.json
    python benchmarks/bench_test_lanes.py -- -m "not slow"   # pytest arguments after --

Runs ``python -m pytest -q`` (the README's test command, on this checkout and its driver cache),
alternating

* ``lanes``: the suite's default, one worker per core plus one for the real-time link's tests,
  compute tests at a lower CPU priority (``tests/xdist_lanes.py``);
* ``per_core``: ``STEERLAB_TEST_LANES=0``, pytest-xdist's own ``-n auto`` (one worker per core)
  and ``load`` scheduling;

and reports for each the median wall time, the median CPU time (user + system of pytest and
every process it waited for) and the cores' use, ``CPU / (cores x wall)``. These machines are
noisy: the pairs alternate so that a slow spell hits both, and the figure that matters is the
ratio of the medians. Warm the driver cache first (``bash .ci/warm-cache``), or the first run
pays the compiles.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import resource
import statistics
import subprocess
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
MODES = {"lanes": {}, "per_core": {"STEERLAB_TEST_LANES": "0"}}


def _children_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def run_suite(mode: str, pytest_args: list[str]) -> dict:
    """One ``python -m pytest -q`` in ``mode``: wall [s], CPU [s], pytest's own duration [s],
    and whether it passed."""
    env = {**os.environ, **MODES[mode], "MPLBACKEND": "Agg"}
    env.pop("PYTHONDONTWRITEBYTECODE", None)            # as .ci/run: bytecode cache on
    c0, t0 = _children_cpu(), time.perf_counter()
    p = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", *pytest_args],
                       cwd=REPO, env=env, capture_output=True, text=True)
    wall, cpu = time.perf_counter() - t0, _children_cpu() - c0
    lines = p.stdout.strip().splitlines()
    last = (lines or [""])[-1]
    m = re.search(r"in ([\d.]+)s", last)
    return {"mode": mode, "wall_s": round(wall, 2), "cpu_s": round(cpu, 2),
            "pytest_s": float(m.group(1)) if m else None, "passed": p.returncode == 0, "summary": last,
            "failed": [line for line in lines if line.startswith(("FAILED ", "ERROR "))]}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeats", type=int, default=2, help="alternating pairs of runs (default 2)")
    ap.add_argument("--json", action="store_true", help="print the runs and medians as JSON")
    ap.add_argument("pytest_args", nargs="*", help="arguments for pytest (after --)")
    args = ap.parse_args(argv)
    if args.repeats < 1:
        ap.error("--repeats: at least 1")
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)
    runs = []
    for i in range(args.repeats):
        for mode in (("lanes", "per_core") if i % 2 == 0 else ("per_core", "lanes")):
            r = run_suite(mode, args.pytest_args)
            runs.append(r)
            print(f"{mode:9s} wall {r['wall_s']:7.1f} s  cpu {r['cpu_s']:7.1f} s  {r['summary']}",
                  *(f"  {line[:300]}" for line in r["failed"]), sep="\n", file=sys.stderr, flush=True)
    out = {"cores": cores, "runs": runs, "median": {}}
    for mode in MODES:
        mine = [r for r in runs if r["mode"] == mode]
        wall = statistics.median(r["wall_s"] for r in mine)
        cpu = statistics.median(r["cpu_s"] for r in mine)
        out["median"][mode] = {"wall_s": wall, "cpu_s": cpu, "core_use": round(cpu / (cores * wall), 3),
                               "all_passed": all(r["passed"] for r in mine)}
    out["wall_ratio_lanes_to_per_core"] = round(out["median"]["lanes"]["wall_s"] / out["median"]["per_core"]["wall_s"], 3)
    if args.json:
        print(json.dumps(out, indent=2))
    else:
        for mode, m in out["median"].items():
            print(f"{mode:9s} median wall {m['wall_s']:7.1f} s, cpu {m['cpu_s']:7.1f} s, "
                  f"core use {m['core_use']:.2f}, all passed: {m['all_passed']}")
        print(f"lanes / per_core wall: {out['wall_ratio_lanes_to_per_core']:.3f}")
    return 0 if all(r["passed"] for r in runs) else 1


if __name__ == "__main__":
    sys.exit(main())
