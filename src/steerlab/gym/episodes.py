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
"""

from __future__ import annotations

import math

import numpy as np

from steerlab.errors import InputError, require_finite_range
from steerlab.units import rad

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

    def __init__(self, n, task="course_keeping", ship="esso", speed_kn=16.0, gear=None, environment=None,
                 ship_options=None, dt=0.1, control_dt=1.0, episode_s=300.0, lam=0.1,
                 initial_offset_deg=10.0, change_deg=20.0, change_t=10.0, guidance=None, reward="speed_loss"):
        from steerlab.gym.plant_batch import REWARDS, lane_stepper
        from steerlab.guidance.reference_models import course_guide
        from steerlab.guidance.reference_vector import initial_reference
        from steerlab.sim.setup import build_seeds

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
        self._build_seeds = build_seeds
        s0 = build_seeds(self.scenario, [0])[0]
        self.task, self.n, self.dt, self.nc, self.lam = task, int(n), float(dt), nc, float(lam)
        self.control_dt = nc * self.dt
        self.offset_max = rad(initial_offset_deg) if task == "course_keeping" else 0.0
        self.delta_max = float(s0.pg[0])
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
        self._work = np.empty((5, nx))
        self._step = lane_stepper(s0.ship.rhs, self.guide)
        self.rngs = [None] * n

    # ----------------------------------------------------------------- reset
    def reset_lanes(self, lanes, seeds=None):
        """Reset ``lanes`` (indices); ``seeds[i]`` (int or None) reseeds lane's generator first."""
        from gymnasium.utils import seeding

        from steerlab.guidance.reference_vector import REF_RPM, initial_reference
        from steerlab.gym.plant_batch import observe

        lanes = list(lanes)
        sea_seeds, offsets = [], []
        for q, i in enumerate(lanes):
            s = None if seeds is None else seeds[q]
            if s is not None or self.rngs[i] is None:
                self.rngs[i], _ = seeding.np_random(s)
            rng = self.rngs[i]
            sea_seeds.append(int(rng.integers(0, 2**31 - 1)))
            offsets.append(float(rng.uniform(-self.offset_max, self.offset_max)) if self.offset_max > 0 else 0.0)
        setups = self._build_seeds(self.scenario, sea_seeds)
        for q, i in enumerate(lanes):
            su = setups[q]
            self.X[i] = su.x0
            self.X[i, 2] += offsets[q]
            self.W[i] = su.w
            self.PS[i] = su.ps
            self.K[i] = 0
            self.J[i] = 0
            self.cmd[i] = 0.0
            self.bad[i] = False
            self.GZ[i] = su.gz0
            self.REF[i] = initial_reference()
            self.guide(0.0, self.X[i], self.gd, self.GZ[i], self.REF[i], self.control_dt)
            if self.rpm_slot >= 0 and self.REF[i, REF_RPM] >= 0.0:
                self.PS[i, self.rpm_slot] = self.REF[i, REF_RPM]
            observe(self.X[i], self.REF[i, 0], self.obs[i])
            self.rew[i] = 0.0
        return [{"sea_seed": sea_seeds[q], "initial_heading": float(self.X[i, 2])} for q, i in enumerate(lanes)]

    # ----------------------------------------------------------------- step
    def orders(self, actions) -> np.ndarray:
        """Rudder orders [rad] from actions in [-1, 1] (fraction of the gear limit); refuses others."""
        a = np.asarray(actions, dtype=np.float64).reshape(self.n)
        if not np.all(np.isfinite(a)) or np.any(np.abs(a) > 1.0):
            i = int(np.argmax(~np.isfinite(a) | (np.abs(a) > 1.0)))
            raise InputError("action", f"must be finite and in [-1, 1] (rudder order / gear limit "
                                       f"{math.degrees(self.delta_max):g} deg), got {a[i]!r}")
        return a * self.delta_max

    def step(self, actions, active=None):
        """Advance the ``active`` lanes (default all) by one env step; fills ``obs``, ``rew``, ``bad``."""
        self.cmd[:] = self.orders(actions)
        act = self.active if active is None else active
        self._step(self.X, self.K, self.J, self.cmd, self.W, self.PS, self.PG, self.dt, self.nc, self.gd, self.GZ,
                   self.REF, self.rpm_slot, self.lam, self.reward, act, self.obs, self.rew, self.bad, self._work)
        truncated = self.J >= self.n_env_steps
        return self.obs, self.rew, self.bad.copy(), truncated & ~self.bad
