"""Fused closed-loop kernels built from the model, gear, controller and guidance kernels.

One definition, two speeds: :func:`plant_step` builds the RK4 step of ship + steering gear;
:func:`closed_loop` builds the compiled loop used by the single fast run and the batch
engine. The readable engine (:mod:`steerlab.sim.engine`) calls the very same ``plant_step``
and controller/guidance kernels from Python. Factories are memoised per combination, so
each combination compiles once per process (numba cannot disk-cache closures).
"""

from __future__ import annotations

from functools import lru_cache

import numba
import numpy as np

from steerlab.angles import wrap_to_pi
from steerlab.guidance.reference_models import course_reference
from steerlab.metrics_online import accumulate
from steerlab.steering_gear import gear_clamp, gear_rate


@lru_cache(maxsize=None)
def plant_step(ship_rhs):
    """RK4 step of the plant ``[ship states..., delta]`` with the rudder order held (ZOH)."""

    @numba.njit
    def plant_rhs(t, x, delta_cmd, w, ps, pg, dx):
        nd = x.shape[0] - 1
        delta = x[nd]
        ship_rhs(t, x, delta, w, ps, dx)
        dx[nd] = gear_rate(delta, delta_cmd, pg)

    @numba.njit
    def rk4_step(t, x, delta_cmd, w, ps, pg, dt, work):
        """Advance ``x`` in place by one RK4 step; ``work`` is a (5, nx) scratch array."""
        nx = x.shape[0]
        k1 = work[0]
        k2 = work[1]
        k3 = work[2]
        k4 = work[3]
        xt = work[4]
        h2 = 0.5 * dt
        plant_rhs(t, x, delta_cmd, w, ps, pg, k1)
        for i in range(nx):
            xt[i] = x[i] + h2 * k1[i]
        plant_rhs(t + h2, xt, delta_cmd, w, ps, pg, k2)
        for i in range(nx):
            xt[i] = x[i] + h2 * k2[i]
        plant_rhs(t + h2, xt, delta_cmd, w, ps, pg, k3)
        for i in range(nx):
            xt[i] = x[i] + dt * k3[i]
        plant_rhs(t + dt, xt, delta_cmd, w, ps, pg, k4)
        s = dt / 6.0
        for i in range(nx):
            x[i] += s * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
        x[nx - 1] = gear_clamp(x[nx - 1], pg)

    return rk4_step


@lru_cache(maxsize=None)
def closed_loop(ship_rhs, ctrl_update):
    """Compiled closed loop for one (ship, controller) pair.

    ``run(x, z, ps, pg, pc, gd, w, dt, nc, n_steps, rec_every, out_x, out_cmd, out_ref, acc)``
    advances ``x`` (plant state) and ``z`` (controller state) in place over ``n_steps`` steps
    of ``dt``; the controller and the guidance are sampled every ``nc`` steps and the order is
    held in between. Rows ``0, rec_every, 2*rec_every, ...`` (and the final row, if it falls on
    that grid) are written to the ``out_*`` arrays (pass ``rec_every > n_steps`` and 1-row
    arrays to record only the start); the integral metrics accumulate into ``acc``.
    """
    rk4_step = plant_step(ship_rhs)

    @numba.njit
    def run(x, z, ps, pg, pc, gd, w, dt, nc, n_steps, rec_every, out_x, out_cmd, out_ref, acc):
        nx = x.shape[0]
        work = np.empty((5, nx))
        ref = np.zeros(2)
        cmd = 0.0
        h = nc * dt
        j = 0
        for k in range(n_steps + 1):
            t = k * dt
            if k % nc == 0:
                course_reference(t, gd, ref)
                cmd = ctrl_update(z, pc, t, x, ref, h)
            if k % rec_every == 0:
                for i in range(nx):
                    out_x[j, i] = x[i]
                out_cmd[j] = cmd
                out_ref[j, 0] = ref[0]
                out_ref[j, 1] = ref[1]
                j += 1
            if k == n_steps:
                break
            e = wrap_to_pi(ref[0] - x[2])
            delta = x[nx - 1]
            rk4_step(t, x, cmd, w[k], ps, pg, dt, work)
            accumulate(acc, t, e, delta, x[nx - 1], dt)

    return run


@lru_cache(maxsize=None)
def batch_loop(ship_rhs, ctrl_update):
    """Parallel batch over scenarios (numba ``prange``) around :func:`closed_loop`.

    Per-run 2-D inputs have a leading run axis; ``w`` is a stack of disturbance sequences
    shared by index ``w_index[i]`` (so 1000 runs in the same sea store it once).
    """
    run = closed_loop(ship_rhs, ctrl_update)

    @numba.njit(parallel=True)
    def run_batch(X, Z, PS, PG, PC, GD, W, w_index, dt, nc, n_steps, rec_every,
                  out_x, out_cmd, out_ref, ACC):
        for i in numba.prange(X.shape[0]):
            run(X[i], Z[i], PS[i], PG[i], PC[i], GD[i], W[w_index[i]], dt, nc, n_steps,
                rec_every, out_x[i], out_cmd[i], out_ref[i], ACC[i])

    return run_batch
