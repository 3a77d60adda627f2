"""Integral metrics accumulated step by step: one definition for every engine.

The compiled batch engine calls :func:`accumulate` inside its loop (no logs needed for big
batches); :mod:`steerlab.metrics` calls the very same kernel over recorded arrays. Integrals
use the rectangle rule on the simulation grid: step ``k`` contributes ``f(t_k) * dt``.
"""

import math

import numba
import numpy as np

M_IAE, M_ISE, M_ITAE = 0, 1, 2          # [rad s], [rad^2 s], [rad s^2]
M_E2_DEG, M_D2_DEG = 3, 4               # int e^2 dt, int delta^2 dt [deg^2 s] (speed-loss J)
M_ABS_DELTA = 5                         # int |delta| dt [rad s]
M_TRAVEL = 6                            # rudder travel sum |d delta| [rad]
M_REVERSALS = 7                         # number of rudder direction reversals [-]
M_MAX_ABS_E = 8                         # max |e| [rad]
M_DURATION = 9                          # integrated time [s]
M_LAST_DIR = 10                         # internal: sign of the last rudder move
N_ACC = 11

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
