r"""N course-keeping / course-change episodes on one ship: the core of the Gymnasium environments.

A lane is one episode: a ship (``steerlab ships``) with a steering gear in a sea built by the
scenario machinery (``[environment]`` keys; :func:`steerlab.sim.setup.build_seeds`, so the
seas are exactly those of ``steerlab run``), a reference heading from the scenario's guidance
kernel (the time-only course schedule, or ``guidance=`` any ``[guidance]`` table, e.g. LOS
route following for ``track_following``: :data:`TRACK_GUIDANCE` by default),
and an agent that orders the rudder every ``control_dt`` seconds (``nc = control_dt / dt``
plant steps, order held). Each lane owns a random generator (gymnasium's
``seeding.np_random``); at reset it draws the sea's seed and, for course keeping, the initial
heading offset. Lanes are independent: lane i of N behaves as a single environment seeded
alike.

``vectorised=True`` (the native vector environment) advances the ships with the batch
engine's vectorised groups (:func:`steerlab.gym.plant_batch.vector_stepper`) instead of one
after the other; the numbers are the same. Resets of many lanes draw their seas in one call
(:func:`steerlab.environment.disturbance.build_disturbances`, the seas
:func:`~steerlab.sim.setup.realise` gives, without re-designing anything per reset); a sea
with optional blocks (``uses_sea``: spectra, gusts, current variation, wind rudder) is
realised lane by lane.
"""

from __future__ import annotations

import math
from typing import Any, Iterable, Mapping, Optional, Sequence, Union

import numpy as np
from numpy.typing import ArrayLike

from steerlab.errors import InputError, require_finite_range
from steerlab.units import rad
from steerlab.ships.state import IPSI
from steerlab.steering_gear import G_DMAX

TASKS = ("course_keeping", "course_change", "track_following")

#: the track-following task's default route: a straight line north, the ship starting 200 m to starboard
TRACK_GUIDANCE = {"type": "los", "start": [0.0, 200.0], "route": [[0.0, 0.0], [100000.0, 0.0]],
                  "lookahead_L": 5.0}
N_OBS = 3
OBS_NAMES = ("heading_error", "yaw_rate", "rudder")
OBS_UNITS = ("rad", "rad/s", "rad")


def _scenario(task, ship, speed_kn, gear, environment, ship_options, dt, episode_s, change_deg, change_t,
              guidance):
    from steerlab.sim.scenario import scenario_from_dict

    if guidance is not None:
        g = dict(guidance)
    elif task == "track_following":
        g = dict(TRACK_GUIDANCE)
    else:
        g = {"psi0_deg": 0.0, "changes": [] if task == "course_keeping" else [{"t": change_t, "psi_deg": change_deg}]}
    ship_d = {"model": ship, "speed_kn": speed_kn}
    if ship_options:
        ship_d["options"] = dict(ship_options)
    d = {"name": f"gym-{task}", "seed": 0, "dt": dt, "duration": episode_s, "ship": ship_d,
         "gear": dict(gear or {}), "controller": {"type": "pid"}, "guidance": g,
         "environment": {"waves": True} if environment is None else dict(environment)}
    return scenario_from_dict(d)


