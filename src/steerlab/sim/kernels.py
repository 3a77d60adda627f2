"""Fused closed-loop kernels built from the model, gear, controller and guidance kernels.

One definition, two speeds: :func:`plant_step` builds the RK4 step of ship + steering gear;
:func:`closed_loop` builds the compiled loop used by the single fast run; the batch engine
(:mod:`steerlab.sim.lanes`) calls the same fused ship + gear kernel, vectorised across runs.
The readable engine (:mod:`steerlab.sim.engine`) calls the very same ``plant_step`` and
controller/guidance kernels from Python. Factories are memoised per combination, so each
combination compiles once per process (numba cannot disk-cache closures).

Every loop takes one kind of guidance kernel, ``guide(t, x, gd, gz, ref, h)`` with a
guidance state ``gz`` and the 6-entry reference vector (:mod:`steerlab.guidance.plan`),
called at each controller sample: LOS, berthing, course-change models with a state, and
the time-only course schedule (:func:`~steerlab.guidance.reference_models.course_guide`).

How the fused loop is made fast (and why the numbers do not change)
--------------------------------------------------------------------
* Every kernel (ship, gear, controller, guidance, metrics) is compiled once more **from its
  own Python function** (``kernel.py_func``) with LLVM-level forced inlining and without
  reference counting (:func:`_fused`). Numba otherwise compiles each kernel into its own
  library and calls it through a real call (arrays exploded into ~7 words each) with an
  atomic incref/decref of every array argument and every array view. The physics is still
  written once; only the compilation flags differ. No ``fastmath``: the same IEEE operations
  in the same order, so the fused loop and the readable loop give bit-identical results.
* Factories may be specialised on the plant state size ``nx`` so that the short per-state
  loops of the RK4 step unroll instead of being vectorised with run-time alias checks.
* Sample and record decisions use counters instead of integer ``%`` per step.
"""

from __future__ import annotations

import types
from functools import lru_cache

import numba
import numpy as np
from numba.core.registry import CPUDispatcher

from steerlab.angles import wrap_to_pi
from steerlab.guidance.reference_models import course_guide
from steerlab.guidance.reference_vector import N_REF, REF_LEG, REF_RPM, REF_XTE
from steerlab.metrics_online import accumulate
from steerlab.steering_gear import gear_clamp, gear_rate

@lru_cache(maxsize=None)
def _fuse_options() -> dict:
    """Numba options for kernels that are inlined into the fused loop.

    ``forceinline`` marks the function ``alwaysinline`` for LLVM; ``_nrt=False`` compiles it
    without reference counting (these kernels never allocate; the loop's scratch arrays are
    allocated by the caller); ``error_model="numpy"`` lets a float division by zero give
    IEEE inf/NaN instead of raising ``ZeroDivisionError``, so a division (``/ T`` in most
    ship models) is one instruction and not a branch to an exception, which would stop the
    batch engine from vectorising the kernel. The records the kernels divide by are validated
    (T != 0 etc.), so no valid scenario divides by zero and the numbers are those of the
    plain kernels. Falls back to plain ``njit`` if this numba rejects the options.
    """
    opts = {"forceinline": True, "_nrt": False, "error_model": "numpy"}
    try:
        probe = numba.njit(**opts)(_probe_kernel)
        probe(np.zeros(2))
    except Exception:  # pragma: no cover - depends on the numba version
        return {}
    return opts


def _probe_kernel(a):
    a[1] = a[0] + 1.0


def _jit_fused(fn):
    return numba.njit(**_fuse_options())(fn)


@lru_cache(maxsize=None)
def _fused(kernel):
    """The same kernel, compiled from its own Python function for the fused loop.

    Kernels it calls through module globals (e.g. ``adrc_update`` -> ``eso_step``) are fused
    the same way, recursively, by rebinding those names in a copy of the function. Under
    ``NUMBA_DISABLE_JIT=1`` kernels are plain functions and are returned as they are.
    """
    py = getattr(kernel, "py_func", None)
    if py is None or not isinstance(kernel, CPUDispatcher):
        return kernel
    g = py.__globals__
    subs = {name: _fused(g[name]) for name in py.__code__.co_names
            if isinstance(g.get(name), CPUDispatcher)}
    if subs:
        py = types.FunctionType(py.__code__, {**g, **subs}, py.__name__, py.__defaults__,
                                py.__closure__)
    return _jit_fused(py)


