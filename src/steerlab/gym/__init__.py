r"""Gymnasium environments on steerlab ships (optional extra ``steerlab[rl]``,
``pip install 'steerlab[rl]'``; ``steerlab[gym]`` is the same).

``import steerlab.gym`` registers (all keyword arguments of
:class:`steerlab.gym.episodes.Episodes` pass through ``gymnasium.make``)::

    steerlab/CourseKeeping-v0   hold 0 deg from a seeded initial offset, in waves
    steerlab/CourseChange-v0    a 20 deg step of the reference at 10 s, in waves
    steerlab/TrackFollowing-v0  LOS route following from 200 m off a straight route, in waves

each with a single environment (:class:`~steerlab.gym.env.SteeringEnv`) and a native vector
one (:class:`~steerlab.gym.vector_env.SteeringVectorEnv`,
``gymnasium.make_vec(id, num_envs=N, vectorization_mode="vector_entry_point")``).
"""

from __future__ import annotations

IDS = {"steerlab/CourseKeeping-v0": "course_keeping", "steerlab/CourseChange-v0": "course_change",
       "steerlab/TrackFollowing-v0": "track_following"}


def register_envs() -> None:
    """Register the ids with gymnasium (idempotent)."""
    try:
        import gymnasium
    except ImportError as err:
        raise ImportError("steerlab.gym needs gymnasium: pip install 'steerlab[rl]'") from err

    for env_id, task in IDS.items():
        if env_id in gymnasium.registry:
            continue
        gymnasium.register(id=env_id, entry_point="steerlab.gym.env:SteeringEnv",
                           vector_entry_point="steerlab.gym.vector_env:SteeringVectorEnv",
                           kwargs={"task": task}, max_episode_steps=None)


register_envs()
