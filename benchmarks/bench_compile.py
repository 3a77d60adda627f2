"""What a driver's compile costs, as steerlab ships it against one of two earlier ways.

``--against inlined`` (the default): every (ship, law, guidance) combination had a loop of its
own with the law and the guidance inlined, where steerlab now compiles one loop per ship that
calls the law and the guidance by address (:mod:`steerlab.jit.loop_calls`), and each law's
and guidance's entry once for every ship. ``--against wrappers``: the fused kernels
(:func:`steerlab.sim.kernels._fuse_options`) with their Python and C wrappers, which steerlab
leaves out (``no_cpython_wrapper``, ``no_cfunc_wrapper``: they are called from compiled code
only).

Each round starts two fresh processes on empty caches, one with the earlier way put back
(patched in the child) and one as steerlab ships, in alternating order; each compiles the
single-run loop of a few (ship, law) combinations and two batch group loops on one ship, and
reports the CPU of each compile. Medians and the ratio (shipped / earlier) over the rounds are
printed; no number of a run can differ (the same operations are inlined into the same loops).

Usage (the machine quiet; about a minute of CPU per round)::

    PYTHONPATH=src python3 benchmarks/bench_compile.py --rounds 3 [--against wrappers]
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile

CHILD = r"""
import json, sys, time
if sys.argv[1] == "wrappers":
    import steerlab.sim.kernels as K
    from steerlab.jit.dispatch import supported_options
    opts = supported_options({"forceinline": True, "_nrt": False, "error_model": "numpy"})
    K._fuse_options = lambda: opts
if sys.argv[1] == "inlined":
    import steerlab.jit.loop_calls as L
    L.by_address = lambda: False
from steerlab.sim.batch import simulate_batch
from steerlab.sim.engine import simulate
from steerlab.sim.scenario import scenario_from_dict
from steerlab.sim.setup import build

def setup(ship, law):
    return build(scenario_from_dict({"ship": {"model": ship}, "controller": {"type": law}, "duration": 20.0}))

out = {}
t = time.process_time(); simulate(setup("nomoto1", "sliding_mode")); out["first compile in the process"] = time.process_time() - t
for ship, law in (("nomoto1", "pid"), ("esso", "adrc"), ("mss-mariner", "lq_pd+wf")):
    s = setup(ship, law)
    t = time.process_time(); simulate(s); out[f"run {ship} + {law}"] = time.process_time() - t
for law in ("pid", "adrc"):
    s = setup("nomoto1", law)
    t = time.process_time(); simulate_batch([s, s, s]); out[f"group nomoto1 + {law}"] = time.process_time() - t
s = setup("esso", "pid")
t = time.process_time(); simulate(s); out["run esso + pid (law and ship seen before)"] = time.process_time() - t
print(json.dumps(out))
"""


def one(variant: str) -> dict:
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, XDG_CACHE_HOME=cache, STEERLAB_CACHE_DIR=os.path.join(cache, "steerlab"))
        proc = subprocess.run([sys.executable, "-c", CHILD, variant], env=env, capture_output=True, text=True,
                              check=True)
    return json.loads(proc.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--against", choices=("inlined", "wrappers"), default="inlined")
    args = ap.parse_args()
    runs: dict[str, list[dict]] = {args.against: [], "shipped": []}
    for k in range(args.rounds):
        order = (args.against, "shipped") if k % 2 == 0 else ("shipped", args.against)
        for variant in order:
            runs[variant].append(one(variant))
            print(f"round {k + 1} {variant}: " + ", ".join(f"{v:.2f}" for v in runs[variant][-1].values()),
                  file=sys.stderr)
    print(f"{'compile [s CPU, median of ' + str(args.rounds) + ']':44s} {args.against:>9s} {'shipped':>9s} {'ratio':>6s}")
    for key in runs["shipped"][0]:
        a = statistics.median(r[key] for r in runs[args.against])
        b = statistics.median(r[key] for r in runs["shipped"])
        print(f"{key:44s} {a:9.2f} {b:9.2f} {b / a:6.2f}")


if __name__ == "__main__":
    main()