@numba.njit(inline="always")
def rk4_stage(x, c, k):
    """Classic RK4 (Runge-Kutta 1901/Kutta): a stage's input state ``x + c k``, ``c`` = h/2 or h."""
    return x + c * k


@numba.njit(inline="always")
def rk4_update(x, s6, k1, k2, k3, k4):
    """Classic RK4: the step ``x + (h/6) (k1 + 2 k2 + 2 k3 + k4)``, ``s6 = h/6``.

    These two helpers are the RK4 formula for every engine (the single run's :func:`_plant_kernels`
    and the batch's :mod:`steerlab.sim.lanes`), element by element, so both give the same bits.
    """
    return x + s6 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)


@lru_cache(maxsize=None)
def _plant_kernels(ship_rhs, nx: int = 0):
    """``(rk4, rk4_step)`` for a ship model; ``nx > 0`` specialises on the plant state size."""
    ship = _fused(ship_rhs)
    rate = _fused(gear_rate)
    clamp = _fused(gear_clamp)
    NX = nx

    @_jit_fused
    def plant_rhs(t, x, delta_cmd, w, ps, pg, dx):
        nd = (x.shape[0] if NX == 0 else NX) - 1
        delta = x[nd]
        ship(t, x, delta, w, ps, dx)
        dx[nd] = rate(delta, delta_cmd, pg)

    @_jit_fused
    def rk4(t, x, delta_cmd, w, ps, pg, dt, k1, k2, k3, k4, xt):
        """Advance ``x`` in place by one RK4 step; ``k1..k4``, ``xt`` are (nx,) scratch."""
        nx = x.shape[0] if NX == 0 else NX
        h2 = 0.5 * dt
        plant_rhs(t, x, delta_cmd, w, ps, pg, k1)
        for i in range(nx):
            xt[i] = rk4_stage(x[i], h2, k1[i])
        plant_rhs(t + h2, xt, delta_cmd, w, ps, pg, k2)
        for i in range(nx):
            xt[i] = rk4_stage(x[i], h2, k2[i])
        plant_rhs(t + h2, xt, delta_cmd, w, ps, pg, k3)
        for i in range(nx):
            xt[i] = rk4_stage(x[i], dt, k3[i])
        plant_rhs(t + dt, xt, delta_cmd, w, ps, pg, k4)
        s = dt / 6.0
        for i in range(nx):
            x[i] = rk4_update(x[i], s, k1[i], k2[i], k3[i], k4[i])
        x[nx - 1] = clamp(x[nx - 1], pg)

    @numba.njit
    def rk4_step(t, x, delta_cmd, w, ps, pg, dt, work):
        """Advance ``x`` in place by one RK4 step; ``work`` is a (5, nx) scratch array."""
        rk4(t, x, delta_cmd, w, ps, pg, dt, work[0], work[1], work[2], work[3], work[4])

    return rk4, rk4_step, plant_rhs, clamp


def plant_step(ship_rhs):
    """RK4 step of the plant ``[ship states..., delta]`` with the rudder order held (ZOH).

    ``rk4_step(t, x, delta_cmd, w_row, ps, pg, dt, work)`` advances ``x`` in place;
    ``work`` is a (5, nx) scratch array.
    """
    return _plant_kernels(ship_rhs)[1]


@lru_cache(maxsize=None)
def closed_loop(ship_rhs, ctrl_update, nx: int | None = None, guide=None):
    """Compiled closed loop for one (ship, controller, guidance) combination.

    ``guide`` is a guidance kernel ``guide(t, x, gd, gz, ref, h)`` (see
    :mod:`steerlab.guidance.plan`); ``None`` means the time-only course schedule
    (:func:`~steerlab.guidance.reference_models.course_guide`). The loop is
    :func:`guided_closed_loop`'s.
    """
    return guided_closed_loop(ship_rhs, ctrl_update, course_guide if guide is None else guide, nx)


