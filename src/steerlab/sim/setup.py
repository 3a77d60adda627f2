"""Turn a validated :class:`~steerlab.sim.scenario.Scenario` into SI arrays for the engines."""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from steerlab.control.design_context import DesignContext
from steerlab.control.registry import ControllerSpec, get_controller
from steerlab.environment.disturbance import Disturbance, build_disturbance
from steerlab.environment.sea import SeaContext, add_sea, uses_sea
from steerlab.errors import InputError
from steerlab.sim.inert_settings import warn_inert_settings
from steerlab.guidance.plan import GuidancePlan, build_guidance
from steerlab.guidance.reference_vector import REF_PSI, REF_R, initial_reference
from steerlab.sensors.wrapper import SUFFIX as SENSORS_SUFFIX
from steerlab.sensors.wrapper import sensed_spec, with_sensors
from steerlab.ships.registry import ShipSpec, get_ship
from steerlab.steering_gear import SteeringGear
from steerlab.units import rad
from steerlab.ships.state import IPSI, IU, IX, IY


@dataclass(frozen=True)
class SimSetup:
    """Everything an engine needs for one run, in SI; arrays are packed kernel records."""

    ship: ShipSpec
    controller: ControllerSpec
    ps: np.ndarray      # ship parameters
    pg: np.ndarray      # steering-gear parameters
    pc: np.ndarray      # controller parameters
    gd: np.ndarray      # guidance schedule
    x0: np.ndarray      # plant state [ship states..., delta]
    z0: np.ndarray      # controller state
    w: np.ndarray       # disturbances (n_steps + 1, channels)
    dt: float
    nc: int             # controller sample = nc * dt
    n_steps: int
    name: str = "scenario"
    seed: int = 0
    guidance: GuidancePlan | None = None   # None: the time-only course schedule in gd

    @property
    def guide(self):
        """State-dependent guidance kernel ``guide(t, x, gd, gz, ref, h)``; None = time-only course."""
        return None if self.guidance is None else self.guidance.guide

    @property
    def gz0(self) -> np.ndarray:
        """Initial guidance state."""
        return np.zeros(0) if self.guidance is None else self.guidance.gz0

    @property
    def rpm_slot(self) -> int:
        """Index in ``ps`` of the propeller rate the guidance orders (-1: none)."""
        return -1 if self.guidance is None else self.guidance.rpm_slot

    @property
    def state_names(self):
        return tuple(self.ship.state_names) + ("delta",)

    @property
    def state_units(self):
        return tuple(self.ship.state_units) + ("rad",)


def controller_spec(name: str) -> ControllerSpec:
    """The spec of a controller name as a setup carries it, wrappers included:
    ``"pid"``, ``"pid+wf"`` (registered) or ``"pid+sensors"`` (the ``[sensors]`` wrapper that
    :func:`realise` applies). Batches keep names, not kernels, and resolve them here."""
    if name.endswith(SENSORS_SUFFIX):
        return sensed_spec(controller_spec(name[:-len(SENSORS_SUFFIX)]))
    return get_controller(name)


def scenario_gear(s) -> SteeringGear:
    """The scenario's steering gear (SI) from its ``[gear]`` table."""
    return gear_from_config(s.gear)


def gear_from_config(g) -> SteeringGear:
    """A steering gear (SI) from a validated ``[gear]`` table (degrees at the edge)."""
    return SteeringGear(rad(g.delta_max_deg), rad(g.rate_max_deg_s), g.T_sg, rad(g.dead_zone_deg))


def build(scenario) -> SimSetup:
    """Validate the combination and pack the arrays (raises :class:`InputError`)."""
    return realise(design(scenario), scenario.seed)


def build_seeds(scenario, seeds) -> list[SimSetup]:
    """``build`` of the scenario with each of ``seeds``: the seed-independent part (ship,
    gear, controller design, guidance, initial state) is built once, the seas (and sensor
    noise keys) per seed. Each setup equals ``build(scenario.replace(seed=seed))``."""
    d = design(scenario)
    return [realise(d, int(seed)) for seed in seeds]


