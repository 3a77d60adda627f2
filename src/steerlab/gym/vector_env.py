r"""The native vector environment: N ships stepped in one compiled call.

``gymnasium.make_vec("steerlab/CourseKeeping-v0", num_envs=N, vectorization_mode="vector_entry_point")``
gives a :class:`SteeringVectorEnv`: spaces, reward and episodes as the single
:class:`~steerlab.gym.env.SteeringEnv` (observations (N, 3), actions (N, 1)), all N ships
advanced by the batch engine's vectorised groups of ``LANES`` ships in one compiled call
(``step`` of :func:`steerlab.gym.plant_batch.env_kernels`: actions checked, autoresets, plants,
guidance, observations and rewards; the single environment steps its ship with the scalar
kernel, with the same numbers); asked for threads (``threads=k``, or ``None``: numba's
count), from 512 ships on (:data:`~steerlab.gym.episodes.THREADS_FROM`) the call is split into
ranges of whole groups spread over them by numba's ``prange`` (on TBB, or a layer the user
chose: :mod:`steerlab.jit.threading_layer`), after every action has been checked (same numbers
whatever the split). ``reset(seed=s)`` seeds ship i with ``s + i`` (as gymnasium's
``SyncVectorEnv``; or ``seed=[s0, s1, ...]``, one per ship), so ship i's episodes equal a
single environment's after ``reset(seed=s + i)``. Autoreset: gymnasium's ``NEXT_STEP`` mode
(the step after an episode ends resets that ship to its next episode and ignores its action;
reward 0), or ``autoreset_mode="SameStep"`` (the step that ends an episode resets that ship
at once and returns its new first observation; the last one in ``infos["final_obs"]``), which
:mod:`steerlab.gym.sb3` builds SB3's ``VecEnv`` on. :meth:`SteeringVectorEnv.reset_lanes` resets
chosen ships now. Threads: one unless asked (``threads=1``, the default; ``threads=None``
spreads a step of ``THREADS_FROM`` ships or more over numba's threads, ``threads=k`` over
k): an automatic switch to two threads ran at 0.65x one thread's speed with the cores busy
(issue 34), so the env never switches by itself. An action outside [-1, 1] (or NaN) raises :class:`~steerlab.errors.InputError`
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
                 autoreset_mode: Union[str, AutoresetMode] = AutoresetMode.NEXT_STEP, threads: Optional[int] = 1,
                 **kw: Any) -> None:
        Episodes.check_keywords(kw, own=("num_envs", "render_mode", "autoreset_mode"))
        self.num_envs = int(num_envs)
        try:
            mode = AutoresetMode(autoreset_mode)
        except ValueError:
            mode = None
        if mode not in (AutoresetMode.NEXT_STEP, AutoresetMode.SAME_STEP):
            raise InputError("autoreset_mode", f"must be 'NextStep' or 'SameStep', got {autoreset_mode!r}")
        self.autoreset_mode = mode
        self.metadata = {**self.metadata, "autoreset_mode": mode}
        self.core = Episodes(self.num_envs, task=task, vectorised=True, threads=threads, **kw)
        self.single_observation_space, self.single_action_space = spaces(self.core.observation, self.core.delta_max)
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
        return self.core.observed.copy(), {}

    def reset_lanes(self, lanes: Union[Sequence[int], np.ndarray], seeds: Optional[Sequence[Optional[int]]] = None
                    ) -> tuple[np.ndarray, list[dict[str, Any]]]:
        """Reset the ships ``lanes`` (indices) now, each to its next episode (``seeds[q]``, an int,
        first keys ship ``lanes[q]`` with it: episode 0; None keeps its key), as a single
        environment's ``reset()`` (``reset(seed=...)``) does; the other ships are untouched and
        a pending autoreset of these ships is cancelled. Returns their observations
        ``(len(lanes), n_obs)`` and one info dict per ship (``episode``, ``initial_heading`` [rad]).
        The public per-ship reset a same-step autoreset (SB3's ``VecEnv``) is built on."""
        idx = np.ascontiguousarray(lanes, dtype=np.int64).reshape(-1)
        if idx.size and (idx.min() < 0 or idx.max() >= self.num_envs):
            raise InputError("lanes", f"must be ship indices in [0, {self.num_envs}), got {idx.tolist()!r}")
        if seeds is not None and len(seeds) != idx.size:
            raise InputError("seeds", f"must be one per lane ({idx.size}), got {len(seeds)}")
        infos = self.core.reset_lanes(idx, seeds)
        self._autoreset[idx] = False
        self._reset_done = self._reset_done or idx.size == self.num_envs
        return self.core.observed[idx].copy(), infos

    def step(self, actions: ArrayLike
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        c = self.core
        if not self._reset_done:
            raise RuntimeError("call reset() before step()")
        c.step_autoreset(actions, self._autoreset, self._term, self._trunc)
        rew = c.rew.copy()                                      # before a same-step reset zeroes it
        infos: dict[str, Any] = {}
        if self._term.any():
            infos["reason"] = np.where(self._term, "diverged", "")
            infos["_reason"] = self._term.copy()
        if self.autoreset_mode == AutoresetMode.SAME_STEP and self._autoreset.any():
            done = self._autoreset.copy()                       # ended now: reset now (gymnasium's SAME_STEP)
            final = np.empty(self.num_envs, dtype=object)
            rows = c.observed[done].copy()
            for q, i in enumerate(np.flatnonzero(done).tolist()):
                final[i] = rows[q]
            final_info = {k: v for k, v in infos.items()}
            self.reset_lanes(np.flatnonzero(done))
            infos["final_obs"], infos["_final_obs"] = final, done
            infos["final_info"], infos["_final_info"] = final_info, done
        return c.observed.copy(), rew, self._term.copy(), self._trunc.copy(), infos
