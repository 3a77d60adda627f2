#!/usr/bin/env python
"""Start-up of two checkouts of steerlab, side by side: CPU time of whole processes, interleaved.

Usage::

    git worktree add --detach /tmp/old COMMIT
    python benchmarks/bench_startup_ab.py --old /tmp/old --new . --repeats 9
    python benchmarks/bench_startup_ab.py --old /tmp/old --new . --json > ab.json
    python benchmarks/bench_startup_ab.py --old /tmp/old --new . --main /tmp/main   # three sides

Each round runs, in an order shuffled per round (seeded), for both checkouts (``PYTHONPATH`` at
the checkout's ``src``, a driver cache of its own, warmed first; bytecode compiled first):

* ``run``: ``python -m steerlab run --out DIR --quiet`` (the bundled default scenario, the whole
  command);
* ``import``: ``python -c "import steerlab"``;
* ``library``: ``python -c "import steerlab as sl; sl.simulate(sl.default_scenario())"`` (a
  library user's first simulation, warm cache);
* ``help``: ``python -m steerlab --help`` (a command that needs no kernel);

and once the reference ``python -c "import numpy, numba, matplotlib.pyplot"``. Reported: medians of
the CPU time (user + system of the process and the children it waited for, ``getrusage``) and
of the wall time, and the ratios new / old. On a loaded machine the wall time says little and
the CPU time moves less; the ratios of runs interleaved in one session are the figures to read.
"""

from __future__ import annotations

import argparse
import compileall
import json
import os
import random
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

CASES = {
    "run": None,     # filled in with the output directory
    "import": ["-c", "import steerlab"],
    "library": ["-c", "import steerlab as sl; sl.simulate(sl.default_scenario())"],
    "help": ["-m", "steerlab", "--help"],
}


def _cpu_of_children() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def timed(cmd: list[str], env: dict) -> tuple[float, float]:
    """Wall time [s] and CPU time [s] (user + system of the process tree it waited for)."""
    c0, t0 = _cpu_of_children(), time.perf_counter()
    p = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=900)
    dt, cpu = time.perf_counter() - t0, _cpu_of_children() - c0
    if p.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed: {p.stderr.strip()[-600:]}")
    return dt, cpu


def env_for(checkout: Path, cache: Path) -> dict:
    env = {**os.environ, "STEERLAB_CACHE_DIR": str(cache), "MPLBACKEND": "Agg",
           "PYTHONPATH": str(checkout / "src")}
    env.pop("PYTHONDONTWRITEBYTECODE", None)      # as after pip install: bytecode cache on
    return env


def check_imports_from(checkout: Path, env: dict) -> None:
    p = subprocess.run([sys.executable, "-c", "import steerlab; print(steerlab.__file__)"], env=env,
                       capture_output=True, text=True, timeout=300, check=True)
    got = Path(p.stdout.strip()).resolve()
    if not str(got).startswith(str((checkout / "src").resolve())):
        raise RuntimeError(f"steerlab imported from {got}, not from {checkout}")


def measure(sides: dict[str, Path], repeats: int, seed: int = 0, progress=print) -> dict:
    py = sys.executable
    tmp = Path(tempfile.mkdtemp(prefix="steerlab-ab-"))
    jobs = []
    for side, checkout in sides.items():
        compileall.compile_dir(str(checkout / "src" / "steerlab"), quiet=1)
        env = env_for(checkout, tmp / f"cache-{side}")
        check_imports_from(checkout, env)
        for case, args in CASES.items():
            if case == "run":
                args = ["-m", "steerlab", "run", "--out", str(tmp / f"out-{side}"), "--quiet"]
            jobs.append((side, case, [py, *args], env))
    ref_env = env_for(next(iter(sides.values())), tmp / "cache-ref")
    jobs.append(("reference", "import numpy, numba, matplotlib", [py, "-c", "import numpy, numba, matplotlib.pyplot"],
                 ref_env))
    progress("warming each side's caches ...")
    for _, _, cmd, env in jobs:
        timed(cmd, env)
        timed(cmd, env)
    wall: dict = {}
    cpu: dict = {}
    rng = random.Random(seed)
    for i in range(repeats):
        progress(f"round {i + 1}/{repeats}")
        order = list(jobs)
        rng.shuffle(order)
        for side, case, cmd, env in order:
            w, c = timed(cmd, env)
            wall.setdefault((side, case), []).append(w)
            cpu.setdefault((side, case), []).append(c)
    res: dict = {"repeats": repeats, "sides": {k: str(v) for k, v in sides.items()}, "cases": {}}
    for (side, case), c in cpu.items():
        res["cases"][f"{side}: {case}"] = {"cpu_s": round(statistics.median(c), 3),
                                           "wall_s": round(statistics.median(wall[(side, case)]), 3),
                                           "cpu_min_s": round(min(c), 3), "cpu_max_s": round(max(c), 3)}
    names = list(sides)
    if "new" in sides:
        for a in names:
            if a == "new":
                continue
            suffix = "" if a == "old" else f"_vs_{a}"     # new / old; new / each further side
            for what, key in (("cpu", "cpu_s"), ("wall", "wall_s")):
                res[f"ratios_{what}{suffix}"] = {
                    case: round(res["cases"][f"new: {case}"][key] / res["cases"][f"{a}: {case}"][key], 3)
                    for case in CASES}
    load = os.getloadavg() if hasattr(os, "getloadavg") else None
    res["load_average_1min_at_end"] = load[0] if load else None
    return res


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--old", type=Path, required=True, help="the checkout to compare against")
    ap.add_argument("--new", type=Path, default=Path(__file__).resolve().parent.parent)
    ap.add_argument("--main", type=Path, default=None,
                    help="a third checkout measured in the same rounds (ratios new / main as well)")
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args(argv)
    if args.repeats < 1:
        print("bench_startup_ab: error: --repeats: must be >= 1", file=sys.stderr)
        return 2
    for name in ("old", "new", "main"):
        if name == "main" and args.main is None:
            continue
        if not (getattr(args, name) / "src" / "steerlab" / "__init__.py").is_file():
            print(f"bench_startup_ab: error: --{name}: {getattr(args, name)} is not a steerlab checkout", file=sys.stderr)
            return 2
    sides = {"old": args.old.resolve(), "new": args.new.resolve()}
    if args.main is not None:
        sides["main"] = args.main.resolve()
    res = measure(sides, args.repeats, args.seed, progress=lambda m: print(m, file=sys.stderr, flush=True))
    if args.json:
        print(json.dumps(res, indent=2))
    else:
        for k, v in res["cases"].items():
            print(f"{k:45s} CPU {v['cpu_s']:.3f} s  wall {v['wall_s']:.3f} s")
        for k in sorted(k for k in res if k.startswith("ratios_")):
            print(k, res[k])
        print("load", res["load_average_1min_at_end"])
    return 0


if __name__ == "__main__":
    sys.exit(main())