def design(scenario) -> "Design":
    """The seed-free :class:`Design` of a validated scenario (raises :class:`InputError`)."""
    return Design.of(scenario)


@dataclass(frozen=True)
class Design:
    """The part of a setup that does not depend on the seed.

    The one place where a scenario's design context (:class:`DesignContext`), steering gear
    and controller design are built and where the controller wrappers are applied: ``+wf``
    is a registered controller type (designed here like any other), ``+sensors`` is applied
    per seed by :meth:`wrapped` (through :meth:`controller_record` and :func:`realise`) when
    the scenario has ``[sensors]``. Every command (run, batch, Monte-Carlo, robustness, tune, trials, the
    runtime's controller) goes through it.
    """

    scenario: object
    ship: ShipSpec
    ctrl_spec: ControllerSpec
    ps: np.ndarray
    pg: np.ndarray
    pc: np.ndarray
    z0: np.ndarray
    x0: np.ndarray
    ref0: tuple
    plan: GuidancePlan
    nc: int
    ts: float
    speed: float
    ship_options: object
    dist: Disturbance
    gear: SteeringGear = None
    ctx: DesignContext = None
    ctrl: object = None          # the designed controller (``init_state``)

    @classmethod
    def of(cls, s) -> "Design":
        ship = get_ship(s.ship.model)
        speed = s.ship.speed()             # speed_kn, else the ship's design speed
        ship_options = ship.options(s.ship.options)
        ship = ship.for_options(ship_options)
        ps = ship.pack(speed, s.ship.rpm, ship_options)
        gear = scenario_gear(s)
        pg = gear.pack()
        ts = s.controller.sample_time if s.controller.sample_time is not None else s.dt
        ctx = DesignContext(ship, speed, gear, s.dt, ts, ship_options)
        ctrl_spec = get_controller(s.controller.type)
        ctrl, pc = ctrl_spec.build(s.controller, ctx)
        nc = int(round(ts / s.dt))
        if nc < 1 or abs(nc * s.dt - ts) > 1e-9 * max(ts, 1.0):
            raise InputError("controller.sample_time", f"must be a positive multiple of dt={s.dt} s, got {ts} s")
        psi0 = rad(s.guidance.psi0_deg)
        plan = build_guidance(s.guidance, ship, ps)
        if s.n_steps > 50_000_000:
            raise InputError("duration", f"duration/dt = {s.n_steps} steps; allowed at most 50000000")
        x0 = np.zeros(ship.n_states + 1)
        x0[IX], x0[IY] = s.guidance.start
        x0[IPSI] = psi0
        x0[IU] = speed
        ref0 = (psi0, 0.0)
        if plan.guide is not None:        # the controller starts on the guidance's first reference
            ref = initial_reference()
            plan.guide(0.0, x0, plan.gd, plan.gz0.copy(), ref, nc * s.dt)
            ref0 = (float(ref[REF_PSI]), float(ref[REF_R]))
        z0 = np.asarray(ctrl.init_state(x0, ref0), dtype=float)
        check_state_size(ctrl_spec, z0)
        ws = s.environment.wave_sample_time
        eq39 = s.environment.waves or (s.environment.wave is not None and s.environment.wave.model == "eq39")
        if eq39 and abs(ws / s.dt - round(ws / s.dt)) > 1e-9 * max(1.0, ws / s.dt):
            raise InputError("environment.wave_sample_time",
                             f"must be a positive integer multiple of dt={s.dt} s, got {ws} s")
        env = s.environment
        dist = Disturbance(rad(env.constant_rudder_deg), env.constant_start, eq39,
                           env.wave_sample_time, env.wave_power, wind_speed=env.wind_speed,
                           wind_dir=rad(env.wind_dir_deg), current_speed=env.current_speed,
                           current_dir=rad(env.current_dir_deg))
        # settings its models do not read: one warning each
        warn_inert_settings(s, ship, ps, x0, lambda rpm: ship.pack(speed, rpm, ship_options))
        return cls(s, ship, ctrl_spec, ps, pg, pc, z0, x0, ref0, plan, nc, ts, speed, ship_options, dist,
                   gear, ctx, ctrl)

    def context(self, gear: SteeringGear | None = None, sample_time: float | None = None) -> DesignContext:
        """The design context, optionally with another gear or controller sample time [s]."""
        return replace(self.ctx, gear=self.gear if gear is None else gear,
                       sample_time=self.ts if sample_time is None else float(sample_time))

    def designed(self, cfg=None):
        """``(spec, controller, pc, z0)`` of the controller config ``cfg`` (default: the
        scenario's, already designed) in this design's context, starting on ``ref0``."""
        if cfg is None:
            return self.ctrl_spec, self.ctrl, np.asarray(self.pc, dtype=np.float64), self.z0
        spec = get_controller(cfg.type)
        ctrl, pc = spec.build(cfg, self.ctx)
        z0 = np.asarray(ctrl.init_state(self.x0, self.ref0), dtype=float)
        check_state_size(spec, z0)
        return spec, ctrl, np.asarray(pc, dtype=np.float64), z0

    def wrapped(self, spec: ControllerSpec, pc, z0, seed: int):
        """``(spec, pc, z0)`` behind the seed's wrappers: the ``[sensors]`` block, if any."""
        if self.scenario.sensors is None:
            return spec, pc, z0
        return with_sensors(spec, pc, z0, self.scenario.sensors, int(seed), self.ts, self.x0.shape[0])

    def controller_record(self, cfg=None, seed: int = 0):
        """``(spec, pc, z0)`` as a run of ``seed`` uses them (:meth:`designed`, then :meth:`wrapped`)."""
        spec, _, pc, z0 = self.designed(cfg)
        return self.wrapped(spec, pc, z0, seed)


