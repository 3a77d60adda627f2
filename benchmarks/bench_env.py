#!/usr/bin/env python
"""Environment steps per second: steerlab's native vector env against gymnasium's SyncVectorEnv.

Usage::

    python benchmarks/bench_gym.py                       # N = 1, 64, 1024
    python benchmarks/bench_gym.py --n 1,64 --steps 150 --json

Workload: ``steerlab/CourseKeeping-v0`` (Esso tanker at 16 kn, gear 35 deg / 2.33 deg/s, eq-39
waves, dt 0.1 s, control_dt 1 s = 10 RK4 steps per env step, 120 s episodes so resets are
included), random actions drawn up front. For each N: env-steps/s (N ships x steps / wall) of
``gymnasium.make_vec(..., vectorization_mode="vector_entry_point")`` (one compiled call for N
ships) and of ``gymnasium.vector.SyncVectorEnv`` over N single environments, and their ratio.
Each figure is the median of ``--repeats`` after one untimed warm-up; ``reset_ms`` is the
median wall time of one reset of all N native ships without a seed (what an autoreset round
costs: the N seas drawn in one call). Not a test: numbers depend on the machine and its load.
"""

from __future__ import annotations

import argparse
import json
import sys
import time

import numpy as np


def _rate(env, n, steps, repeats, seed=0):
    rng = np.random.default_rng(seed)
    acts = rng.uniform(-1, 1, size=(steps, n, 1)).astype(np.float32)
    env.reset(seed=seed)
    for k in range(min(steps, 5)):                       # warm-up (compiles)
        env.step(acts[k])
    times = []
    for _ in range(repeats):
        env.reset(seed=seed)
        t0 = time.perf_counter()
        for k in range(steps):
            env.step(acts[k])
        times.append(time.perf_counter() - t0)
    return n * steps / float(np.median(times))


def _reset_ms(env, n, repeats):
    core = env.unwrapped.core
    times = []
    for _ in range(max(repeats, 3)):
        t0 = time.perf_counter()
        core.reset_lanes(range(n))
        times.append(time.perf_counter() - t0)
    return 1e3 * float(np.median(times))


def main(argv=None) -> int:
    import gymnasium as gym

    import steerlab.gym  # noqa: F401  (registers the ids)

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", default="1,64,1024", help="comma-separated numbers of ships")
    ap.add_argument("--steps", type=int, default=150, help="env steps per timing (> 120: one autoreset inside)")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--json", action="store_true")
    a = ap.parse_args(argv)
    kw = {"episode_s": 120.0}
    rows = []
    for n in (int(v) for v in a.n.split(",")):
        native = gym.make_vec("steerlab/CourseKeeping-v0", num_envs=n, vectorization_mode="vector_entry_point", **kw)
        sync = gym.vector.SyncVectorEnv([lambda: gym.make("steerlab/CourseKeeping-v0", **kw) for _ in range(n)])
        r_native = _rate(native, n, a.steps, a.repeats)
        r_sync = _rate(sync, n, a.steps, a.repeats)
        reset_ms = _reset_ms(native, n, a.repeats)
        rows.append({"n": n, "native_env_steps_per_s": r_native, "sync_env_steps_per_s": r_sync,
                     "ratio": r_native / r_sync, "native_reset_all_ms": reset_ms})
        if not a.json:
            print(f"N={n:5d}  native {r_native:12.4g} env-steps/s   SyncVectorEnv {r_sync:12.4g}   "
                  f"ratio {r_native / r_sync:8.1f}x   native reset of all N {reset_ms:8.2f} ms")
    if a.json:
        print(json.dumps({"workload": "steerlab/CourseKeeping-v0, esso 16 kn, waves, 10 RK4 steps per env step",
                          "rows": rows}, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
