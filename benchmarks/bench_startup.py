#!/usr/bin/env python
"""Start-up speed: what a user waits for, whole processes, against an import-only reference.

Usage::

    python benchmarks/bench_startup.py                  # 5 repeats of each, medians
    python benchmarks/bench_startup.py --repeats 9 --json > startup.json
    python benchmarks/bench_startup.py --skip-cold      # without the cold-cache run
    python benchmarks/bench_startup.py --warm-run-only  # only the reference and the warm default run
    python benchmarks/bench_startup.py --switches       # the command's settings, each switched off

Measured (wall time of whole processes, medians of ``--repeats``; these machines are noisy,
so the figures that matter are the ratios to the reference measured in the same session,
interleaved with the runs):

* ``reference``: ``python -c "import numpy, numba, matplotlib.pyplot"``;
* ``run_default_warm``: ``python -m steerlab run --out DIR --quiet`` on the bundled default
  scenario with a warm driver cache (target: <= 1.5x the reference); with the CPU time (user +
  system of the process and its children) of both, which a loaded machine moves less than the
  wall time;
* ``first_sim_and_batch_beyond_import``: in a fresh process with a warm cache, the time of
  the first ``simulate`` plus the first ``simulate_batch`` (of 32 runs) after
  ``import steerlab`` (target: <= 0.8 s);
* ``first_controller_steps_beyond_import``: in a fresh process with a warm cache, the time of
  designing and stepping a wave-filtered PID (``sl.controller("pid+wf", ship="esso")``, a law
  wrapped at run time) and eight ADRCs in one call (``sl.controllers("adrc", n=8, ...)``), the
  components API's first orders, after ``import steerlab`` (median 1.46 s before the session of
  2026-11-26 afternoon: the wrapped law and the vector step compiled in every process, and
  the wave filter's Nomoto design imported python-control);
* ``run_default_cold``: the default run with an empty driver cache (a fresh
  ``STEERLAB_CACHE_DIR``; target <= 10 s, and it says that it is compiling).

``--switches`` measures what each of the ``steerlab`` command's process-wide settings
(:mod:`steerlab.jit.command`) saves: the warm default run with all of them, with each one
switched off by its environment variable, and with all of them off, interleaved with the
reference (medians of wall and CPU time, and their ratios to the reference's).

Each measurement uses its own cache directory under a temporary folder, so the user's cache
is neither used nor changed. steerlab's sources are compiled to bytecode first and the runs
have Python's bytecode cache on, as after ``pip install`` on a user's machine.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

SRC = Path(__file__).resolve().parent.parent / "src"

FIRST_CALLS = """
import time
t0 = time.perf_counter()
import steerlab
from steerlab.sim.batch import simulate_batch, vary_controller
from steerlab.sim.engine import simulate
from steerlab.sim.scenario import default_scenario
from steerlab.sim.setup import build
t1 = time.perf_counter()
setup = build(default_scenario())
simulate(setup)
import numpy as np
simulate_batch(vary_controller(setup, np.tile(setup.pc, (32, 1))))
t2 = time.perf_counter()
print(t1 - t0, t2 - t1)
"""


def _env(cache: Path) -> dict:
    env = {**os.environ, "STEERLAB_CACHE_DIR": str(cache), "MPLBACKEND": "Agg"}
    # as on a user's machine: Python's bytecode cache on (a sandbox may set PYTHONDONTWRITEBYTECODE,
    # and then every process compiles steerlab's ~150 modules from source, ~0.3 s)
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    env["PYTHONPATH"] = os.pathsep.join(p for p in (str(SRC), os.environ.get("PYTHONPATH")) if p)
    return env


def _cpu_of_children() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def _timed(cmd, env) -> tuple[float, subprocess.CompletedProcess]:
    dt, _, p = _timed_cpu(cmd, env)
    return dt, p


def _timed_cpu(cmd, env) -> tuple[float, float, subprocess.CompletedProcess]:
    """Wall time [s], CPU time (user + system, the process and the children it waited for) [s]."""
    c0 = _cpu_of_children()
    t0 = time.perf_counter()
    p = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=900)
    dt = time.perf_counter() - t0
    if p.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed: {p.stderr.strip()[-400:]}")
    return dt, _cpu_of_children() - c0, p


FIRST_STEPS = """
import time
t0 = time.perf_counter()
import numpy as np
import steerlab as sl
t1 = time.perf_counter()
sl.controller("pid+wf", ship="esso", speed_kn=16.0).reset().step(0.0, 0.0, 0.0, 0.1)
sl.controllers("adrc", n=8, ship="esso", speed_kn=16.0).reset().step(0.0, np.zeros(8), 0.0, 0.1)
t2 = time.perf_counter()
print(t1 - t0, t2 - t1)
"""


def measure(repeats: int, cold: bool, progress=print, first_calls: bool = True) -> dict:
    """The medians and ratios of the module docstring (``first_calls=False``: without the
    first-calls measurement; the CPU times are user + system of the whole process tree)."""
    py = sys.executable
    tmp = Path(tempfile.mkdtemp(prefix="steerlab-startup-"))
    warm = tmp / "warm"
    out = tmp / "out"
    reference_cmd = [py, "-c", "import numpy, numba, matplotlib.pyplot"]
    run_cmd = [py, "-m", "steerlab", "run", "--out", str(out), "--quiet"]
    import compileall

    compileall.compile_dir(str(SRC / "steerlab"), quiet=1)   # what pip install does for a wheel
    progress("warming the cache (default run, first calls) ...")
    _timed(run_cmd, _env(warm))
    _timed([py, "-c", FIRST_CALLS], _env(warm))
    _timed([py, "-c", FIRST_STEPS], _env(warm))
    ref, run, ref_cpu, run_cpu, imports, first, steps = [], [], [], [], [], [], []
    for i in range(repeats):
        progress(f"repeat {i + 1}/{repeats}")
        dt, cpu, _ = _timed_cpu(reference_cmd, _env(warm))
        ref.append(dt)
        ref_cpu.append(cpu)
        dt, cpu, _ = _timed_cpu(run_cmd, _env(warm))
        run.append(dt)
        run_cpu.append(cpu)
        if first_calls:
            _, p = _timed([py, "-c", FIRST_CALLS], _env(warm))
            a, b = (float(v) for v in p.stdout.split())
            imports.append(a)
            first.append(b)
            _, p = _timed([py, "-c", FIRST_STEPS], _env(warm))
            steps.append(float(p.stdout.split()[1]))
    res = {
        "repeats": repeats,
        "reference_s": statistics.median(ref),
        "run_default_warm_s": statistics.median(run),
        "reference_cpu_s": statistics.median(ref_cpu),
        "run_default_warm_cpu_s": statistics.median(run_cpu),
    }
    if first_calls:
        res["import_steerlab_s"] = statistics.median(imports)
        res["first_sim_and_batch_beyond_import_s"] = statistics.median(first)
        res["first_controller_steps_beyond_import_s"] = statistics.median(steps)
    res["run_default_warm_vs_reference"] = res["run_default_warm_s"] / res["reference_s"]
    res["run_default_warm_vs_reference_cpu"] = res["run_default_warm_cpu_s"] / res["reference_cpu_s"]
    load = os.getloadavg() if hasattr(os, "getloadavg") else None
    res["load_average_1min_at_end"] = load[0] if load else None
    if cold:
        colds = []
        said = []
        for i in range(max(1, min(3, repeats))):
            progress(f"cold run {i + 1}")
            dt, p = _timed([py, "-m", "steerlab", "run", "--out", str(out)], _env(tmp / f"cold{i}"))
            colds.append(dt)
            said.append("compiling" in p.stderr)
        res["run_default_cold_s"] = statistics.median(colds)
        res["cold_run_says_compiling"] = all(said)
    res["targets"] = {"run_default_warm_vs_reference": 1.5, "first_sim_and_batch_beyond_import_s": 0.8,
                      "run_default_cold_s": 10.0}
    return res


SWITCHES = {
    "light cache load": {"STEERLAB_LIGHT_CACHE_LOAD": "0"},
    "BLAS probe": {"STEERLAB_BLAS_PROBE": "0"},
    "fast exit": {"STEERLAB_FAST_EXIT": "0"},
    "one OpenBLAS thread": {"STEERLAB_ONE_BLAS_THREAD": "0"},
}
"""The command's settings and the variables that switch each off (:mod:`steerlab.jit.command`)."""


