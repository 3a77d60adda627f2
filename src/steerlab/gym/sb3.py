r"""Stable-Baselines3's ``VecEnv`` on the native vector environment (optional: ``steerlab[learn]``).

:class:`SB3VecEnv` (made by :func:`make_sb3_vec_env`) gives SB3's algorithms (PPO, A2C, SAC, ...)
N ships stepped in one compiled call (:class:`~steerlab.gym.vector_env.SteeringVectorEnv`),
through public API only: the native env in its same-step autoreset mode
(``autoreset_mode="SameStep"``: an ended ship is reset within the step, with
:meth:`~steerlab.gym.vector_env.SteeringVectorEnv.reset_lanes`) and SB3's conventions on top:
``dones = terminated | truncated``, ``infos[i]["terminal_observation"]`` (the last observation
of the ended episode) and ``infos[i]["TimeLimit.truncated"]`` (truncated, not terminated: SB3
bootstraps the value there), rewards float32 as SB3's ``DummyVecEnv`` returns them.

Seeds: ``venv.seed(s)`` (SB3's) keys ship i with ``s + i`` at the next ``reset()``, as
``DummyVecEnv`` seeds its i-th env; so ship i's episodes equal those of a single
:class:`~steerlab.gym.env.SteeringEnv` after ``reset(seed=s + i)`` then ``reset()`` at each end,
bit for bit (``tests/test_gym_sb3.py``).

Threads: the native env's (one unless ``threads=`` asks, :mod:`steerlab.gym.vector_env`). Set
torch to one thread too (``torch.set_num_threads(1)``): on two cores torch's own pool made a
policy step 70x slower (87 ms against 1.25 ms, issue 34).
"""

from __future__ import annotations

from typing import Any, Optional, Sequence

import numpy as np

try:
    from stable_baselines3.common.vec_env.base_vec_env import VecEnv
except ImportError as err:                       # pragma: no cover - the message is the point
    raise ImportError("steerlab.gym.sb3 needs stable-baselines3: pip install 'steerlab[learn]'") from err

from steerlab.gym import IDS
from steerlab.gym.vector_env import SteeringVectorEnv


class SB3VecEnv(VecEnv):
    """SB3 ``VecEnv`` of ``num_envs`` ships of ``task`` (keywords: those of
    :class:`~steerlab.gym.episodes.Episodes`, e.g. ``observation="normalised"``,
    ``reward="autopilot"``, ``episode_s``; and ``threads``)."""

    def __init__(self, num_envs: int, task: str = "course_keeping", **kw: Any) -> None:
        self.venv = SteeringVectorEnv(num_envs, task=task, autoreset_mode="SameStep", **kw)
        self.render_mode = None
        super().__init__(num_envs, self.venv.single_observation_space, self.venv.single_action_space)
        self._actions: Optional[np.ndarray] = None

    # ------------------------------------------------------------------ stepping
    def reset(self) -> np.ndarray:
        obs, infos = self.venv.reset_lanes(np.arange(self.num_envs), list(self._seeds))
        self.reset_infos = infos
        self._reset_seeds()
        self._reset_options()
        return obs

    def step_async(self, actions: np.ndarray) -> None:
        self._actions = np.asarray(actions)

    def step_wait(self):
        if self._actions is None:
            raise RuntimeError("step_wait() without step_async()")
        obs, rew, term, trunc, info = self.venv.step(self._actions.reshape(self.num_envs, 1))
        self._actions = None
        dones = term | trunc
        infos: list[dict[str, Any]] = [{} for _ in range(self.num_envs)]
        if "_reason" in info:
            for i in np.flatnonzero(info["_reason"]).tolist():
                infos[i]["reason"] = "diverged"
        if dones.any():
            final = info["final_obs"]
            for i in np.flatnonzero(dones).tolist():
                infos[i]["terminal_observation"] = final[i]
                infos[i]["TimeLimit.truncated"] = bool(trunc[i] and not term[i])
        return obs, rew.astype(np.float32), dones, infos

    def close(self) -> None:
        self.venv.close()

    # ------------------------------------------------------------------ SB3's plumbing
    def _indices(self, indices) -> list[int]:
        if indices is None:
            return list(range(self.num_envs))
        if isinstance(indices, int):
            return [indices]
        return list(indices)

    def get_attr(self, attr_name: str, indices=None) -> list[Any]:
        if attr_name == "render_mode":
            return [None for _ in self._indices(indices)]
        value = getattr(self.venv, attr_name)
        return [value for _ in self._indices(indices)]

    def set_attr(self, attr_name: str, value: Any, indices=None) -> None:
        raise AttributeError(f"the ships of a native vector env share their settings; cannot set {attr_name!r}")

    def env_method(self, method_name: str, *method_args, indices=None, **method_kwargs) -> list[Any]:
        raise AttributeError(f"the ships of a native vector env have no methods of their own ({method_name!r})")

    def env_is_wrapped(self, wrapper_class, indices=None) -> list[bool]:
        return [False for _ in self._indices(indices)]

    def get_images(self) -> Sequence[Optional[np.ndarray]]:
        return [None for _ in range(self.num_envs)]


def make_sb3_vec_env(env: str = "steerlab/CourseKeeping-v0", num_envs: int = 8, **kw: Any) -> SB3VecEnv:
    """An :class:`SB3VecEnv` of ``num_envs`` ships; ``env`` a registered id
    (``steerlab/CourseKeeping-v0``, ...) or a task name (``course_keeping``, ...)."""
    from steerlab.errors import InputError

    task = IDS.get(env, env)
    if task not in IDS.values():
        raise InputError("env", f"must be one of {sorted(IDS)} (or their tasks), got {env!r}")
    return SB3VecEnv(num_envs, task=task, **kw)


__all__ = ["SB3VecEnv", "make_sb3_vec_env"]
