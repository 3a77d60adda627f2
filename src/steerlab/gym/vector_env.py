r"""The native vector environment: N ships stepped in one compiled call.

``gymnasium.make_vec("steerlab/CourseKeeping-v0", num_envs=N, vectorization_mode="vector_entry_point")``
gives a :class:`SteeringVectorEnv`: spaces, reward and episodes as the single
:class:`~steerlab.gym.env.SteeringEnv` (observations (N, 3), actions (N, 1)), all N ships
advanced by the batch engine's vectorised groups of ``LANES`` ships in one compiled call
(``step`` of :func:`steerlab.gym.plant_batch.env_kernels`: actions checked, autoresets, plants,
guidance, observations and rewards; the single environment steps its ship with the scalar
kernel, with the same numbers); from 512 ships on (:data:`~steerlab.gym.episodes.THREADS_FROM`)
the call is split into ranges of whole groups spread over ``numba.get_num_threads()``
threads by numba's ``prange`` (on TBB, or a layer the user chose: :mod:`steerlab.jit.threading_layer`),
after every action has been checked (same numbers whatever the split). ``reset(seed=s)`` seeds ship i with ``s + i`` (as gymnasium's
``SyncVectorEnv``; or ``seed=[s0, s1, ...]``, one per ship), so ship i's episodes equal a
single environment's after ``reset(seed=s + i)``. Autoreset: gymnasium's ``NEXT_STEP`` mode
(the step after an episode ends resets that ship to its next episode and ignores its action;
reward 0). An action outside [-1, 1] (or NaN) raises :class:`~steerlab.errors.InputError`
before anything moves; a diverged ship ends its episode (``terminated``,
``infos["reason"] == "diverged"``, zeros observed).
"""

from __future__ import annotations

from typing import Any, Optional, Sequence, Union

import gymnasium as gym
import numpy as np
from numpy.typing import ArrayLike
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from steerlab.errors import InputError
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
        self._autoreset = np.zeros(self.num_envs, dtype=np.bool_)   # ended at the last step: reset at the next
        self._term = np.zeros(self.num_envs, dtype=np.bool_)
        self._trunc = np.zeros(self.num_envs, dtype=np.bool_)
        self._reset_done = False

    def reset(self, *, seed: Union[int, Sequence[Optional[int]], None] = None,
              options: Optional[dict[str, Any]] = None) -> tuple[np.ndarray, dict[str, Any]]:
        n = self.num_envs
        seeds: Optional[list[Optional[int]]]
        if seed is None:
            seeds = None
        elif isinstance(seed, (int, np.integer)) and not isinstance(seed, (bool, np.bool_)):
            seeds = [int(seed) + i for i in range(n)]
        else:
            try:
                seeds = list(seed)  # type: ignore[arg-type]   # a bad value: refused just below
            except TypeError:
                seeds = None
            if seeds is None or len(seeds) != n:
                raise InputError("seed", f"must be None, an int or a sequence of {n} ints (one per ship), "
                                         f"got {seed!r}")
        self.core.reset_lanes(np.arange(n), seeds)
        self._autoreset[:] = False
        self._reset_done = True
        return self.core.obs.copy(), {}

    def step(self, actions: ArrayLike
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        c = self.core
        if not self._reset_done:
            raise RuntimeError("call reset() before step()")
        c.step_autoreset(actions, self._autoreset, self._term, self._trunc)
        infos: dict[str, Any] = {}
        if self._term.any():
            infos["reason"] = np.where(self._term, "diverged", "")
            infos["_reason"] = self._term.copy()
        return c.obs.copy(), c.rew.copy(), self._term.copy(), self._trunc.copy(), infos
