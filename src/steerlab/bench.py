"""Benchmark W1: how fast the compiled engines run one autopilot workload.

Workload W1 (through the public API only): the Esso 190 kdwt tanker at 16 kn, steering gear
35 deg / 2.33 deg/s / 1 s, PID (Kp 3.81, Ki 0.00547, Kd 3.95, derivative on yaw rate),
RK4 with dt = 0.1 s, 3000 s, a 20 deg course change at t = 100 s, no disturbance.

:func:`run_bench` measures three things (the compiled ones after a first call, whose time
is reported as ``compile_s`` / ``batch_compile_s`` - near zero if this process had compiled
the loop already - and one untimed warm-up call):

* the single compiled run recording every step (:func:`~steerlab.sim.engine.simulate_compiled`
  on a built setup), in steps/s, and separately including the scenario build;
* a batch of ``n_batch`` runs with Kp and Kd scaled by seeded random factors in [0.5, 1.5]
  (:func:`~steerlab.sim.batch.vary_controller` + :func:`~steerlab.sim.batch.simulate_batch`),
  in ship-steps/s (``n_batch * n_steps / wall``); run 0 keeps the unscaled gains;
* a plain-Python reference of the *same* model in the same process: the readable loop
  (:func:`~steerlab.sim.engine.simulate_readable`) run over the kernels' pure-Python
  functions (numba's ``py_func``), obtained by :func:`pure_python` - no physics is written
  again here. It runs over a shorter duration (300 s by default).

Timings are medians over ``repeats`` (``SINGLE_REPEATS * repeats`` for the short single run).
The C figure is quoted, not measured here.
"""

from __future__ import annotations

import dataclasses
import os
import platform
import time
import types
from functools import lru_cache
from typing import Callable, Optional

import numpy as np

from steerlab.jit import loop_calls
from steerlab.jit.dispatch import is_dispatcher
from steerlab.jit.numba_stamped import numba
from steerlab.sim.batch import simulate_batch, vary_controller
from steerlab.sim.engine import simulate_compiled, simulate_readable
from steerlab.sim.kernels import plant_step
from steerlab.sim.lanes import LANES, vectorisation_report
from steerlab.sim.scenario import Scenario, scenario_from_dict
from steerlab.sim.setup import SimSetup, build

W1 = {
    "name": "W1-esso-pid-course-change",
    "description": "Esso tanker 16 kn, gear 35 deg/2.33 deg/s/1 s, PID, RK4 dt 0.1 s, "
                   "20 deg course change at t = 100 s, no disturbance",
    "seed": 0,
    "dt": 0.1,
    "duration": 3000.0,
    "ship": {"model": "esso", "speed_kn": 16.0},
    "gear": {"delta_max_deg": 35.0, "rate_max_deg_s": 2.33, "T_sg": 1.0},
    "controller": {"type": "pid", "Kp": 3.81, "Ki": 0.00547, "Kd": 3.95},
    "guidance": {"psi0_deg": 0.0, "changes": [{"t": 100.0, "psi_deg": 20.0}]},
    "environment": {"waves": False},
}
"""Workload W1 as a scenario dict (the TOML shape)."""

C_REFERENCE_STEPS_PER_S = 13.8e6
C_REFERENCE_NOTE = ("quoted figure of a plain C build of the Esso + PID loop on one core of "
                    "this class of machine (docs/architecture.md, speed reference); not measured here")
PYTHON_REFERENCE_DURATION = 300.0
SINGLE_REPEATS = 5
"""The single run is timed ``SINGLE_REPEATS * repeats`` times (it is short)."""
GAIN_SCALE = (0.5, 1.5)
BATCH_SEED = 20240601


def w1_scenario(duration: float = 3000.0) -> Scenario:
    """The validated W1 scenario with the given duration [s]."""
    return scenario_from_dict({**W1, "duration": float(duration)})


