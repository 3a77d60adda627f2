"""Propeller-rate input of ship models: a constant rate or a piecewise-linear schedule.

A ship with an rpm input stores, at some offset ``o`` of its packed record, the block
:data:`RATE` (declared once, :mod:`steerlab.records`) followed by the schedule::

    p[o + R_N]               constant rate n [rev/s] (used when there is no schedule)
    p[o + R_K]               k, the number of schedule points (0: constant)
    p[o + N_RATE_HEAD ...]   k times [s] (non-decreasing), then k rates [rev/s]

A ship composes its fixed fields with the block by ``PARAMS.then("rpm", RATE)`` (so the rate is
addressable as ``rpm.n``) and packs with :func:`pack_with_rate`.

Scenarios give the schedule as ``[ship.options] rpm_schedule = [[t, rpm], ...]`` (rpm at the
edge, rev/s inside); it is linear between points, held before the first and after the last,
and a repeated time makes a step (e.g. the stepwise rpm reduction of the berthing paper, 2019,
Sec. 4).
"""

from __future__ import annotations

import math

import numpy as np

from steerlab.jit.numba_stamped import numba
from steerlab.records import Field, Layout

MAX_SCHEDULE = 256
MAX_RPM = 5000.0

RATE = Layout("rpm", "R_", [
    Field("N", "n", "rev/s", "constant propeller rate (used when there is no schedule)"),
    Field("K", "n_points", "-", "number of schedule points (0: constant)", lo=0.0, hi=float(MAX_SCHEDULE)),
], size_name="N_RATE_HEAD")
RATE.export(globals())           # R_N = 0, R_K = 1, N_RATE_HEAD = 2


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
    out = np.zeros(N_RATE_HEAD + 2 * k)
    out[:N_RATE_HEAD] = RATE.pack(n=n_rps, n_points=k)
    for i, (t, n) in enumerate(schedule_rpm):
        out[N_RATE_HEAD + i] = t
        out[N_RATE_HEAD + k + i] = n / 60.0
    return out


def pack_with_rate(layout: Layout, values: dict, n_rps: float, schedule_rpm=(), label: str = "rpm") -> np.ndarray:
    """A ship record: ``layout`` (fixed fields, then ``label`` + :data:`RATE`) packed from
    ``values`` and the rate block of :func:`pack_rate`, followed by the schedule."""
    block = pack_rate(n_rps, schedule_rpm)
    head = {f"{label}.{k}": v for k, v in RATE.unpack(block[:N_RATE_HEAD]).items()}
    return np.concatenate([layout.pack({**values, **head}), block[N_RATE_HEAD:]])


@numba.njit(cache=True)
def scheduled_rate(t, p, o):
    """Propeller rate [rev/s] at time ``t`` [s] from the block at offset ``o`` of ``p``."""
    k = int(p[o + R_K])
    if k == 0:
        return p[o + R_N]
    ts = o + N_RATE_HEAD
    ns = o + N_RATE_HEAD + k
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
