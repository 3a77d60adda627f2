r"""Course-change reference: a schedule of set headings with an optional turn-rate limit.

The reference is stateless (a function of time only), so it is identical in every engine::

    g = [rate_max, psi_0, n, t_1, psi_1, ..., t_n, psi_n]

``psi_ref`` starts at ``psi_0``; at each ``t_i`` it heads for ``psi_i`` the short way round
(``wrap_to_pi``: 359 deg -> 1 deg is a 2 deg turn to starboard), moving at ``rate_max``
[rad/s] (``0`` = a step). ``r_ref`` is the reference's own rate of turn [rad/s].
"""

from __future__ import annotations

import math

import numba
import numpy as np

from steerlab.angles import wrap_to_pi
from steerlab.errors import InputError, require_finite_range
from steerlab.guidance.reference_vector import REF_PSI, REF_R


def course_schedule(psi0: float, changes=(), rate_max: float = 0.0) -> np.ndarray:
    """Pack a schedule: ``changes`` is a sequence of ``(t_i [s], psi_i [rad])``."""
    require_finite_range("guidance.rate_max", rate_max, 0.0)
    require_finite_range("guidance.psi0", psi0)
    g = [rate_max, psi0, float(len(changes))]
    t_prev = -math.inf
    for i, (ti, psii) in enumerate(changes):
        require_finite_range(f"guidance.changes[{i}].t", ti, 0.0)
        require_finite_range(f"guidance.changes[{i}].psi", psii)
        if ti < t_prev:
            raise InputError(f"guidance.changes[{i}].t", "course changes must be in time order")
        t_prev = ti
        g += [ti, psii]
    return np.array(g, dtype=np.float64)


@numba.njit(cache=True)
def course_reference(t, g, ref):
    """Write ``ref[0] = psi_ref`` [rad], ``ref[1] = r_ref`` [rad/s] at time ``t`` [s]."""
    rate = g[0]
    psi = g[1]
    r = 0.0
    n = int(g[2])
    for i in range(n):
        ti = g[3 + 2 * i]
        if t < ti:
            break
        step = wrap_to_pi(g[4 + 2 * i] - psi)
        t_end = t
        if i + 1 < n and g[5 + 2 * i] <= t:
            t_end = g[5 + 2 * i]
        if rate <= 0.0:
            psi = psi + step
            r = 0.0
        else:
            reach = rate * (t_end - ti)
            if reach >= abs(step):
                psi = psi + step
                r = 0.0
            else:
                psi = psi + math.copysign(reach, step)
                r = math.copysign(rate, step)
    ref[REF_PSI] = wrap_to_pi(psi)
    ref[REF_R] = r


@numba.njit(cache=True)
def course_guide(t, x, g, z, ref, h):
    """:func:`course_reference` in the shape of a guidance kernel ``guide(t, x, gd, gz, ref, h)``
    (state, guidance state and sample time unused): the engines' loops take one kind of
    guidance kernel, and a time-only course schedule is this one."""
    course_reference(t, g, ref)