def w1_batch_setups(setup: SimSetup, n: int, seed: int = BATCH_SEED) -> list[SimSetup]:
    """``n`` copies of ``setup`` with Kp and Kd scaled by seeded factors in [0.5, 1.5].

    Run 0 keeps the unscaled gains (so it can be checked against the single run).
    """
    from steerlab.control.pid import C_KD, C_KP

    rng = np.random.default_rng(seed)
    factors = rng.uniform(GAIN_SCALE[0], GAIN_SCALE[1], size=(n, 2))
    factors[0] = 1.0
    rows = np.tile(setup.pc, (n, 1))
    rows[:, C_KP] *= factors[:, 0]
    rows[:, C_KD] *= factors[:, 1]
    return vary_controller(setup, rows)


# --- the plain-Python reference: the same kernels, uncompiled --------------------------------

def _pure_callable(obj):
    """``obj`` itself, or, for a numba dispatcher, its Python function made pure (recursively)."""
    if is_dispatcher(obj):
        return pure_python(obj)
    return obj


@lru_cache(maxsize=None)
def pure_python(kernel):
    """The pure-Python version of a numba kernel, with every kernel it calls pure as well.

    Numba dispatchers keep the original Python function as ``py_func``. Calling ``py_func``
    alone would still call the *compiled* kernels it references (module globals such as
    ``wrap_to_pi``, closure cells such as the ship model inside the RK4 step), so this
    returns a copy of ``py_func`` with those references rebound to their own pure versions.
    The code objects are the original ones: this runs the very same source as the compiled
    engines, interpreted (what ``NUMBA_DISABLE_JIT=1`` does for a whole process).
    """
    fn = getattr(kernel, "py_func", kernel)
    return _rebind(fn)


def _rebind(fn, overrides: Optional[dict] = None):
    code = fn.__code__
    g = fn.__globals__
    subs = {name: _pure_callable(g[name]) for name in code.co_names
            if is_dispatcher(g.get(name))}
    subs.update(overrides or {})
    closure = fn.__closure__
    if closure is not None:
        closure = tuple(types.CellType(_pure_callable(c.cell_contents)) for c in closure)
    return types.FunctionType(code, {**g, **subs}, fn.__name__, fn.__defaults__, closure)


def _pure_plant_step(ship_rhs):
    return pure_python(plant_step(ship_rhs))


@lru_cache(maxsize=None)
def _readable_python():
    """:func:`simulate_readable` with every kernel it reaches in pure Python."""
    return _rebind(simulate_readable, {"plant_step": _pure_plant_step})


def simulate_python(setup: SimSetup):
    """The readable loop over the pure-Python kernels (the plain-Python reference)."""
    ctrl = dataclasses.replace(setup.controller, update=pure_python(setup.controller.update))
    return _readable_python()(dataclasses.replace(setup, controller=ctrl))


# --- timing ------------------------------------------------------------------------------------

def _median_time(fn, repeats: int):
    times = []
    out = None
    for _ in range(max(1, int(repeats))):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return float(np.median(times)), out


