#!/usr/bin/env python
"""Environment steps per second: steerlab's native vector env against gymnasium's SyncVectorEnv.

Usage::

    python benchmarks/bench_env.py                       # N = 1, 64, 1024
    python benchmarks/bench_env.py --n 1,64 --steps 150 --repeats 5 --json
    python benchmarks/bench_env.py --control-dt 0.1     # one RK4 step per env step
    python benchmarks/bench_env.py --threads 2          # the native env on two threads from 512 ships
    python benchmarks/bench_env.py --sb3 --n 8,64       # as SB3 sees it: steerlab.gym.sb3 vs DummyVecEnv
    python benchmarks/bench_env.py --sb3 --subproc --n 8   # ... and SubprocVecEnv (one process per env)
    python benchmarks/bench_env.py --sb3 --subproc --start-method fork --n 8,64   # workers forked (less memory)

Workload: ``steerlab/CourseKeeping-v0`` with its defaults (Esso tanker at 16 kn, gear 35 deg /
2.33 deg/s, eq-39 waves, dt 0.1 s, control_dt 1 s = 10 RK4 steps per env step) but episodes of
120 env steps, so that the 150 timed steps include one autoreset of every ship; random actions
drawn up front. ``--control-dt 0.1`` makes an env step one RK4 step (less physics per step, so
more of a step is the per-call overhead a vector env saves). For each N, in one process:
env-steps/s (N ships x steps / time) of
``gymnasium.make_vec(..., vectorization_mode="vector_entry_point")`` (the whole step of N ships,
autoresets included, in one compiled call) and of ``gymnasium.vector.SyncVectorEnv`` over N
single environments made by ``gymnasium.make`` (its wrappers included), and their ratio.
The two are timed alternately, ``--repeats`` times each after one untimed warm-up (the first
call compiles), each timing the ``--steps`` steps after ``reset(seed=0)`` (repeated until
``--min-time`` seconds, for small N, and averaged); the figures are the medians, by
wall clock and by the process's CPU time (``time.process_time``, all the process's threads).
``reset_ms`` is the median wall time of one reset of all N native ships without a seed (what
an autoreset round costs).

``--sb3``: env-steps/s as Stable-Baselines3 sees them (``VecEnv.step``, what PPO's rollout
calls): steerlab's adapter (:mod:`steerlab.gym.sb3`, same-step autoreset on the native env, the
normalised observation and the ``"autopilot"`` reward terms) against SB3's ``DummyVecEnv`` over N
single environments of the same settings (and ``SubprocVecEnv`` with ``--subproc``: one process
per env), ``--repeats`` alternating timings, medians. ``--start-method`` is SubprocVecEnv's
(default: SB3's, ``forkserver`` on Linux, each worker importing steerlab anew; ``fork``: the
workers share the parent's imports, far less memory at 64 envs); it changes how the workers
start, not the timed steps (a pipe round trip to every worker per step). A SubprocVecEnv's
steps run in its workers, so its ``env_steps_per_cpu_s`` (the parent's CPU) is no cost figure:
read the wall clock.

Threads: the native env runs on one thread unless asked (issue 34: an automatic switch to two
threads from 512 ships ran at 0.65x one thread with the cores busy); ``--threads k`` asks it to
spread a step (and a reset) of ``THREADS_FROM`` = 512 ships or more over k threads with numba's
``prange`` (:meth:`steerlab.gym.episodes.Episodes.step_autoreset`) on the threading layer
steerlab asks for (:mod:`steerlab.jit.threading_layer`: TBB, else workqueue, unless
``NUMBA_THREADING_LAYER`` says otherwise; ``layer`` in the output); ``threads`` in the table
is the number it used at that N (1 below 512, and on workqueue, where threads do not pay).
``SyncVectorEnv`` steps its envs one after the other in one thread. So the **wall** ratio is
the user's figure (what this machine gives an RL loop), and the **CPU** ratio is the per-core one (what a step costs in core time; threads do
not make a step cheaper, they add the hand-over to numba's threads). Two threads cut the
wall time of a 1024-ship step only when a second core is free; with the cores held by other
programs the figure falls to about the one-thread one (compare ``--threads 1``).
Not a test: the numbers depend on the machine and its load (printed with them).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time

import numpy as np


def _time(env, acts, seed=0, min_s=0.0):
    """``(wall, cpu)`` seconds per ``len(acts)`` steps from ``reset(seed=seed)`` (the reset not
    timed), averaged over as many such blocks as take ``min_s`` seconds of wall time."""
    wall = cpu = 0.0
    blocks = 0
    while blocks == 0 or wall < min_s:
        env.reset(seed=seed)
        w0, c0 = time.perf_counter(), time.process_time()
        for a in acts:
            env.step(a)
        wall += time.perf_counter() - w0
        cpu += time.process_time() - c0
        blocks += 1
    return wall / blocks, cpu / blocks


def _reset_ms(env, n, repeats):
    core = env.unwrapped.core
    lanes = np.arange(n)
    times = []
    for _ in range(max(repeats, 3)):
        t0 = time.perf_counter()
        core.reset_lanes(lanes)
        times.append(time.perf_counter() - t0)
    return 1e3 * float(np.median(times))


def _time_sb3(venv, acts, min_s=0.0):
    """``(wall, cpu)`` seconds per ``len(acts)`` SB3 steps after ``seed(0); reset()``."""
    wall = cpu = 0.0
    blocks = 0
    while blocks == 0 or wall < min_s:
        venv.seed(0)
        venv.reset()
        w0, c0 = time.perf_counter(), time.process_time()
        for a in acts:
            venv.step(a)
        wall += time.perf_counter() - w0
        cpu += time.process_time() - c0
        blocks += 1
    return wall / blocks, cpu / blocks


def measure_sb3(n, steps=150, repeats=5, control_dt=1.0, min_s=0.2, subproc=False, start_method=None):
    """One row for ``n`` ships as SB3 sees them (module docstring)."""
    import gymnasium as gym
    from stable_baselines3.common.vec_env import DummyVecEnv, SubprocVecEnv

    import steerlab.gym  # noqa: F401
    from steerlab.gym.sb3 import make_sb3_vec_env

    kw = {"episode_s": 120 * control_dt, "control_dt": control_dt, "observation": "normalised",
          "reward": "autopilot"}
    envs = {"adapter": make_sb3_vec_env("steerlab/CourseKeeping-v0", n, **kw),
            "dummy": DummyVecEnv([lambda: gym.make("steerlab/CourseKeeping-v0", **kw) for _ in range(n)])}
    if subproc:
        envs["subproc"] = SubprocVecEnv([lambda: gym.make("steerlab/CourseKeeping-v0", **kw) for _ in range(n)],
                                        start_method=start_method)
    acts = np.random.default_rng(0).uniform(-1, 1, size=(steps, n, 1)).astype(np.float32)
    for env in envs.values():
        _time_sb3(env, acts[:5])
    t = {k: [] for k in envs}
    for _ in range(repeats):
        for k, env in envs.items():
            t[k].append(_time_sb3(env, acts, min_s=min_s))
    row = {"n": n, "control_dt": control_dt, "steps": steps, "repeats": repeats}
    for k, times in t.items():
        wall, cpu = np.median(np.array(times), axis=0)
        row[f"{k}_env_steps_per_s"] = n * steps / wall
        row[f"{k}_env_steps_per_cpu_s"] = n * steps / cpu
    row["ratio_vs_dummy"] = row["adapter_env_steps_per_s"] / row["dummy_env_steps_per_s"]
    if subproc:
        row["ratio_vs_subproc"] = row["adapter_env_steps_per_s"] / row["subproc_env_steps_per_s"]
    for env in envs.values():
        env.close()
    return row


def measure(n, steps=150, repeats=5, control_dt=1.0, min_s=0.2, threads=1):
    """One row of the table for ``n`` ships (see the module docstring)."""
    import gymnasium as gym

    import steerlab.gym  # noqa: F401  (registers the ids)

    kw = {"episode_s": 120 * control_dt, "control_dt": control_dt}
    native = gym.make_vec("steerlab/CourseKeeping-v0", num_envs=n, vectorization_mode="vector_entry_point",
                          threads=threads, **kw)
    threads = native.unwrapped.core._threads(n)        # what the env used at this N
    sync = gym.vector.SyncVectorEnv([lambda: gym.make("steerlab/CourseKeeping-v0", **kw) for _ in range(n)])
    acts = np.random.default_rng(0).uniform(-1, 1, size=(steps, n, 1)).astype(np.float32)
    for env in (native, sync):                           # warm-up: compiles, touches the memory
        _time(env, acts[:5])
    t = {"native": [], "sync": []}
    for _ in range(repeats):
        t["native"].append(_time(native, acts, min_s=min_s))
        t["sync"].append(_time(sync, acts, min_s=min_s))
    row = {"n": n, "threads": threads, "control_dt": control_dt, "steps": steps, "repeats": repeats}
    for name, times in t.items():
        wall, cpu = np.median(np.array(times), axis=0)
        row[f"{name}_env_steps_per_s"] = n * steps / wall
        row[f"{name}_env_steps_per_cpu_s"] = n * steps / cpu
    row["ratio"] = row["native_env_steps_per_s"] / row["sync_env_steps_per_s"]
    row["ratio_cpu"] = row["native_env_steps_per_cpu_s"] / row["sync_env_steps_per_cpu_s"]
    row["native_reset_all_ms"] = _reset_ms(native, n, repeats)
    native.close()
    sync.close()
    return row


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", default="1,64,1024", help="comma-separated numbers of ships")
    ap.add_argument("--steps", type=int, default=150, help="env steps per timing (> 120: one autoreset inside)")
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--control-dt", type=float, default=1.0,
                    help="env step [s] (the env's default 1 s = 10 RK4 steps of 0.1 s; 0.1: one); "
                         "episodes of 120 steps")
    ap.add_argument("--min-time", type=float, default=0.2,
                    help="each timing repeats its block of steps until this many seconds (small N)")
    ap.add_argument("--threads", type=int, default=None,
                    help="threads of the native env from 512 ships on (default: 1, the env's default)")
    ap.add_argument("--sb3", action="store_true", help="time SB3's VecEnv.step: the adapter against DummyVecEnv")
    ap.add_argument("--subproc", action="store_true", help="with --sb3: SubprocVecEnv too")
    ap.add_argument("--start-method", choices=("fork", "forkserver", "spawn"), default=None,
                    help="with --subproc: how SubprocVecEnv starts its workers (default: SB3's)")
    ap.add_argument("--json", action="store_true")
    a = ap.parse_args(argv)
    import numba

    from steerlab.jit.threading_layer import num_threads

    num_threads()                        # numba's threads on steerlab's layer, before set_num_threads
    if a.threads is not None:
        if not 1 <= a.threads <= numba.config.NUMBA_NUM_THREADS:
            print(f"bench_env.py: --threads must be in [1, {numba.config.NUMBA_NUM_THREADS}], got {a.threads}",
                  file=sys.stderr)
            return 2
        numba.set_num_threads(a.threads)
    rows = []
    if a.sb3:
        for n in (int(v) for v in a.n.split(",")):
            r = measure_sb3(n, a.steps, a.repeats, a.control_dt, a.min_time, a.subproc, a.start_method)
            rows.append(r)
            if not a.json:
                extra = (f"   SubprocVecEnv {r['subproc_env_steps_per_s']:10.3g}   ratio {r['ratio_vs_subproc']:6.1f}x"
                         if a.subproc else "")
                print(f"N={n:5d}  SB3 adapter {r['adapter_env_steps_per_s']:10.3g} env-steps/s   DummyVecEnv "
                      f"{r['dummy_env_steps_per_s']:10.3g}   ratio {r['ratio_vs_dummy']:6.1f}x{extra}", flush=True)
        if a.json:
            print(json.dumps({"workload": "SB3 VecEnv.step, steerlab/CourseKeeping-v0 normalised/autopilot",
                              "start_method": a.start_method,
                              "load_average_1min": os.getloadavg()[0], "rows": rows}, indent=2))
        return 0
    load0 = os.getloadavg()
    for n in (int(v) for v in a.n.split(",")):
        r = measure(n, a.steps, a.repeats, a.control_dt, a.min_time, threads=a.threads or 1)
        rows.append(r)
        if not a.json:
            print(f"N={n:5d}  threads {r['threads']}  native {r['native_env_steps_per_s']:10.3g} env-steps/s   "
                  f"SyncVectorEnv "
                  f"{r['sync_env_steps_per_s']:10.3g}   ratio {r['ratio']:6.1f}x   (CPU time: "
                  f"{r['native_env_steps_per_cpu_s']:9.3g} / {r['sync_env_steps_per_cpu_s']:9.3g} = "
                  f"{r['ratio_cpu']:6.1f}x)   native reset of all N {r['native_reset_all_ms']:7.2f} ms", flush=True)
    load = {"before": load0[0], "after": os.getloadavg()[0], "cores": os.cpu_count()}
    if a.json:
        print(json.dumps({"workload": f"steerlab/CourseKeeping-v0, esso 16 kn, waves, dt 0.1 s, control_dt "
                                      f"{a.control_dt} s, episodes of 120 env steps", "load_average_1min": load,
                          "layer": numba.threading_layer(), "rows": rows}, indent=2))
    else:
        print(f"load average (1 min) {load['before']:.2f} before, {load['after']:.2f} after, {load['cores']} cores; "
              f"numba threading layer {numba.threading_layer()}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
