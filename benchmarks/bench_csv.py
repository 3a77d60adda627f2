#!/usr/bin/env python
"""The time-series CSV writer: steerlab.fast_csv against numpy.savetxt (the previous writer).

Usage::

    python benchmarks/bench_csv.py                    # default run, repeated to 300 000 rows
    python benchmarks/bench_csv.py --rows 1000000 --repeats 3 --json

Workload: the columns of the bundled default run (Esso + ADRC, 3000 s at dt 0.1 s, 18 columns),
tiled to ``--rows`` rows. Both writers run in this process on the same array into files in a
temporary folder; each time is the median of ``--repeats`` after one untimed warm-up (which
compiles or loads the formatter). The files must be byte-identical (checked; exit 1 if not).
Not a test: numbers depend on the machine and its load.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rows", type=int, default=300_000)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args(argv)

    import steerlab as sl
    from steerlab.fast_csv import write_csv

    cols = sl.simulate(sl.default_scenario()).columns()
    base = np.column_stack(list(cols.values()))
    data = np.tile(base, (-(-args.rows // len(base)), 1))[:args.rows]
    header = list(cols)
    with tempfile.TemporaryDirectory() as tmp:
        a, b = Path(tmp) / "savetxt.csv", Path(tmp) / "fast.csv"

        def ref():
            np.savetxt(a, data, delimiter=",", header=",".join(header), comments="", fmt="%.10g")

        def fast():
            write_csv(b, header, data)

        times = {}
        for name, fn in (("savetxt", ref), ("fast_csv", fast)):
            fn()
            runs = []
            for _ in range(args.repeats):
                t0 = time.perf_counter()
                fn()
                runs.append(time.perf_counter() - t0)
            times[name] = statistics.median(runs)
        identical = a.read_bytes() == b.read_bytes()
        size = a.stat().st_size
    out = {"rows": args.rows, "columns": len(header), "bytes": size,
           "savetxt_s": times["savetxt"], "fast_csv_s": times["fast_csv"],
           "speedup": times["savetxt"] / times["fast_csv"],
           "fast_csv_MB_per_s": size / times["fast_csv"] / 1e6, "byte_identical": identical}
    if args.json:
        print(json.dumps(out, indent=2))
    else:
        for k, v in out.items():
            print(f"{k:<20} {v:.4g}" if isinstance(v, float) else f"{k:<20} {v}")
    return 0 if identical else 1


if __name__ == "__main__":
    sys.exit(main())