def run_bench(n_batch: int = 1000, duration: float = 3000.0, repeats: int = 5,
              progress: Optional[Callable[[str], None]] = None) -> dict:
    """Run workload W1 and return the measurements (see the module docstring).

    Parameters
    ----------
    n_batch : int
        Runs in the batch measurement.
    duration : float
        Simulated time of the single and batch runs [s] (W1: 3000 s).
    repeats : int
        Timed repetitions; medians are reported. The plain-Python reference uses
        ``min(repeats, 3)`` repetitions over ``min(duration, 300 s)``.
    progress : callable(str), optional
        Called with a short message before each phase.
    """
    say = progress or (lambda msg: None)
    n_batch = int(n_batch)
    if n_batch < 1:
        raise ValueError("n_batch must be >= 1")
    scenario = w1_scenario(duration)
    setup = build(scenario)
    N = setup.n_steps

    # (a) single compiled run, recording every step
    say("single: compiling (first call)")
    t0 = time.perf_counter()
    simulate_compiled(setup)
    compile_s = time.perf_counter() - t0
    simulate_compiled(setup)  # untimed warm-up (first-touch of the output buffers)
    # a single W1 run takes a few milliseconds: time SINGLE_REPEATS x as many, so that the
    # median is not at the mercy of one preempted run on a noisy machine
    n_single = SINGLE_REPEATS * max(1, int(repeats))
    say(f"single: {n_single} timed runs of {N} steps")
    t_single, single = _median_time(lambda: simulate_compiled(setup), n_single)
    t_single_build, _ = _median_time(lambda: simulate_compiled(build(scenario)), repeats)

    # (b) batch with varied gains, integral metrics only
    setups = w1_batch_setups(setup, n_batch)
    say("batch: compiling (first call)")
    t0 = time.perf_counter()
    simulate_batch(setups[:2])
    batch_compile_s = time.perf_counter() - t0
    simulate_batch(setups)  # untimed warm-up at full size
    say(f"batch: {repeats} timed batches of {n_batch} runs x {N} steps")
    t_batch, batch = _median_time(lambda: simulate_batch(setups), repeats)
    acc_diff = float(np.max(np.abs(batch.acc[0] - single.meta["online_metrics"])))
    state_diff = float(np.max(np.abs(batch.final_states[0] - single.states[-1])))

    # (c) plain-Python reference: the readable loop over the kernels' Python functions
    py_duration = min(float(duration), PYTHON_REFERENCE_DURATION)
    py_setup = build(w1_scenario(py_duration))
    py_repeats = max(1, min(int(repeats), 3))
    say(f"python reference: {py_repeats} runs of {py_setup.n_steps} steps")
    t_py, py_res = _median_time(lambda: simulate_python(py_setup), py_repeats)
    py_diff = float(np.max(np.abs(py_res.states - simulate_compiled(py_setup).states)))

    single_rate = N / t_single
    batch_rate = n_batch * N / t_batch
    py_rate = py_setup.n_steps / t_py
    say("done")
    return {
        "workload": "W1",
        "description": W1["description"],
        "n_steps": N,
        "dt": setup.dt,
        "duration": float(duration),
        "n_batch": n_batch,
        "repeats": int(repeats),
        "single_steps_per_s": single_rate,
        "single_run_s": t_single,
        "single_steps_per_s_incl_build": N / t_single_build,
        "single_run_s_incl_build": t_single_build,
        "batch_ship_steps_per_s": batch_rate,
        "batch_s": t_batch,
        "python_reference_steps_per_s": py_rate,
        "python_reference_n_steps": py_setup.n_steps,
        "python_reference_max_abs_diff": py_diff,
        "speedup_single_vs_python": single_rate / py_rate,
        "speedup_batch_vs_python": batch_rate / py_rate,
        "c_reference_steps_per_s": C_REFERENCE_STEPS_PER_S,
        "c_reference_note": C_REFERENCE_NOTE,
        "ratio_single_vs_c": single_rate / C_REFERENCE_STEPS_PER_S,
        "ratio_batch_vs_c": batch_rate / C_REFERENCE_STEPS_PER_S,
        "batch_vs_single_acc_max_abs_diff": acc_diff,
        "batch_vs_single_final_state_max_abs_diff": state_diff,
        "compile_s": compile_s,
        "batch_compile_s": batch_compile_s,
        "cores": os.cpu_count(),
        "numba_threads": numba.get_num_threads(),
        "batch_lanes": LANES,
        "batch_vectorisation": vectorisation_report(setup.ship.rhs, setup.controller.update, setup.x0.size),
        "numba_version": numba.__version__,
        "numpy_version": np.__version__,
        "python_version": platform.python_version(),
        "machine": f"{platform.machine()} {platform.processor() or ''}".strip(),
        "jit_disabled": bool(numba.config.DISABLE_JIT),
        "laws_called_by_address": loop_calls.by_address(),
    }