def measure_switches(repeats: int, progress=print) -> dict:
    """The warm default run with all the command's settings, each one off, all off (module
    docstring): medians [s] and ratios to the reference measured in the same rounds."""
    py = sys.executable
    tmp = Path(tempfile.mkdtemp(prefix="steerlab-switches-"))
    warm, out = tmp / "warm", tmp / "out"
    import compileall

    compileall.compile_dir(str(SRC / "steerlab"), quiet=1)
    reference_cmd = [py, "-c", "import numpy, numba, matplotlib.pyplot"]
    run_cmd = [py, "-m", "steerlab", "run", "--out", str(out), "--quiet"]
    every_off = {k: v for env in SWITCHES.values() for k, v in env.items()}
    cases = {"reference": ({}, reference_cmd), "all on": ({}, run_cmd),
             **{f"without {name}": (env, run_cmd) for name, env in SWITCHES.items()},
             "all off": (every_off, run_cmd)}
    progress("warming the cache ...")
    _timed(run_cmd, _env(warm))
    wall: dict = {k: [] for k in cases}
    cpu: dict = {k: [] for k in cases}
    for i in range(repeats):
        progress(f"round {i + 1}/{repeats}")
        for name, (env, cmd) in cases.items():
            e = _env(warm)
            for k in set(every_off) | {"OPENBLAS_NUM_THREADS"}:
                e.pop(k, None)            # each run decides as a user's shell would
            e.update(env)
            dt, c, _ = _timed_cpu(cmd, e)
            wall[name].append(dt)
            cpu[name].append(c)
    res: dict = {"repeats": repeats}
    ref_w, ref_c = statistics.median(wall["reference"]), statistics.median(cpu["reference"])
    for name in cases:
        w, c = statistics.median(wall[name]), statistics.median(cpu[name])
        res[name] = {"wall_s": round(w, 3), "cpu_s": round(c, 3),
                     "wall_vs_reference": round(w / ref_w, 3), "cpu_vs_reference": round(c / ref_c, 3)}
    load = os.getloadavg() if hasattr(os, "getloadavg") else None
    res["load_average_1min_at_end"] = load[0] if load else None
    return res


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--skip-cold", action="store_true")
    ap.add_argument("--warm-run-only", action="store_true",
                    help="only the reference and the warm default run (no first calls, no cold run)")
    ap.add_argument("--switches", action="store_true",
                    help="the warm default run with each of the command's settings switched off")
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args(argv)
    if args.repeats < 1:
        print("bench_startup: error: --repeats: must be >= 1", file=sys.stderr)
        return 2
    if args.switches:
        res = measure_switches(args.repeats, progress=lambda m: print(m, file=sys.stderr, flush=True))
        print(json.dumps(res, indent=2) if args.json else
              "\n".join(f"{k:32s} {v}" for k, v in res.items()))
        return 0
    res = measure(args.repeats, not (args.skip_cold or args.warm_run_only),
                  progress=lambda m: print(m, file=sys.stderr, flush=True), first_calls=not args.warm_run_only)
    if args.json:
        print(json.dumps(res, indent=2))
    else:
        for k, v in res.items():
            print(f"{k:40s} {v}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
