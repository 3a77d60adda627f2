"""Integral metrics accumulated step by step: one definition for every engine.

The compiled batch engine calls :func:`accumulate` inside its loop (no logs needed for big
batches); :mod:`steerlab.metrics` calls the very same kernel over recorded arrays. Integrals
use the rectangle rule on the simulation grid: step ``k`` contributes ``f(t_k) * dt``.
"""

from typing import TYPE_CHECKING

import math

import numpy as np

from steerlab.angles import wrap_to_pi_array
from steerlab.jit.numba_stamped import numba
from steerlab.records import Field, Layout

if TYPE_CHECKING:   # Layout.export below writes this module's index constants: ints, for type checkers
    def __getattr__(name: str) -> int: ...


ACCUMULATOR = Layout("online_metrics", "M_", [
    Field("IAE", "iae", "rad s", "integral of |e| dt"),
    Field("ISE", "ise", "rad^2 s", "integral of e^2 dt"),
    Field("ITAE", "itae", "rad s^2", "integral of t |e| dt"),
    Field("E2_DEG", "int_e2_deg", "deg^2 s", "integral of e^2 dt in degrees (speed-loss J)"),
    Field("D2_DEG", "int_delta2_deg", "deg^2 s", "integral of delta^2 dt in degrees (speed-loss J)"),
    Field("ABS_DELTA", "int_abs_delta", "rad s", "integral of |delta| dt"),
    Field("TRAVEL", "rudder_travel", "rad", "rudder travel, sum of |d delta|"),
    Field("REVERSALS", "rudder_reversals", "-", "number of rudder direction reversals"),
    Field("MAX_ABS_E", "max_abs_e", "rad", "max |e|"),
    Field("DURATION", "duration", "s", "integrated time"),
    Field("LAST_DIR", "last_rudder_dir", "-", "internal: sign of the last rudder move"),
], size_name="N_ACC")
ACCUMULATOR.export(globals())    # M_IAE = 0, ..., N_ACC = 11

REVERSAL_EPS = 1e-9
"""Rudder moves smaller than this [rad per step] do not count as a direction."""

_R2D = 180.0 / math.pi


def new_accumulator() -> np.ndarray:
    return np.zeros(N_ACC)


@numba.njit(cache=True)
def accumulate(acc, t, e, delta, delta_next, dt):
    """Add step ``[t, t + dt)`` with heading error ``e`` and rudder ``delta`` [rad]."""
    ae = abs(e)
    acc[M_IAE] += ae * dt
    acc[M_ISE] += e * e * dt
    acc[M_ITAE] += t * ae * dt
    acc[M_E2_DEG] += (e * _R2D) ** 2 * dt
    acc[M_D2_DEG] += (delta * _R2D) ** 2 * dt
    acc[M_ABS_DELTA] += abs(delta) * dt
    acc[M_DURATION] += dt
    if ae > acc[M_MAX_ABS_E]:
        acc[M_MAX_ABS_E] = ae
    dd = delta_next - delta
    acc[M_TRAVEL] += abs(dd)
    if abs(dd) > REVERSAL_EPS:
        d = 1.0 if dd > 0.0 else -1.0
        if acc[M_LAST_DIR] != 0.0 and d != acc[M_LAST_DIR]:
            acc[M_REVERSALS] += 1.0
        acc[M_LAST_DIR] = d


def online_metrics_from_result(res) -> np.ndarray:
    """Integral metrics of a recorded run (a :class:`~steerlab.sim.result.Result`: ``time``,
    ``psi``, ``psi_ref``, ``delta`` [s, rad], ``dt`` [s]) through the same accumulator the batch
    engine uses: ``e = wrap_to_pi(psi_ref - psi)``, step ``k`` adding ``[t_k, t_k + dt)``.

    Here, below the engine, so that :mod:`steerlab.metrics` reads a result without importing the
    engine (the layers, docs/architecture.md)."""
    acc = new_accumulator()
    e = wrap_to_pi_array(res.psi_ref - res.psi)
    d = res.delta
    dt = res.dt
    for k in range(len(res.time) - 1):
        accumulate(acc, res.time[k], e[k], d[k], d[k + 1], dt)
    return acc
