r"""Nonlinear extended state observer with Han's ``fal`` function.

Source: LOS + ADRC berthing paper (2019), eqs (23)-(25), after Han (2009)::

    e = z1 - y
    z1' = z2 - beta01 e
    z2' = z3 - beta02 fal(e, a01, delta01) + b u
    z3' = -beta03 fal(e, a02, delta02)                                              (24)

    fal(e, a, delta) = |e|^a sgn(e)         |e| >  delta
                       e / delta^(1 - a)    |e| <= delta     (delta > 0)            (25)

With ``a01 = a02 = 1`` ``fal`` is the identity and (24) is the linear ESO of
:mod:`steerlab.control.estimators` (``eso_step`` with ``L = beta``, ``c0 = b``); steerlab
integrates both the same way (forward Euler at the sample time, heading innovation wrapped),
and a test checks they agree. In the linear zone of ``fal`` (``|e| <= delta``) the gains act as
``beta02 / delta01^(1-a01)`` and ``beta03 / delta02^(1-a02)``: :func:`nleso_gains_bandwidth`
uses that to start from the bandwidth gains of ``estimators.eso_gains_bandwidth``.
"""

from __future__ import annotations

import math

import numpy as np

from steerlab.angles import wrap_to_pi
from steerlab.control.estimators import eso_gains_bandwidth
from steerlab.jit.numba_stamped import numba
from steerlab.records import Field, Layout

NLESO = Layout("NLESO state", "E_", [
    Field("Z1", "z1", "rad", "heading estimate z1 of (24)"),
    Field("Z2", "z2", "rad/s", "yaw-rate estimate z2 of (24)"),
    Field("Z3", "z3", "rad/s^2", "total-disturbance estimate z3 of (24)"),
], size_name="N_NLESO")
NLESO.export(globals())  # E_Z1 = 0, E_Z2 = 1, E_Z3 = 2, N_NLESO = 3


@numba.njit(cache=True)
def fal(e, a, delta):
    """Eq (25)."""
    if abs(e) > delta:
        return math.copysign(abs(e) ** a, e)
    return e / delta ** (1.0 - a)


def nleso_gains_bandwidth(omega_o: float, a01: float, delta01: float, a02: float,
                          delta02: float) -> np.ndarray:
    """``beta`` whose linear-zone gains are the triple-pole gains ``[3w, 3w^2, w^3]`` at ``-omega_o``."""
    l1, l2, l3 = eso_gains_bandwidth(omega_o)
    return np.array([l1, l2 * delta01 ** (1.0 - a01), l3 * delta02 ** (1.0 - a02)])


@numba.njit(cache=True)
def nleso_step(zh, i, b, beta1, beta2, beta3, a01, d01, a02, d02, y, u, h):
    """Advance the estimate (layout :data:`NLESO`) held at offset ``i`` of ``zh`` in place by one
    Euler step of (24); ``y`` a heading [rad]."""
    z1 = zh[i + E_Z1]
    z2 = zh[i + E_Z2]
    z3 = zh[i + E_Z3]
    e = wrap_to_pi(z1 - y)
    zh[i + E_Z1] = wrap_to_pi(z1 + h * (z2 - beta1 * e))
    zh[i + E_Z2] = z2 + h * (z3 - beta2 * fal(e, a01, d01) + b * u)
    zh[i + E_Z3] = z3 + h * (-beta3 * fal(e, a02, d02))