@lru_cache(maxsize=None)
def guided_closed_loop(ship_rhs, ctrl_update, guide, nx: int | None = None):
    """Compiled closed loop with a guidance kernel ``guide(t, x, gd, gz, ref, h)``.

    ``run(x, z, ps, pg, pc, gd, gz, w, dt, nc, n_steps, rec_every, out_x, out_cmd, out_ref,
    acc, rpm_slot)`` advances ``x`` (plant state) and ``z`` (controller state) in place over
    ``n_steps`` steps of ``dt``; the guidance and the controller are sampled every ``nc``
    steps and the order is held in between. The guidance state ``gz`` is advanced in place;
    ``rpm_slot``: when >= 0, a propeller-rate order of the guidance (``ref[REF_RPM] >= 0``)
    is written to ``ps[rpm_slot]`` at the sample, so ``ps`` must be the run's own copy. Rows
    ``0, rec_every, 2*rec_every, ...`` (and the final row, if it falls on that grid) are
    written to the ``out_*`` arrays (pass ``rec_every > n_steps`` and 1-row arrays to record
    only the start); ``out_ref`` has up to ``N_REF`` columns
    (:mod:`steerlab.guidance.reference_vector`), as many as it has are recorded. The integral
    metrics accumulate into ``acc``.

    ``nx`` (the plant state size, ship states + rudder), when given, specialises the loop on
    it (faster); ``run`` then raises ``ValueError`` for a state of another size.
    """
    NX = 0 if nx is None else int(nx)
    rk4 = _plant_kernels(ship_rhs, NX)[0]
    update = _fused(ctrl_update)
    reference = _fused(guide)
    acc_step = _fused(accumulate)
    wrap = _fused(wrap_to_pi)
    NR = N_REF
    RPM = REF_RPM

    @_jit_fused
    def loop(x, z, ps, pg, pc, gd, gz, w, dt, nc, n_steps, rec_every, out_x, out_cmd, out_ref,
             acc, rpm_slot, k1, k2, k3, k4, xt, ref):
        nx = x.shape[0] if NX == 0 else NX
        nr = min(out_ref.shape[1], NR)
        cmd = 0.0
        h = nc * dt
        j = 0
        kc = 0
        kr = 0
        for k in range(n_steps + 1):
            t = k * dt
            sample = kc == 0
            if sample:
                reference(t, x, gd, gz, ref, h)
                if rpm_slot >= 0 and ref[RPM] >= 0.0:
                    ps[rpm_slot] = ref[RPM]
            e = wrap(ref[0] - x[2])
            if sample:
                cmd = update(z, pc, t, x, ref, h)
            kc += 1
            if kc == nc:
                kc = 0
            if kr == 0:
                for i in range(nx):
                    out_x[j, i] = x[i]
                out_cmd[j] = cmd
                for q in range(nr):
                    out_ref[j, q] = ref[q]
                j += 1
            kr += 1
            if kr == rec_every:
                kr = 0
            if k == n_steps:
                break
            delta = x[nx - 1]
            rk4(t, x, cmd, w[k], ps, pg, dt, k1, k2, k3, k4, xt)
            acc_step(acc, t, e, delta, x[nx - 1], dt)

    @numba.njit
    def run(x, z, ps, pg, pc, gd, gz, w, dt, nc, n_steps, rec_every, out_x, out_cmd, out_ref, acc,
            rpm_slot):
        nx = x.shape[0]
        if NX != 0 and nx != NX:
            raise ValueError("plant state size differs from the one this loop was built for")
        k1 = np.empty(nx)
        k2 = np.empty(nx)
        k3 = np.empty(nx)
        k4 = np.empty(nx)
        xt = np.empty(nx)
        ref = np.zeros(NR)
        ref[RPM] = -1.0
        ref[REF_XTE] = np.nan
        ref[REF_LEG] = -1.0
        loop(x, z, ps, pg, pc, gd, gz, w, dt, nc, n_steps, rec_every, out_x, out_cmd, out_ref, acc,
             rpm_slot, k1, k2, k3, k4, xt, ref)

    return run
