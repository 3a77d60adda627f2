r"""The Gymnasium environments' observations: ``"raw"`` (default) or ``"normalised"``.

``"raw"``: ``[e, r, delta]`` [rad, rad/s, rad] as the compiled step writes it
(:mod:`steerlab.gym.plant_batch`), kept as the default so that recorded episodes and their
hashes do not change. ``"normalised"``: the four fields of
:mod:`steerlab.control.policy_observation` (heading error, yaw rate, rudder, reference rate
of turn, each over a documented scale), the observation the ``policy`` controller computes
from the same plant state and reference vector with the same compiled function, so a network
trained on it runs unchanged in the engines.
"""

from __future__ import annotations

import math

import numpy as np

from steerlab.control.policy_observation import N_POLICY_OBS, obs_bounds, observe_policy
from steerlab.guidance.reference_vector import REF_PSI, REF_R
from steerlab.jit.numba_stamped import numba
from steerlab.ships.state import IPSI, IR

OBSERVATIONS = ("raw", "normalised")


def observation_space_bounds(observation: str, delta_max: float) -> np.ndarray:
    """Upper bounds of the observation (symmetric Box)."""
    if observation == "raw":
        return np.array([math.pi, math.pi, math.pi / 2])  # e [rad], r [rad/s] (180 deg/s: no ship), delta [rad]
    return obs_bounds(delta_max)


@numba.njit(cache=True)
def normalised_lanes(X, REF, bad, delta_max, out):
    """The normalised observation of every lane into ``out`` (N, 4): from the plant state
    ``X[i]`` (heading, yaw rate, rudder last) and the reference ``REF[i]``; zeros for a
    diverged lane (``bad[i]``), as the raw observation."""
    for i in range(X.shape[0]):
        if bad[i]:
            out[i, :] = 0.0
        else:
            x = X[i]
            observe_policy(REF[i, REF_PSI], x[IPSI], x[IR], x[x.shape[0] - 1], REF[i, REF_R], delta_max, out[i])


N_NORMALISED = N_POLICY_OBS
