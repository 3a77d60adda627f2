#!/usr/bin/env python
"""Benchmark W1 (Esso tanker + steering gear + PID, RK4, 3000 s): prints the results as JSON.

Usage::

    python benchmarks/bench_w1.py                    # full run: batch of 1000, 5 repeats
    python benchmarks/bench_w1.py --n-batch 100 --repeats 3
    python benchmarks/bench_w1.py --quiet > w1.json  # progress goes to stderr

See benchmarks/README.md for what is measured.
"""

from __future__ import annotations

import argparse
import json
import sys

from steerlab.bench import run_bench


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n-batch", type=int, default=1000, help="runs in the batch (default 1000)")
    ap.add_argument("--duration", type=float, default=3000.0, help="simulated time [s] (default 3000)")
    ap.add_argument("--repeats", type=int, default=5, help="timed repetitions, medians reported (default 5)")
    ap.add_argument("--quiet", action="store_true", help="no progress messages on stderr")
    args = ap.parse_args(argv)

    def progress(msg: str) -> None:
        print(f"[bench_w1] {msg}", file=sys.stderr, flush=True)

    result = run_bench(n_batch=args.n_batch, duration=args.duration, repeats=args.repeats,
                       progress=None if args.quiet else progress)
    print(json.dumps(result, indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
