"""Propeller-rate input of ship models: a constant rate or a piecewise-linear schedule.

A ship with an rpm input stores, at some offset ``o`` of its packed record::

    p[o]          constant rate n [rev/s] (used when there is no schedule)
    p[o + 1]      k, the number of schedule points (0: constant)
    p[o + 2 ...]  k times [s] (non-decreasing), then k rates [rev/s]

Scenarios give the schedule as ``[ship.options] rpm_schedule = [[t, rpm], ...]`` (rpm at the
edge, rev/s inside); it is linear between points, held before the first and after the last,
and a repeated time makes a step (e.g. the stepwise rpm reduction of the berthing paper, 2019,
Sec. 4).
"""

from __future__ import annotations

import math

import numba
import numpy as np

MAX_SCHEDULE = 256
MAX_RPM = 5000.0


def check_rpm_schedule(v):
    """pydantic validator body for ``rpm_schedule`` (raises ValueError with the allowed range)."""
    if len(v) > MAX_SCHEDULE:
        raise ValueError(f"at most {MAX_SCHEDULE} points, got {len(v)}")
    last = 0.0
    for i, (t, n) in enumerate(v):
        if not (math.isfinite(t) and 0.0 <= t <= 1e6):
            raise ValueError(f"point {i}: time {t} s out of range (allowed: 0 <= t <= 1e6, non-decreasing)")
        if t < last:
            raise ValueError(f"point {i}: time {t} s is before the previous point's {last} s (must be non-decreasing)")
        if not (math.isfinite(n) and 0.0 <= n <= MAX_RPM):
            raise ValueError(f"point {i}: rpm {n} out of range (allowed: 0 <= rpm <= {MAX_RPM:g})")
        last = t
    return v


def pack_rate(n_rps: float, schedule_rpm=()) -> np.ndarray:
    """The record block described in the module docstring (``schedule_rpm`` in [s, rpm])."""
    k = len(schedule_rpm)
    out = np.zeros(2 + 2 * k)
    out[0] = n_rps
    out[1] = k
    for i, (t, n) in enumerate(schedule_rpm):
        out[2 + i] = t
        out[2 + k + i] = n / 60.0
    return out


@numba.njit(cache=True)
def scheduled_rate(t, p, o):
    """Propeller rate [rev/s] at time ``t`` [s] from the block at offset ``o`` of ``p``."""
    k = int(p[o + 1])
    if k == 0:
        return p[o]
    ts = o + 2
    ns = o + 2 + k
    if t <= p[ts]:
        return p[ns]
    i = k - 1
    while i > 0 and p[ts + i] > t:
        i -= 1
    if i == k - 1:
        return p[ns + k - 1]
    t0 = p[ts + i]
    t1 = p[ts + i + 1]
    return p[ns + i] + (p[ns + i + 1] - p[ns + i]) * (t - t0) / (t1 - t0)
