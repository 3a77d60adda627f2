"""Long fuzz run of scenario files: ``python benchmarks/fuzz_scenarios.py --n 10000 [--seed 1]``.

Writes ``--n`` seeded mutants (``tests/scenario_mutator.py``) into a temporary folder and puts
each through ``steerlab run`` up to the engine (the same check as
``tests/test_fuzz_scenarios.py``: exit 0, or exit 2 with one line of at most 300 characters
naming a field and nothing in ``--out``; never a traceback, never 30 s on one file). Prints
the counts and the first failures; exits 1 if any mutant broke the contract.

``--engine real`` runs the accepted files through the real engine and output writing
(``tests/test_fuzz_scenarios.check_one_real``): exit 0 with finite time series and metrics, or
exit 3 (the divergence error, one line, nothing in ``--out``).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
import traceback
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(ROOT / "src"))

import scenario_mutator  # noqa: E402
import test_fuzz_scenarios as fuzz  # noqa: E402


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=10_000)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--engine", choices=("stub", "real"), default="stub",
                    help="stub: up to the engine; real: run and write the accepted files")
    args = ap.parse_args()
    import shutil

    import steerlab.sim.engine as engine

    check = fuzz.check_one
    if args.engine == "stub":
        engine.simulate = fuzz._stub_simulate
    else:
        check = fuzz.check_one_real
    counts = {"accepted": 0, "diverged": 0, "rejected": 0, "failed": 0}
    failures = []
    slowest = (0.0, "")
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        for i, path in enumerate(scenario_mutator.mutants(args.n, args.seed, tmp / "in")):
            t = time.perf_counter()
            try:
                counts[check(path, tmp / f"out{i}")] += 1
            except BaseException as err:  # noqa: BLE001 - report, go on
                counts["failed"] += 1
                if len(failures) < 20:
                    failures.append(f"{path.name}: {type(err).__name__}: {str(err)[:200]}\n"
                                    + "".join(traceback.format_tb(err.__traceback__)[-2:]))
            slowest = max(slowest, (time.perf_counter() - t, path.name))
            shutil.rmtree(tmp / f"out{i}", ignore_errors=True)      # real runs write megabytes
            if (i + 1) % 1000 == 0:
                print(f"{i + 1} mutants, {time.perf_counter() - t0:.0f} s: {counts}", flush=True)
    print(f"{args.n} mutants (seed {args.seed}, {args.engine} engine) in {time.perf_counter() - t0:.0f} s: {counts}; "
          f"slowest {slowest[0]:.2f} s ({slowest[1]})")
    for f in failures:
        print(f)
    return 1 if counts["failed"] else 0


if __name__ == "__main__":
    sys.exit(main())