class Episodes:
    """N lanes (see the module docstring); all arrays SI."""

    def __init__(self, n: int, task: str = "course_keeping", ship: str = "esso", speed_kn: float = 16.0,
                 gear: Optional[Mapping[str, float]] = None, environment: Optional[Mapping[str, Any]] = None,
                 ship_options: Optional[Mapping[str, Any]] = None, dt: float = 0.1, control_dt: float = 1.0,
                 episode_s: float = 300.0, lam: float = 0.1, initial_offset_deg: float = 10.0,
                 change_deg: float = 20.0, change_t: float = 10.0, guidance: Optional[Mapping[str, Any]] = None,
                 reward: str = "speed_loss", vectorised: bool = False) -> None:
        from steerlab.environment.sea import uses_sea
        from steerlab.gym.plant_batch import REWARDS, lane_stepper, resetter, vector_stepper
        from steerlab.guidance.reference_models import course_guide
        from steerlab.guidance.reference_vector import initial_reference
        from steerlab.sim.setup import design, realise

        if task not in TASKS:
            raise InputError("task", f"must be one of {TASKS}, got {task!r}")
        if reward not in REWARDS:
            raise InputError("reward", f"must be one of {REWARDS}, got {reward!r}")
        self.reward = REWARDS.index(reward)
        require_finite_range("dt", dt, 0.0, 10.0, lo_open=True)
        require_finite_range("control_dt", control_dt, 0.0, 60.0, lo_open=True)
        require_finite_range("episode_s", episode_s, 0.0, 1e5, lo_open=True)
        require_finite_range("lam", lam, 0.0, 1e6)
        require_finite_range("initial_offset_deg", initial_offset_deg, 0.0, 180.0)
        if int(n) < 1:
            raise InputError("num_envs", f"must be >= 1, got {n}")
        nc = int(round(control_dt / dt))
        if nc < 1 or abs(nc * dt - control_dt) > 1e-9 * max(control_dt, 1.0):
            raise InputError("control_dt", f"must be a positive multiple of dt={dt} s, got {control_dt} s")
        self.n_env_steps = int(math.ceil(episode_s / control_dt - 1e-9))
        self.scenario = _scenario(task, ship, speed_kn, gear, environment, ship_options, dt,
                                  self.n_env_steps * nc * dt, change_deg, change_t, guidance)
        self.design = design(self.scenario)
        self._realise = realise
        s0 = realise(self.design, 0)
        # the seed changes only the sea (no sensors here): draw many lanes' seas at once unless
        # an optional sea block needs the per-seed machinery
        self._fast_seas = not uses_sea(self.scenario.environment) and self.scenario.sensors is None
        self.task, self.n, self.dt, self.nc, self.lam = task, int(n), float(dt), nc, float(lam)
        self.control_dt = nc * self.dt
        self.offset_max = rad(initial_offset_deg) if task == "course_keeping" else 0.0
        self.delta_max = float(s0.pg[G_DMAX])
        self.state_names = s0.state_names
        self.ship_spec = s0.ship
        self.guide = course_guide if s0.guide is None else s0.guide
        self.gd, self.gz0, self.rpm_slot = s0.gd, s0.gz0, s0.rpm_slot
        n, nx = self.n, s0.x0.shape[0]
        self.X = np.zeros((n, nx))
        self.K = np.zeros(n, dtype=np.int64)
        self.J = np.zeros(n, dtype=np.int64)
        self.W = np.zeros((n,) + s0.w.shape)
        self.PS = np.tile(s0.ps, (n, 1))
        self.PG = np.tile(s0.pg, (n, 1))
        self.GZ = np.tile(s0.gz0, (n, 1))
        self.REF = np.tile(initial_reference(), (n, 1))
        self.cmd = np.zeros(n)
        self.obs = np.zeros((n, N_OBS))
        self.rew = np.zeros(n)
        self.bad = np.zeros(n, dtype=np.bool_)
        self.active = np.ones(n, dtype=np.bool_)
        self.W[:] = s0.w
        self.w_index = np.arange(n, dtype=np.int64)
        self._work = np.empty((5, nx))
        self.vectorised = bool(vectorised)
        if self.vectorised:
            self._vstep = vector_stepper(s0.ship.rhs, self.guide, nx)
        else:
            self._step = lane_stepper(s0.ship.rhs, self.guide)
        self._reset = resetter(self.guide)
        self._x0, self._ps0, self._ref0 = s0.x0, s0.ps, initial_reference()
        self.rngs: list[np.random.Generator | None] = [None] * n

    # ----------------------------------------------------------------- reset
    def reset_lanes(self, lanes: Union[Iterable[int], np.ndarray],
                    seeds: Optional[Sequence[Optional[int]]] = None) -> list[dict[str, Any]]:
        """Reset ``lanes`` (indices); ``seeds[i]`` (int or None) reseeds lane's generator first."""
        from gymnasium.utils import seeding

        from steerlab.environment.disturbance import build_disturbances

        lanes = np.asarray(list(lanes), dtype=np.int64)
        m = lanes.shape[0]
        sea_seeds, offsets = [], np.zeros(m)
        for q, i in enumerate(lanes.tolist()):
            s = None if seeds is None else seeds[q]
            if s is not None or self.rngs[i] is None:
                self.rngs[i], _ = seeding.np_random(s)
            rng = self.rngs[i]
            sea_seeds.append(int(rng.integers(0, 2**31 - 1)))
            if self.offset_max > 0:
                offsets[q] = float(rng.uniform(-self.offset_max, self.offset_max))
        if self._fast_seas:
            sc = self.scenario
            build_disturbances(self.design.dist, sc.n_steps, sc.dt, sea_seeds, out=self.W, rows=lanes)
        else:
            for q, i in enumerate(lanes.tolist()):
                self.W[i] = self._realise(self.design, sea_seeds[q]).w
        self.K[lanes] = 0
        self.J[lanes] = 0
        self.cmd[lanes] = 0.0
        self.bad[lanes] = False
        self.rew[lanes] = 0.0
        self._reset(lanes, self.X, self.PS, self.GZ, self.REF, self._x0, self._ps0, self.gz0, self._ref0, offsets,
                    self.gd, self.control_dt, self.rpm_slot, self.obs)
        return [{"sea_seed": sea_seeds[q], "initial_heading": float(self.X[i, IPSI])}
                for q, i in enumerate(lanes.tolist())]

    # ----------------------------------------------------------------- step
    def orders(self, actions: ArrayLike) -> np.ndarray:
        """Rudder orders [rad] from actions in [-1, 1] (fraction of the gear limit); refuses others."""
        a = np.asarray(actions, dtype=np.float64).reshape(self.n)
        if not (np.abs(a) <= 1.0).all():                 # NaN fails the comparison too
            i = int(np.argmax(~(np.abs(a) <= 1.0)))
            raise InputError("action", f"must be finite and in [-1, 1] (rudder order / gear limit "
                                       f"{math.degrees(self.delta_max):g} deg), got {a[i]!r}")
        return a * self.delta_max

    def step(self, actions: ArrayLike, active: Optional[np.ndarray] = None
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Advance the ``active`` lanes (default all) by one env step; fills ``obs``, ``rew``, ``bad``."""
        self.cmd[:] = self.orders(actions)
        act = self.active if active is None else active
        if self.vectorised:
            self._vstep(self.X, self.K, self.J, self.cmd, self.W, self.w_index, self.PS, self.PG, self.dt, self.nc,
                        self.gd, self.GZ, self.REF, self.rpm_slot, self.lam, self.reward, act, self.obs, self.rew,
                        self.bad)
        else:
            self._step(self.X, self.K, self.J, self.cmd, self.W, self.PS, self.PG, self.dt, self.nc, self.gd,
                       self.GZ, self.REF, self.rpm_slot, self.lam, self.reward, act, self.obs, self.rew, self.bad,
                       self._work)
        truncated = self.J >= self.n_env_steps
        return self.obs, self.rew, self.bad.copy(), truncated & ~self.bad
