r"""Manoeuvre program: a piecewise-constant rudder order from a time table.

Drives the turning circle (rudder to ``delta`` at the execute time), the pull-out (rudder
back to midships once the turn is steady) and the direct spiral (a staircase of rudder
angles). Packed parameters (``p[0]`` is the program tag, see :mod:`steerlab.trials.program`)::

    p = [MODE, n, t_1, delta_1, t_2, delta_2, ..., t_n, delta_n]      (t_1 < t_2 < ... [s], delta [rad])

    delta_cmd(t) = 0            for t < t_1
                 = delta_i      for t_i <= t < t_{i+1}

No controller state is used. The order is what the bridge gives; the steering gear (or the
ideal rudder of ``--no-gear``) turns it into the rudder angle.
"""

from __future__ import annotations

from steerlab.jit.numba_stamped import numba
import numpy as np

S_N = 1
S_TABLE = 2


@numba.njit(cache=True)
def schedule_update(z, p, t, x, ref, h):
    """Rudder order [rad] at time ``t`` [s] from the table in ``p`` (see the module docstring)."""
    n = int(p[S_N])
    cmd = 0.0
    for i in range(n):
        if t >= p[S_TABLE + 2 * i]:
            cmd = p[S_TABLE + 2 * i + 1]
        else:
            break
    return cmd


def pack_schedule(mode: float, times, deltas) -> np.ndarray:
    """``[mode, n, t_1, delta_1, ...]`` for increasing ``times`` [s] and ``deltas`` [rad]."""
    times = np.asarray(times, dtype=float)
    deltas = np.asarray(deltas, dtype=float)
    if times.shape != deltas.shape or times.ndim != 1 or len(times) == 0:
        raise ValueError("times and deltas must be 1-D of the same non-zero length")
    if np.any(np.diff(times) <= 0.0):
        raise ValueError("schedule times must increase")
    table = np.column_stack([times, deltas]).ravel()
    return np.concatenate([[float(mode), float(len(times))], table])
