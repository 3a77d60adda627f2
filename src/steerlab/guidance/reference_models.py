r"""Course-change reference: a schedule of set headings with an optional turn-rate limit.

The reference is stateless (a function of time only), so it is identical in every engine.
Packed record ``g``: the head :data:`SCHEDULE` (declared once, :mod:`steerlab.records`), then
the changes::

    g[G_RATE] rate_max [rad/s]   g[G_PSI0] psi_0 [rad]   g[G_N] n
    g[G_CHANGES + 2 i], g[G_CHANGES + 2 i + 1]      t_i [s], psi_i [rad]   (i = 0 .. n - 1)

``psi_ref`` starts at ``psi_0``; at each ``t_i`` it heads for ``psi_i`` the short way round
(``wrap_to_pi``: 359 deg -> 1 deg is a 2 deg turn to starboard), moving at ``rate_max``
[rad/s] (``0`` = a step). ``r_ref`` is the reference's own rate of turn [rad/s].
"""

from __future__ import annotations

import math

import numpy as np

from steerlab.angles import wrap_to_pi
from steerlab.errors import InputError, require_finite_range
from steerlab.guidance.reference_vector import REF_PSI, REF_R
from steerlab.jit.numba_stamped import numba
from steerlab.records import Field, Layout

SCHEDULE = Layout("guidance", "G_", [
    Field("RATE", "rate_max", "rad/s", "turn-rate limit of the reference (0: a step)", lo=0.0),
    Field("PSI0", "psi0", "rad", "initial set course"),
    Field("N", "n_changes", "-", "number of course changes (t_i, psi_i) after the head", lo=0.0),
], size_name="G_CHANGES")
SCHEDULE.export(globals())       # G_RATE = 0, G_PSI0 = 1, G_N = 2, G_CHANGES = 3


def course_schedule(psi0: float, changes=(), rate_max: float = 0.0) -> np.ndarray:
    """Pack a schedule: ``changes`` is a sequence of ``(t_i [s], psi_i [rad])``."""
    require_finite_range("guidance.rate_max", rate_max, 0.0)
    require_finite_range("guidance.psi0", psi0)
    g = np.empty(G_CHANGES + 2 * len(changes), dtype=np.float64)
    g[:G_CHANGES] = SCHEDULE.pack(rate_max=rate_max, psi0=psi0, n_changes=float(len(changes)))
    t_prev = -math.inf
    for i, (ti, psii) in enumerate(changes):
        require_finite_range(f"guidance.changes[{i}].t", ti, 0.0)
        require_finite_range(f"guidance.changes[{i}].psi", psii)
        if ti < t_prev:
            raise InputError(f"guidance.changes[{i}].t", "course changes must be in time order")
        t_prev = ti
        g[G_CHANGES + 2 * i] = ti
        g[G_CHANGES + 2 * i + 1] = psii
    return g


@numba.njit(cache=True)
def course_reference(t, g, ref):
    """Write ``ref[REF_PSI] = psi_ref`` [rad], ``ref[REF_R] = r_ref`` [rad/s] at time ``t`` [s]."""
    rate = g[G_RATE]
    psi = g[G_PSI0]
    r = 0.0
    n = int(g[G_N])
    for i in range(n):
        ti = g[G_CHANGES + 2 * i]
        if t < ti:
            break
        step = wrap_to_pi(g[G_CHANGES + 2 * i + 1] - psi)
        t_end = t
        if i + 1 < n and g[G_CHANGES + 2 * i + 2] <= t:
            t_end = g[G_CHANGES + 2 * i + 2]
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
