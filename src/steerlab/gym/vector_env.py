r"""The native vector environment: N ships stepped in one compiled call.

``gymnasium.make_vec("steerlab/CourseKeeping-v0", num_envs=N, vectorization_mode="vector_entry_point")``
gives a :class:`SteeringVectorEnv`: spaces, reward and episodes as the single
:class:`~steerlab.gym.env.SteeringEnv` (observations (N, 3), actions (N, 1)), all N ships
advanced by the batch engine's vectorised groups of ``LANES`` ships in one compiled call
(:func:`steerlab.gym.plant_batch.vector_stepper`; the single environment steps its ship with
the scalar kernel, with the same numbers). ``reset(seed=s)`` seeds ship i
with ``s + i`` (as gymnasium's ``SyncVectorEnv``), so ship i's episode equals a single
environment's reset with seed ``s + i``. Autoreset: gymnasium's ``NEXT_STEP`` mode (the step
after an episode ends resets that ship and ignores its action; reward 0).
"""

from __future__ import annotations

from typing import Any, Optional, Sequence, Union

import gymnasium as gym
import numpy as np
from numpy.typing import ArrayLike
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from steerlab.gym.env import spaces
from steerlab.gym.episodes import Episodes


class SteeringVectorEnv(VectorEnv):
    metadata = {"render_modes": [], "autoreset_mode": AutoresetMode.NEXT_STEP}

    def __init__(self, num_envs: int = 1, task: str = "course_keeping", render_mode: Optional[str] = None,
                 **kw: Any) -> None:
        self.num_envs = int(num_envs)
        self.core = Episodes(self.num_envs, task=task, vectorised=True, **kw)
        self.single_observation_space, self.single_action_space = spaces()
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self.render_mode = render_mode
        self._autoreset = np.zeros(self.num_envs, dtype=np.bool_)

    def reset(self, *, seed: Union[int, Sequence[Optional[int]], None] = None,
              options: Optional[dict[str, Any]] = None) -> tuple[np.ndarray, dict[str, Any]]:
        n = self.num_envs
        seeds: list[int | None]
        if seed is None:
            seeds = [None] * n
        elif isinstance(seed, int):
            seeds = [seed + i for i in range(n)]
        else:
            seeds = list(seed)
        self.core.reset_lanes(range(n), seeds)
        self._autoreset[:] = False
        return self.core.obs.copy(), {}

    def step(self, actions: ArrayLike
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        c = self.core
        a = np.asarray(actions, dtype=np.float64).reshape(self.num_envs)
        redo = self._autoreset.copy()
        if redo.any():
            a = np.where(redo, 0.0, a)               # the action of a resetting ship is ignored
        obs, rew, term, trunc = c.step(a, active=~redo)
        rew = rew.copy()
        term, trunc = term.copy(), trunc.copy()
        if redo.any():
            c.reset_lanes(np.flatnonzero(redo))
            rew[redo] = 0.0
            term[redo] = False
            trunc[redo] = False
        infos: dict[str, Any] = {}
        if term.any():
            infos["reason"] = np.where(term, "diverged", "")
            infos["_reason"] = term.copy()
        self._autoreset = term | trunc
        return c.obs.copy(), rew, term, trunc, infos
