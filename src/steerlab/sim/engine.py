"""Run one scenario: the readable loop (plain Python around the kernels) or the compiled loop.

Both call the same kernels (ship, gear, RK4 step, controller, guidance); the parity test
checks they give the same numbers. The readable loop is for reading and debugging (it also
runs with ``NUMBA_DISABLE_JIT=1``); the compiled loop is what ``steerlab run`` uses.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Union

import numpy as np

from steerlab.guidance.reference_models import course_guide
from steerlab.guidance.reference_vector import N_REF, REF_NAMES, REF_PSI, REF_R, REF_RPM, initial_reference
from steerlab.metrics_online import accumulate, new_accumulator, online_metrics_from_result
from steerlab.jit.controller_calls import controller_step
from steerlab.sim.kernels import closed_loop, plant_step
from steerlab.sim.result import Result
from steerlab.sim.setup import SimSetup, build

if TYPE_CHECKING:
    from steerlab.sim.scenario import Scenario

ENGINES = ("compiled", "readable")


def _as_setup(scenario_or_setup) -> SimSetup:
    if isinstance(scenario_or_setup, SimSetup):
        return scenario_or_setup
    return build(scenario_or_setup)


def _ref_columns(s: SimSetup) -> int:
    """Reference entries logged: ``[psi_ref, r_ref]`` for a time-only course, else all N_REF."""
    return 2 if s.guide is None else N_REF


def _result(s: SimSetup, X, cmd, ref, engine: str, record_every: int = 1) -> Result:
    time = np.arange(0, X.shape[0] * record_every, record_every) * s.dt   # t_k = k dt, k = 0, N, 2N ...
    w = s.w if record_every == 1 else s.w[::record_every]
    res = Result(time=time, states=X, state_names=s.state_names, state_units=s.state_units,
                 delta_cmd=cmd, psi_ref=ref[:, REF_PSI], r_ref=ref[:, REF_R], disturbance=w,
                 meta={"name": s.name, "seed": s.seed, "ship": s.ship.name,
                       "controller": s.controller.name, "engine": engine, "dt": s.dt,
                       "controller_sample_time": s.nc * s.dt, "n_steps": s.n_steps})
    if record_every != 1:
        res.meta["record_every"] = record_every
    res.meta["ship_dims"] = (float(s.ship.dims[1]), float(s.ship.dims[2]))   # L, B [m] for plots
    if s.guidance is not None and s.guide is not None:
        res.meta["guidance"] = s.guidance
        res.meta["guidance_log"] = {name: ref[:, q].copy() for q, name in enumerate(REF_NAMES) if q >= 2}
    return res


def simulate_readable(scenario_or_setup: Union[Scenario, SimSetup]) -> Result:
    """The closed loop written out step by step in Python (same kernels as the compiled one)."""
    s = _as_setup(scenario_or_setup)
    rk4_step = plant_step(s.ship.rhs)
    update = controller_step(s.controller.update)   # the kernel (a wrapped law: a cached entry calling it)
    x = s.x0.copy()
    z = s.z0.copy()
    nx = x.shape[0]
    N = s.n_steps
    X = np.empty((N + 1, nx))
    cmd_log = np.empty(N + 1)
    work = np.empty((5, nx))
    guide = course_guide if s.guide is None else s.guide   # time-only schedule, or LOS, models ...
    ref = initial_reference()
    ref_log = np.empty((N + 1, _ref_columns(s)))
    gz = s.gz0.copy()
    ps = s.ps.copy()                              # the guidance may order the propeller rate
    slot = s.rpm_slot
    cmd = 0.0
    h = s.nc * s.dt
    for k in range(N + 1):
        t = k * s.dt
        if k % s.nc == 0:                         # controller sample: guidance, then control law
            guide(t, x, s.gd, gz, ref, h)
            if slot >= 0 and ref[REF_RPM] >= 0.0:
                ps[slot] = ref[REF_RPM]
            cmd = update(z, s.pc, t, x, ref, h)
        X[k] = x
        cmd_log[k] = cmd
        ref_log[k] = ref[:ref_log.shape[1]]
        if k == N:
            break
        rk4_step(t, x, cmd, s.w[k], ps, s.pg, s.dt, work)   # ship + gear, order held (ZOH)
    return _result(s, X, cmd_log, ref_log, "readable")


def simulate_compiled(scenario_or_setup: Union[Scenario, SimSetup], record_every: int = 1) -> Result:
    """The compiled closed loop (numba), recording every ``record_every``-th step (steps
    0, N, 2N, ...); the integral metrics are accumulated on every step all the same."""
    s = _as_setup(scenario_or_setup)
    run = closed_loop(s.ship.rhs, s.controller.update, s.x0.shape[0], s.guide)
    x = s.x0.copy()
    z = s.z0.copy()
    N = s.n_steps
    rows = N // record_every + 1
    X = np.empty((rows, x.shape[0]))
    cmd = np.empty(rows)
    acc = new_accumulator()
    ref = np.empty((rows, _ref_columns(s)))
    run(x, z, s.ps.copy(), s.pg, s.pc, s.gd, s.gz0.copy(), s.w, s.dt, s.nc, N, record_every, X, cmd, ref,
        acc, s.rpm_slot)
    res = _result(s, X, cmd, ref, "compiled", record_every)
    res.meta["online_metrics"] = acc
    if record_every != 1:
        res.meta["final_state"] = x.copy()        # the state after the last step (maybe not logged)
    return res


def _thinned(res: Result, record_every: int) -> Result:
    """A full-rate readable run cut to every ``record_every``-th row, its integral metrics kept
    from every step (the compiled engine's log and accumulator, same numbers)."""
    from dataclasses import replace

    acc = online_metrics_from_result(res)
    final = res.states[-1].copy()
    k = slice(None, None, record_every)
    out = replace(res, time=res.time[k], states=res.states[k], delta_cmd=res.delta_cmd[k],
                  psi_ref=res.psi_ref[k], r_ref=res.r_ref[k], disturbance=res.disturbance[k], meta=dict(res.meta))
    out.meta.update(online_metrics=acc, record_every=record_every, final_state=final)
    return out


def simulate(scenario_or_setup: Union[Scenario, SimSetup], engine: str = "compiled", record_every: int = 1) -> Result:
    """Run one scenario (a :class:`Scenario` or a built :class:`SimSetup`).

    ``record_every``: log every N-th step only (``time`` then steps ``k = 0, N, 2N, ...``; the
    last step is logged only if the step count is a multiple of N). The integral metrics
    (``meta["online_metrics"]``) still cover every step; ``meta["final_state"]`` is the state
    after the last step.
    """
    from steerlab.errors import InputError

    if isinstance(record_every, bool) or not isinstance(record_every, (int, np.integer)) or record_every < 1:
        raise InputError("--record-every", f"must be an integer >= 1, got {record_every!r}")
    record_every = int(record_every)
    if engine == "compiled":
        return simulate_compiled(scenario_or_setup, record_every)
    if engine == "readable":
        res = simulate_readable(scenario_or_setup)
        return res if record_every == 1 else _thinned(res, record_every)
    raise InputError("engine", f"must be one of {ENGINES}, got {engine!r}")
