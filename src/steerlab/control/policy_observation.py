r"""The normalised observation of a heading policy: declared once, read by the Gymnasium
environments (``observation="normalised"``, :mod:`steerlab.gym.observations`) and by the
``policy`` controller (:mod:`steerlab.control.policy`), so a trained network sees in the
engines exactly what it saw in training.

Fields (in order; each a raw SI quantity divided by its scale, so typical values are O(1))::

    heading_error   e / E_SCALE          e = wrap_to_pi(psi_ref - psi) [rad],  E_SCALE = 0.35 rad (20 deg)
    yaw_rate        r / R_SCALE          r [rad/s],                            R_SCALE = 0.01 rad/s (0.57 deg/s)
    rudder          delta / delta_max    delta [rad], delta_max the gear's limit [rad]
    reference_rate  r_ref / R_SCALE      r_ref = ref[REF_R] [rad/s], the guidance's rate of turn

The reference enters as the heading error (``psi_ref - psi``) and its rate of turn ``r_ref``
(the feed-forward the classical laws use, e.g. PID's ``Kd (r - r_ref)``); the absolute
heading ``psi_ref`` is left out on purpose: a heading law must not depend on which way is
north. Why scales: a large ship's yaw rate is about 1e-3 rad/s, so in raw radians a network
without observation normalisation (e.g. SB3's ``VecNormalize``) cannot see it.
"""

from __future__ import annotations

import math

import numpy as np

from steerlab.angles import wrap_to_pi
from steerlab.jit.numba_stamped import numba

E_SCALE = 0.35          #: [rad] heading-error scale (20 deg)
R_SCALE = 0.01          #: [rad/s] yaw-rate and reference-rate scale
OBS_FIELDS = ("heading_error", "yaw_rate", "rudder", "reference_rate")
"""The normalised observation's fields, in order."""
OBS_UNITS = ("rad", "rad/s", "rad", "rad/s")
"""The raw quantity's unit of each field (the field itself is dimensionless)."""
N_POLICY_OBS = len(OBS_FIELDS)
P_E, P_R, P_DELTA, P_RREF = range(N_POLICY_OBS)   # noqa: E501  (indices: the order of OBS_FIELDS)


def obs_scales(delta_max: float) -> np.ndarray:
    """The divisor of each field [its raw unit], for a gear limit ``delta_max`` [rad]."""
    return np.array([E_SCALE, R_SCALE, float(delta_max), R_SCALE])


def obs_bounds(delta_max: float) -> np.ndarray:
    """Upper bound of each normalised field (the raw observation's bounds over the scales:
    ``|e| <= pi``, ``|r| <= pi`` rad/s, ``|delta| <= pi/2``, ``|r_ref| <= pi`` rad/s)."""
    return np.array([math.pi, math.pi, math.pi / 2, math.pi]) / obs_scales(delta_max)


@numba.njit(cache=True, inline="always")
def observe_policy(psi_ref, psi, r, delta, r_ref, delta_max, out):
    """Write the normalised observation (module docstring) into ``out[:N_POLICY_OBS]``;
    angles [rad], rates [rad/s]; returns nothing."""
    out[P_E] = wrap_to_pi(psi_ref - psi) / E_SCALE
    out[P_R] = r / R_SCALE
    out[P_DELTA] = delta / delta_max
    out[P_RREF] = r_ref / R_SCALE
