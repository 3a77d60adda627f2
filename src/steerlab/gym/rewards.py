r"""Reward terms of the Gymnasium environments, selectable by name with a weight each.

``reward=`` takes a name of the compiled rewards (``"speed_loss"``, the default, ``"itae"``,
``"iae"``: :mod:`steerlab.gym.plant_batch`; unchanged, so recorded episodes keep their
numbers), a preset name of :data:`PRESETS`, or a mapping ``{term: weight}`` of the terms
below. The reward of a step is ``-sum_k w_k c_k`` (weights ``w_k >= 0`` in the inverse unit
of their term), with ``e`` the heading error and ``delta`` the rudder angle after the step
[rad], ``delta_prev`` before it, ``dt_env`` the env step [s], ``t`` the time at its end [s]::

    heading       e^2 dt_env                         [rad^2 s]   the squared-error integral (ISE)
    speed_loss    (e^2 + lam delta^2) dt_env         [rad^2 s]   J = e^2 + lambda delta^2, the speed-loss
                                                                 criterion (Koyama; van Amerongen 1982 eq 3.1)
    itae          t |e| dt_env                       [rad s^2]
    iae           |e| dt_env                         [rad s]
    rudder_rate   ((delta - delta_prev)/dt_env)^2 dt_env [rad^2/s] squared rudder rate: chatter and wear
    rudder_travel |delta - delta_prev|               [rad]       rudder travel (steerlab.metrics' rudder_travel)
    reversals     1 per rudder direction reversal    [-]         as steerlab.metrics' rudder_reversals (moves
                                                                 below REVERSAL_EPS rad per step have no direction)
    xte           xte^2 dt_env                       [m^2 s]     cross-track error of a route (track_following;
                                                                 0 without a route)

Presets: ``"autopilot"`` = speed_loss 1, rudder_rate 2 s, reversals 1e-3 (rad^2 s per reversal):
J with the rudder's chatter priced in, the reward the shipped policy was trained on
(docs/learning.md). Without a rate term a policy trained on J alone chatters (hundreds of
degrees of rudder travel where ADRC moves a few tens).
"""

from __future__ import annotations

from typing import Mapping, Union

import numpy as np

from steerlab.errors import InputError
from steerlab.metrics_online import REVERSAL_EPS

TERMS = ("heading", "speed_loss", "itae", "iae", "rudder_rate", "rudder_travel", "reversals", "xte")
TERM_UNITS = {"heading": "rad^2 s", "speed_loss": "rad^2 s", "itae": "rad s^2", "iae": "rad s",
              "rudder_rate": "rad^2/s", "rudder_travel": "rad", "reversals": "-", "xte": "m^2 s"}
PRESETS = {"autopilot": {"speed_loss": 1.0, "rudder_rate": 2.0, "reversals": 1e-3}}


def reward_weights(reward: Union[str, Mapping[str, float]]) -> dict:
    """The ``{term: weight}`` of a preset name or a mapping (checked: known terms, finite
    weights >= 0, at least one term)."""
    if isinstance(reward, str):
        return dict(PRESETS[reward])
    if not isinstance(reward, Mapping) or not reward:
        raise InputError("reward", f"must be a name or a non-empty mapping {{term: weight}}, got {reward!r}")
    out = {}
    for k, w in reward.items():
        if k not in TERMS:
            raise InputError(f"reward.{k}", f"is not a reward term; terms: {', '.join(TERMS)}")
        try:
            w = float(w)
        except (TypeError, ValueError):
            raise InputError(f"reward.{k}", f"must be a number >= 0, got {w!r}") from None
        if not (w >= 0.0 and np.isfinite(w)):
            raise InputError(f"reward.{k}", f"must be finite and >= 0, got {w!r}")
        out[k] = w
    return out


class RewardTerms:
    """The weighted terms for N lanes; keeps each lane's previous rudder angle and direction."""

    def __init__(self, weights: Mapping[str, float], n: int, lam: float, dt_env: float) -> None:
        self.w = dict(weights)
        self.lam, self.dt = float(lam), float(dt_env)
        self.delta_prev = np.zeros(n)
        self.last_dir = np.zeros(n)

    def restart(self, lanes: np.ndarray, delta: np.ndarray) -> None:
        """Lanes that start an episode, with rudder angles ``delta`` [rad]."""
        self.delta_prev[lanes] = delta
        self.last_dir[lanes] = 0.0

    def step(self, stepped: np.ndarray, e: np.ndarray, delta: np.ndarray, t: np.ndarray, xte: np.ndarray,
             bad: np.ndarray, rew: np.ndarray) -> None:
        """Write the reward of the ``stepped`` lanes (bool mask) into ``rew``; 0 for a diverged lane."""
        s = stepped & ~bad
        dt, w = self.dt, self.w
        dd = delta - self.delta_prev
        cost = np.zeros(e.shape[0])
        for k, wk in w.items():
            if k == "heading":
                cost += wk * e * e * dt
            elif k == "speed_loss":
                cost += wk * (e * e + self.lam * delta * delta) * dt
            elif k == "itae":
                cost += wk * t * np.abs(e) * dt
            elif k == "iae":
                cost += wk * np.abs(e) * dt
            elif k == "rudder_rate":
                cost += wk * (dd / dt) ** 2 * dt
            elif k == "rudder_travel":
                cost += wk * np.abs(dd)
            elif k == "xte":
                cost += wk * np.where(np.isfinite(xte), xte, 0.0) ** 2 * dt
        if "reversals" in w:
            moved = np.abs(dd) > REVERSAL_EPS
            d = np.where(dd > 0.0, 1.0, -1.0)
            rev = moved & (self.last_dir != 0.0) & (d != self.last_dir)
            cost += w["reversals"] * rev
            self.last_dir = np.where(moved & s, d, self.last_dir)
        rew[s] = -cost[s]
        rew[stepped & bad] = 0.0
        self.delta_prev = np.where(s, delta, self.delta_prev)
