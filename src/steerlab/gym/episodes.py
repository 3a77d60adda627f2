r"""N course-keeping / course-change episodes on one ship: the core of the Gymnasium environments.

A lane is one episode: a ship (``steerlab ships``) with a steering gear in a sea built by the
scenario machinery (``[environment]`` keys, :func:`steerlab.sim.setup.design`), a reference
heading from the scenario's guidance kernel (the time-only course schedule, or ``guidance=``
any ``[guidance]`` table, e.g. LOS route following for ``track_following``:
:data:`TRACK_GUIDANCE` by default), and an agent that orders the rudder every ``control_dt``
seconds (``nc = control_dt / dt`` plant steps, order held).

Randomness (:mod:`steerlab.gym.lane_seas`): a reset with a seed keys the lane with it; each
episode of the lane (0 after the seeded reset, then 1, 2, ... at the resets without a seed)
draws its initial heading offset (course keeping) and its sea's white noise from
Philox4x64-10 blocks of (key, episode) in compiled code - no generator object per lane or per
reset. Lanes are independent: lane i of N behaves as a single environment seeded alike, and
the same seed gives the same episodes. A plain sea (waves, constant wind, current, rudder
offset: the default) is the scenario's eq-39 wave disturbance driven by those normals, its
rows filtered env step by env step just before the plants read them; a sea with optional
blocks (``uses_sea``: spectra, gusts, current variation, wind rudder) is realised lane by lane
by :func:`~steerlab.sim.setup.realise` with a sea seed drawn from the episode's header, so it
is the sea ``steerlab run`` gives that seed.

``vectorised=True`` (the native vector environment) advances the ships with the batch
engine's vectorised groups and does the whole step - actions checked, autoresets, plants,
guidance, observations, rewards - in one compiled call
(``step`` of :func:`steerlab.gym.plant_batch.env_kernels`, :meth:`Episodes.step_autoreset`), spread
over ``threads`` threads from :data:`THREADS_FROM` ships on (default one thread: the env
never switches to threads by itself); the single environment steps its ship
with the scalar kernel; the numbers are the same.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any, Iterable, Mapping, Optional, Sequence, Union

import numpy as np
from numpy.typing import ArrayLike

from steerlab.environment.disturbance import N_CHANNELS, W_RUDDER, build_disturbance
from steerlab.environment.iir_filter import _padded
from steerlab.environment.waves import _hold, band_pass_eq39

from steerlab.errors import InputError, require_finite_range
from steerlab.sim.lanes import LANES, range_cuts
from steerlab.jit.numba_gate import internals_allowed
from steerlab.jit.threading_layer import launch, num_threads, threads_pay
from steerlab.units import rad
from steerlab.ships.state import IPSI
from steerlab.steering_gear import G_DMAX

TASKS = ("course_keeping", "course_change", "track_following")

#: the track-following task's default route: a straight line north, the ship starting 200 m to starboard
TRACK_GUIDANCE = {"type": "los", "start": [0.0, 200.0], "route": [[0.0, 0.0], [100000.0, 0.0]],
                  "lookahead_L": 5.0}
THREADS_FROM = 512
"""Least number of lanes whose vectorised step (or reset) is spread over the threads (numba's
``prange``, ``step_parallel`` / ``reset_parallel`` of :mod:`steerlab.jit.env_template`); below
it, one call in the calling thread. A step of 1024 ships at the default ``control_dt`` takes
some 165-175 us on one core of the 2-core development VM (0.17 us per ship; 260-285 us before
the step was made cheaper, 2026-11-26), about 100 us on two TBB threads with a core free; see
``benchmarks/README.md`` for what the threads give there. Used only when threads are asked
(``threads=k`` or ``None``: numba's count); the default ``threads=1`` keeps the env on one
thread at every N (issue 34: the automatic switch ran at 0.65x one thread under load)."""
from steerlab.gym.plant_batch import N_OBS, OBS_DELTA, OBS_E, OBS_NAMES, OBS_UNITS  # noqa: E402,F401  (the layout, declared there)
from steerlab.guidance.reference_vector import REF_XTE  # noqa: E402


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
         "gear": dict(gear or {}), "controller": {"type": "pid", "gains": "paper"}, "guidance": g,
         "environment": {"waves": True} if environment is None else dict(environment)}
    return scenario_from_dict(d)


class Episodes:
    """N lanes (see the module docstring); all arrays SI."""

    @classmethod
    def _check_inert(cls, task: str, guidance, episode_s: float, **given: float) -> None:
        """Settings the task does not read, given other than their defaults: an
        :class:`~steerlab.errors.InertSettingWarning` each (the course change's ``change_deg``
        and ``change_t`` outside the course-change task or with a ``guidance`` of its own, the
        start offset outside course keeping, a ``change_t`` at or after the episode's end)."""
        import inspect
        import warnings

        from steerlab.errors import InertSettingWarning

        defaults = {k: v.default for k, v in inspect.signature(cls.__init__).parameters.items()}
        inert = [] if task == "course_change" and guidance is None else ["change_deg", "change_t"]
        inert += [] if task == "course_keeping" else ["initial_offset_deg"]
        for name in inert:
            if given[name] != defaults[name]:
                why = "a guidance of its own is given" if guidance is not None and name.startswith("change") \
                    else f"task {task!r} does not read it"
                warnings.warn(f"{name}: has no effect here ({why})", InertSettingWarning, stacklevel=4)
        if task == "course_change" and guidance is None:
            t = require_finite_range("change_t", given["change_t"], 0.0)
            if t >= episode_s and t != defaults["change_t"]:     # (a short test episode with the default: quiet)
                warnings.warn(f"change_t: the course change at {t:g} s comes after the episode's end "
                              f"({episode_s:g} s): it never happens", InertSettingWarning, stacklevel=4)

    @classmethod
    def check_keywords(cls, kw: Mapping[str, Any], own: tuple[str, ...] = ()) -> None:
        """:class:`InputError` naming the first keyword of ``kw`` that neither :meth:`__init__`
        nor the environment itself (``own``) takes, with the allowed ones (a misspelt keyword
        to ``gym.make`` was Python's ``TypeError``)."""
        import inspect

        params = inspect.signature(cls.__init__).parameters
        allowed = sorted({*params, *own} - {"self", "n", "vectorised"})
        bad = sorted(k for k in kw if k not in allowed)
        if bad:
            from steerlab.messages import did_you_mean

            hint = did_you_mean(bad[0], allowed, 1)
            raise InputError(bad[0], f"unknown keyword of the steerlab environments{hint}; allowed: "
                                     f"{', '.join(allowed)}")

    def __init__(self, n: int, task: str = "course_keeping", ship: str = "esso", speed_kn: float = 16.0,
                 gear: Optional[Mapping[str, float]] = None, environment: Optional[Mapping[str, Any]] = None,
                 ship_options: Optional[Mapping[str, Any]] = None, dt: float = 0.1, control_dt: float = 1.0,
                 episode_s: float = 300.0, lam: float = 0.1, initial_offset_deg: float = 10.0,
                 change_deg: float = 20.0, change_t: float = 10.0, guidance: Optional[Mapping[str, Any]] = None,
                 reward: Union[str, Mapping[str, float]] = "speed_loss", observation: str = "raw",
                 threads: Optional[int] = 1, vectorised: bool = False) -> None:
        from steerlab.environment.sea import uses_sea
        from steerlab.gym.plant_batch import REWARDS, env_kernels
        from steerlab.guidance.reference_models import course_guide
        from steerlab.guidance.reference_vector import initial_reference
        from steerlab.sim.setup import design, realise

        if task not in TASKS:
            raise InputError("task", f"must be one of {TASKS}, got {task!r}")
        from steerlab.gym.observations import OBSERVATIONS
        from steerlab.gym.rewards import PRESETS, reward_weights

        if isinstance(reward, str) and reward not in REWARDS and reward not in PRESETS:
            raise InputError("reward", f"must be one of {REWARDS + tuple(PRESETS)} or a mapping {{term: weight}}, "
                                       f"got {reward!r}")
        # a compiled reward (the step writes it), or weighted terms (steerlab.gym.rewards) after the step
        self.reward = REWARDS.index(reward) if isinstance(reward, str) and reward in REWARDS else 0
        self.reward_weights = None if isinstance(reward, str) and reward in REWARDS else reward_weights(reward)
        if observation not in OBSERVATIONS:
            raise InputError("observation", f"must be one of {OBSERVATIONS}, got {observation!r}")
        self.observation = observation
        if threads is not None and (isinstance(threads, bool) or not isinstance(threads, (int, np.integer))
                                    or threads < 1):
            raise InputError("threads", f"must be None (numba's threads) or an int >= 1, got {threads!r}")
        require_finite_range("dt", dt, 0.0, 10.0, lo_open=True)
        require_finite_range("control_dt", control_dt, 0.0, 60.0, lo_open=True)
        require_finite_range("episode_s", episode_s, 0.0, 1e5, lo_open=True)
        require_finite_range("lam", lam, 0.0, 1e6)
        require_finite_range("initial_offset_deg", initial_offset_deg, 0.0, 180.0)
        if int(n) < 1:
            raise InputError("num_envs", f"must be >= 1, got {n}")
        self._check_inert(task, guidance, episode_s, change_deg=change_deg, change_t=change_t,
                          initial_offset_deg=initial_offset_deg)
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
        self.PS = np.tile(s0.ps, (n, 1))
        self.PG = np.tile(s0.pg, (n, 1))
        self.GZ = np.tile(s0.gz0, (n, 1))
        self.REF = np.tile(initial_reference(), (n, 1))
        self.cmd = np.zeros(n)
        self.obs = np.zeros((n, N_OBS))
        self.rew = np.zeros(n)
        self.bad = np.zeros(n, dtype=np.bool_)
        self.active = np.ones(n, dtype=np.bool_)
        self.w_index = np.arange(n, dtype=np.int64)
        self._work = np.empty((5, nx))
        self.vectorised = bool(vectorised)
        # the vectorised step of at least threads_from lanes runs on `threads` threads (default 1;
        # None: numba's number, numba.get_num_threads(), read at each step, where threads pay);
        # the numbers do not depend on either
        self.threads_from, self.threads = THREADS_FROM, threads
        from steerlab.jit.drivers import entry

        kernels = env_kernels(s0.ship.rhs, self.guide, nx)      # compiled once ever (disk cache)
        if self.vectorised:
            self._vstep = entry(kernels, "step")
            self._kernels = kernels
            self._par: dict[str, Any] = {}                   # threaded entry points, taken on first use
            self._cuts: dict[int, np.ndarray] = {}           # range bounds per thread count
        else:
            self._step = entry(kernels, "step_serial")
        self._reset = entry(kernels, "reset")
        self._x0, self._ps0, self._ref0 = s0.x0, s0.ps, initial_reference()
        from steerlab.gym.observations import N_NORMALISED
        from steerlab.gym.rewards import RewardTerms

        # weighted reward terms (None: the compiled reward) and the normalised observation (None: raw)
        self.terms = None if self.reward_weights is None else RewardTerms(self.reward_weights, n, lam,
                                                                          self.control_dt)
        self.features = np.zeros((n, N_NORMALISED)) if observation == "normalised" else None
        # per lane: its key (the reset seed), its next episode number (steerlab.gym.lane_seas)
        self.KEY = np.zeros((n, 2), dtype=np.uint64)
        self.EP = np.zeros(n, dtype=np.uint64)
        self.keyed = np.zeros(n, dtype=np.bool_)
        self._sea_seeds = np.zeros(n, dtype=np.int64)
        dist, sc = self.design.dist, self.scenario
        # a plain sea's wave channel is filtered lazily from the lane's draws, added to its
        # seed-free channels (base); W holds every lane's disturbance rows: a lazy sea's lanes
        # only their env step's nc rows (written by the step, lane_seas.fill_rows), the others
        # their whole sequence
        self.lazy = self._fast_seas and bool(dist.waves)
        self.W = np.zeros((n, nc if self.lazy else s0.w.shape[0], s0.w.shape[1]))
        if self._fast_seas:
            self._base = build_disturbance(replace(dist, waves=False), sc.n_steps, sc.dt, 0)
            if not self.lazy:
                self.W[:] = self._base
        else:
            self._base = np.zeros((1, N_CHANNELS))
            self.W[:] = s0.w
        if self.lazy:
            hold, n_samples = _hold(sc.n_steps, sc.dt, dist.wave_sample_time, dist.wave_power)
            self._scale = math.sqrt(dist.wave_power / dist.wave_sample_time)
            self._fb, self._fa = _padded(*band_pass_eq39(sc.dt))
            if self._fb.shape != (3,):      # lane_seas.fill_rows filters a second-order section
                raise ValueError(f"the wave filter must be of second order, got {self._fb.shape[0] - 1}")
        else:
            hold, n_samples, self._scale = 1, 0, 0.0
            self._fb, self._fa = np.zeros(1), np.ones(1)
        self._hold = hold
        self.S = np.zeros((n, n_samples))
        self.Z = np.zeros((n, max(self._fb.shape[0] - 1, 1)))

    def _sea_args(self):
        return (self.lazy, self.S, self.Z, self._base, self._hold, self._fb, self._fa, W_RUDDER)

    def _parallel(self, name: str, one: Any, one_args: tuple) -> tuple[Any, int]:
        """The compiled threaded entry point ``name`` and the address of the one-call entry point
        ``one`` it runs on each range (:mod:`steerlab.jit.numba_call_at`), for a call ``one(*one_args)``
        (the types of these arguments do not change over the life of an ``Episodes``: its own
        arrays, and contiguous actions, lanes and flags). Taken on first use, so that the compile
        message of :func:`steerlab.jit.drivers.entry` comes only when it is compiled."""
        got = self._par.get(name)
        if got is None:
            from steerlab.jit.numba_stamped import numba

            from steerlab.jit.numba_call_at import address_of
            from steerlab.jit.drivers import entry

            at = address_of(one, tuple(numba.typeof(v) for v in one_args))
            got = self._par[name] = (entry(self._kernels, name), at)
        return got

    def _threads(self, m: int) -> int:
        """Threads for a compiled call over ``m`` lanes: 1 below ``threads_from``, else
        ``threads``; None: ``numba.get_num_threads()`` on a threading layer where threads pay,
        else 1 (:func:`steerlab.jit.threading_layer.threads_pay`: not on workqueue)."""
        if m < self.threads_from or not internals_allowed():   # the threaded step: call_at
            return 1
        if self.threads is not None:
            return self.threads
        return num_threads() if threads_pay() else 1

    # ----------------------------------------------------------------- reset
    def reset_lanes(self, lanes: Union[Iterable[int], np.ndarray],
                    seeds: Optional[Sequence[Optional[int]]] = None) -> list[dict[str, Any]]:
        """Reset ``lanes`` (indices) to their next episode; ``seeds[i]`` (int or None) first
        keys lane ``lanes[i]`` with that seed (episode 0). A lane never keyed is keyed from
        the operating system's entropy. Returns one info dict per lane. From ``threads_from``
        distinct lanes on, the compiled resets are spread over the threads as the step's
        (:meth:`step_autoreset`), with the same numbers."""
        from steerlab.jit.philox import seed_key

        lanes = np.ascontiguousarray(lanes, dtype=np.int64).reshape(-1)
        if seeds is not None or not self.keyed[lanes].all():
            new = {}                                       # all checked before any lane changes
            for q, i in enumerate(lanes.tolist()):
                s = None if seeds is None else seeds[q]
                if s is not None or not self.keyed[i]:
                    new[i] = seed_key(s)
            for i, key in new.items():
                self.KEY[i] = key
                self.EP[i] = 0
                self.keyed[i] = True
        m = lanes.shape[0]
        sea_seeds = self._sea_seeds[:m]
        args = (self.KEY, self.EP, self.S, self.Z, self._scale, self.offset_max, self.X, self.K, self.J, self.cmd,
                self.PS, self.GZ, self.REF, self._x0, self._ps0, self.gz0, self._ref0, self.gd, self.control_dt,
                self.rpm_slot, self.obs, self.rew, self.bad)
        threads = self._threads(m)
        if threads > 1 and np.unique(lanes).shape[0] == m:   # distinct lanes: disjoint rows, spread
            par, at = self._parallel("reset_parallel", self._reset, (lanes, *args, sea_seeds))
            launch(par, at, range_cuts(m, 1, threads), lanes, *args, sea_seeds)
        else:
            self._reset(lanes, *args, sea_seeds)
        if self.terms is not None:
            self.terms.restart(lanes, self.obs[lanes, OBS_DELTA])
        self._observe()
        infos = [{"episode": int(self.EP[i]) - 1, "initial_heading": float(self.X[i, IPSI])} for i in lanes.tolist()]
        if not self._fast_seas:
            for q, i in enumerate(lanes.tolist()):
                self.W[i] = self._realise(self.design, int(sea_seeds[q])).w
                infos[q]["sea_seed"] = int(sea_seeds[q])
        return infos

    # ----------------------------------------------------------------- step
    def orders(self, actions: ArrayLike) -> np.ndarray:
        """Rudder orders [rad] from actions in [-1, 1] (fraction of the gear limit); refuses others."""
        a = np.asarray(actions, dtype=np.float64).reshape(self.n)
        if not (np.abs(a) <= 1.0).all():                 # NaN fails the comparison too
            raise self._refused(a[int(np.argmax(~(np.abs(a) <= 1.0)))])
        return a * self.delta_max

    def _refused(self, value):
        return InputError("action", f"must be finite and in [-1, 1] (rudder order / gear limit "
                                    f"{math.degrees(self.delta_max):g} deg), got {value!r}")

    def step(self, actions: ArrayLike, active: Optional[np.ndarray] = None
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Advance the ``active`` lanes (default all) by one env step with the scalar kernel (the
        single environment); fills ``obs``, ``rew``, ``bad``; returns ``(obs, rew, terminated,
        truncated)``."""
        if self.vectorised:
            raise RuntimeError("a vectorised Episodes steps with step_autoreset()")
        self.cmd[:] = self.orders(actions)
        act = self.active if active is None else active
        self._step(self.X, self.K, self.J, self.cmd, self.W, self.PS, self.PG, self.dt, self.nc, self.gd,
                   self.GZ, self.REF, self.rpm_slot, self.lam, self.reward, act, self.obs, self.rew, self.bad,
                   self._work, *self._sea_args())
        self._shape(act)
        truncated = self.J >= self.n_env_steps
        return self.observed, self.rew, self.bad.copy(), truncated & ~self.bad

    @property
    def observed(self) -> np.ndarray:
        """The observations handed out: ``obs`` (raw) or ``features`` (normalised), (N, n_obs)."""
        return self.obs if self.features is None else self.features

    def _observe(self) -> None:
        if self.features is not None:
            from steerlab.gym.observations import normalised_lanes

            normalised_lanes(self.X, self.REF, self.bad, self.delta_max, self.features)

    def _shape(self, stepped: np.ndarray) -> None:
        """After a step of the ``stepped`` lanes (bool mask): the weighted reward terms and the
        normalised observation, where chosen."""
        if self.terms is not None:
            self.terms.step(stepped, self.obs[:, OBS_E], self.obs[:, OBS_DELTA], self.K * self.dt,
                            self.REF[:, REF_XTE], self.bad, self.rew)
        self._observe()

    def step_autoreset(self, actions: ArrayLike, redo: np.ndarray, term: np.ndarray, trunc: np.ndarray) -> None:
        """The vector environment's step (``step`` of :func:`steerlab.gym.plant_batch.env_kernels`): the
        lanes not in ``redo`` (N,) bool advance with ``actions`` (N,) in [-1, 1], the ``redo``
        lanes reset to their next episode (action ignored, reward 0); fills ``obs``, ``rew``,
        ``term``, ``trunc`` and sets ``redo = term | trunc``. One compiled call for all lanes;
        from ``threads_from`` lanes (:data:`THREADS_FROM`) on, ``step_parallel``: all actions
        checked first, then ``threads`` contiguous ranges of whole groups
        (:func:`steerlab.sim.lanes.range_cuts`) spread over numba's threads (a ``prange``,
        :mod:`steerlab.jit.threading_layer`). A lane's numbers do not depend on the split."""
        a = np.ascontiguousarray(actions, dtype=np.float64).reshape(self.n)
        again = None if self.lazy else redo.copy()
        before = redo.copy() if self.terms is not None else None
        args = (a, redo, self.X, self.K, self.J, self.cmd, self.W, self.w_index, self.PS, self.PG, self.dt,
                self.nc, self.gd, self.GZ, self.REF, self.rpm_slot, self.lam, self.reward, self.obs, self.rew,
                self.bad, term, trunc, self.n_env_steps, self.delta_max, *self._sea_args(), self.KEY, self.EP,
                self._scale, self.offset_max, self._x0, self._ps0, self.gz0, self._ref0, self._fast_seas)
        threads = self._threads(self.n)
        if threads <= 1:
            i = self._vstep(0, self.n, *args)
        else:                                              # every action checked before any lane moves
            cuts = self._cuts.get(threads)
            if cuts is None:
                cuts = self._cuts[threads] = range_cuts(self.n, LANES, threads)
            if not all(f.dtype == np.bool_ and f.ndim == 1 and f.flags.c_contiguous for f in (redo, term, trunc)):
                raise TypeError("redo, term and trunc must be contiguous 1-d bool arrays")   # the types step_at takes
            par, at = self._parallel("step_parallel", self._vstep, (0, self.n, *args))
            i = launch(par, at, cuts, *args)
        if i >= 0:
            raise self._refused(a[i])
        if before is not None and before.any() and self.terms is not None:   # reset in the compiled step
            self.terms.restart(np.flatnonzero(before), self.obs[before, OBS_DELTA])
        if again is not None and again.any():              # seas realised lane by lane: reset here
            self.reset_lanes(np.flatnonzero(again))
        self._shape(~before if before is not None else np.ones(self.n, dtype=np.bool_))
