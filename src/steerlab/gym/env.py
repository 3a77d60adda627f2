r"""Gymnasium environments on steerlab ships: one ship (:class:`SteeringEnv`).

Observation (``Box``, float64; ``observation=``, :mod:`steerlab.gym.observations`):
``"raw"`` (default, shape (3,)) ``[heading error e [rad] in [-pi, pi), yaw rate r
[rad/s] in [-pi, pi], rudder angle delta [rad] in [-pi/2, pi/2]]``, ``e = wrap_to_pi(psi_ref - psi)``;
``"normalised"`` (shape (4,)) ``[e / 0.35 rad, r / 0.01 rad/s, delta / delta_max, r_ref / 0.01 rad/s]``
(:mod:`steerlab.control.policy_observation`: the reference's rate of turn included, every field O(1)).
Action (``Box``, float32, shape (1,), in [-1, 1]): the rudder order as a fraction of the gear's
limit (``order = a * delta_max``), held for ``control_dt`` seconds. An action outside the
space raises :class:`~steerlab.errors.InputError` (no silent clipping).
Reward (``reward=``): ``"speed_loss"`` (default) ``-(e^2 + lam delta^2) * control_dt`` after
the step - the speed-loss criterion (Koyama; van Amerongen 1982 eq 3.1), ``lam`` dimensionless
(default 0.1, as steerlab.metrics.speed_loss_J); ``"itae"`` ``-t |e| control_dt``; ``"iae"``
``-|e| control_dt`` (:mod:`steerlab.gym.plant_batch`); or weighted terms (heading error,
J, rudder rate, rudder travel, reversals, cross-track error: ``reward={"speed_loss": 1,
"rudder_rate": 2}``, or the preset ``"autopilot"``; :mod:`steerlab.gym.rewards`).
Episode: ``episode_s`` seconds (``truncated``); a diverged ship (non-finite state, or a yaw
rate beyond the observation bound) ends it
(``terminated``, ``info["reason"] == "diverged"``, observation zeros).
Seeding: ``reset(seed=s)`` keys the ship's random numbers with ``s`` (an int in [0, 2^128));
each later ``reset()`` starts the next episode of that key (:mod:`steerlab.gym.lane_seas`);
``info`` of a reset: ``episode`` (its number since the seed), ``initial_heading`` [rad]
(and ``sea_seed`` when the sea, having optional blocks, was realised by the scenario
machinery).
Tasks: ``course_keeping`` (``steerlab/CourseKeeping-v0``: hold 0 deg from a seeded initial
offset of up to ``initial_offset_deg``), ``course_change`` (``steerlab/CourseChange-v0``: a
``change_deg`` step of the reference at ``change_t``), ``track_following``
(``steerlab/TrackFollowing-v0``: LOS guidance along a route, ``guidance=`` a scenario
``[guidance]`` table; the heading error is then the one to the LOS heading and
``info["xte"]`` the cross-track error [m]), all in the scenario sea ``environment`` (default
``{"waves": True}``, the coloured wave noise of eq 39).
"""

from __future__ import annotations

from typing import Any, Optional

import gymnasium as gym
import numpy as np
from numpy.typing import ArrayLike

from steerlab.guidance.reference_vector import REF_XTE
from steerlab.gym.episodes import Episodes
from steerlab.gym.observations import observation_space_bounds


def spaces(observation: str = "raw", delta_max: float = 1.0) -> tuple[gym.spaces.Box, gym.spaces.Box]:
    """``(observation_space, action_space)`` of one ship (``observation``: ``"raw"`` or
    ``"normalised"``, :mod:`steerlab.gym.observations`; ``delta_max`` the gear limit [rad])."""
    hi = observation_space_bounds(observation, delta_max)
    obs = gym.spaces.Box(low=-hi, high=hi, shape=hi.shape, dtype=np.float64)
    act = gym.spaces.Box(low=-1.0, high=1.0, shape=(1,), dtype=np.float32)
    return obs, act


class SteeringEnv(gym.Env):
    """One ship (keyword arguments: see :class:`steerlab.gym.episodes.Episodes`)."""

    metadata = {"render_modes": []}

    def __init__(self, task: str = "course_keeping", render_mode: Optional[str] = None, **kw: Any) -> None:
        Episodes.check_keywords(kw, own=("render_mode",))
        self.core = Episodes(1, task=task, **kw)
        self.observation_space, self.action_space = spaces(self.core.observation, self.core.delta_max)
        self.render_mode = render_mode
        self._done = True

    def reset(self, *, seed: Optional[int] = None, options: Optional[dict[str, Any]] = None
              ) -> tuple[np.ndarray, dict[str, Any]]:
        super().reset(seed=seed)
        info = self.core.reset_lanes([0], [seed])[0]
        self._done = False
        return self.core.observed[0].copy(), info

    def step(self, action: ArrayLike) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        if self._done:
            raise RuntimeError("episode over: call reset() first")
        obs, rew, term, trunc = self.core.step(np.asarray(action).reshape(1))
        info: dict[str, Any] = {"t": float(self.core.J[0] * self.core.control_dt)}
        xte = float(self.core.REF[0, REF_XTE])
        if xte == xte:                                   # NaN without a route
            info["xte"] = xte
        if term[0]:
            info["reason"] = "diverged"
        self._done = bool(term[0] or trunc[0])
        return obs[0].copy(), float(rew[0]), bool(term[0]), bool(trunc[0]), info