_Design = Design   # the former private name


def check_state_size(spec: ControllerSpec, z0) -> None:
    """``ControllerSpec.n_state`` against the initial state the design gives (InputError naming it)."""
    z0 = np.asarray(z0)
    if z0.ndim != 1 or z0.shape[0] != spec.n_state:
        got = z0.shape[0] if z0.ndim == 1 else f"an array of shape {z0.shape}"
        raise InputError("controller.type", f"controller {spec.name!r} declares n_state = {spec.n_state} "
                                            f"but its init_state gives {got} values")


def realise(d: Design, seed: int) -> SimSetup:
    """The setup of design ``d`` with the seas (and sensor noise) of ``seed``."""
    s = d.scenario
    ship, speed, ship_options, gd = d.ship, d.speed, d.ship_options, d.plan.gd
    w = build_disturbance(d.dist, s.n_steps, s.dt, seed)
    env = s.environment
    if uses_sea(env):
        ref0 = d.ref0
        if d.plan.guide is None:
            headings = lambda t: reference_headings(gd, t)  # noqa: E731
        else:  # state-dependent guidance: its headings are unknown before the run; use the first
            headings = lambda t: np.full(len(t), ref0[REF_PSI])  # noqa: E731
        add_sea(w, env, SeaContext(ship, d.ps, d.x0, speed, lambda: ship.nomoto(speed, ship_options),
                                   headings, lambda: _rudder_b2(ship, speed, ship_options)),
                s.dt, seed)
    ctrl_spec, pc, z0 = d.controller_record(seed=seed)
    return SimSetup(ship, ctrl_spec, d.ps.copy(), d.pg.copy(), pc.copy(), gd.copy(), d.x0.copy(), z0.copy(),
                    w, s.dt, d.nc, s.n_steps, s.name, seed, d.plan)


_realise = realise


def _rudder_b2(ship, speed, options) -> float:
    """Rudder yaw acceleration per rad [1/s^2]: the linearisation's b2, else eq (29)'s estimate."""
    try:
        return ship.b2(speed, "exact", options)
    except Exception:  # noqa: BLE001 - ships without a linearisation
        return ship.b2(speed, "estimate", options)


def reference_headings(gd, t) -> np.ndarray:
    """The guidance's reference heading [rad] at the times ``t`` (for up-front disturbances)."""
    from steerlab.guidance.reference_models import course_reference

    ref = np.zeros(2)
    out = np.empty(len(t))
    for i, ti in enumerate(t):
        course_reference(float(ti), gd, ref)
        out[i] = ref[REF_PSI]
    return out
