"""Turn a validated :class:`~steerlab.sim.scenario.Scenario` into SI arrays for the engines."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from steerlab.control.design_context import DesignContext
from steerlab.control.registry import ControllerSpec, get_controller
from steerlab.environment.disturbance import Disturbance, build_disturbance
from steerlab.environment.sea import SeaContext, add_sea, uses_sea
from steerlab.errors import InputError
from steerlab.guidance.plan import GuidancePlan, build_guidance
from steerlab.guidance.reference_vector import initial_reference
from steerlab.sensors.wrapper import with_sensors
from steerlab.ships.registry import ShipSpec, get_ship
from steerlab.steering_gear import SteeringGear
from steerlab.units import knots_to_ms, rad


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


def controller_params(cfg, ctx: DesignContext):
    """``(controller, packed params)`` for a validated controller config (its module's ``build``)."""
    return get_controller(cfg.type).build(cfg, ctx)


def build(scenario) -> SimSetup:
    """Validate the combination and pack the arrays (raises :class:`InputError`)."""
    return _realise(_Design.of(scenario), scenario.seed)


def build_seeds(scenario, seeds) -> list[SimSetup]:
    """``build`` of the scenario with each of ``seeds``: the seed-independent part (ship,
    gear, controller design, guidance, initial state) is built once, the seas (and sensor
    noise keys) per seed. Each setup equals ``build(scenario.replace(seed=seed))``."""
    design = _Design.of(scenario)
    return [_realise(design, int(seed)) for seed in seeds]


@dataclass(frozen=True)
class _Design:
    """The part of a setup that does not depend on the seed."""

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

    @classmethod
    def of(cls, s) -> "_Design":
        ship = get_ship(s.ship.model)
        ctrl_spec = get_controller(s.controller.type)
        speed = knots_to_ms(s.ship.speed_kn)
        ship_options = ship.options(s.ship.options)
        ps = ship.pack(speed, s.ship.rpm, ship_options)
        gear = SteeringGear(rad(s.gear.delta_max_deg), rad(s.gear.rate_max_deg_s), s.gear.T_sg,
                            rad(s.gear.dead_zone_deg))
        pg = gear.pack()
        ts = s.controller.sample_time if s.controller.sample_time is not None else s.dt
        ctrl, pc = controller_params(s.controller, DesignContext(ship, speed, gear, s.dt, ts, ship_options))
        nc = int(round(ts / s.dt))
        if nc < 1 or abs(nc * s.dt - ts) > 1e-9 * max(ts, 1.0):
            raise InputError("controller.sample_time", f"must be a positive multiple of dt={s.dt} s, got {ts} s")
        psi0 = rad(s.guidance.psi0_deg)
        plan = build_guidance(s.guidance, ship, ps)
        if s.n_steps > 50_000_000:
            raise InputError("duration", f"duration/dt = {s.n_steps} steps; allowed at most 50000000")
        x0 = np.zeros(ship.n_states + 1)
        x0[0], x0[1] = s.guidance.start
        x0[2] = psi0
        x0[3] = speed
        ref0 = (psi0, 0.0)
        if plan.guide is not None:        # the controller starts on the guidance's first reference
            ref = initial_reference()
            plan.guide(0.0, x0, plan.gd, plan.gz0.copy(), ref, nc * s.dt)
            ref0 = (float(ref[0]), float(ref[1]))
        z0 = np.asarray(ctrl.init_state(x0, ref0), dtype=float)
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
        return cls(s, ship, ctrl_spec, ps, pg, pc, z0, x0, ref0, plan, nc, ts, speed, ship_options, dist)


def _realise(d: _Design, seed: int) -> SimSetup:
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
            headings = lambda t: np.full(len(t), ref0[0])  # noqa: E731
        add_sea(w, env, SeaContext(ship, d.ps, d.x0, speed, lambda: ship.nomoto(speed, ship_options),
                                   headings, lambda: _rudder_b2(ship, speed, ship_options)),
                s.dt, seed)
    ctrl_spec, pc, z0 = d.ctrl_spec, d.pc, d.z0
    if s.sensors is not None:
        ctrl_spec, pc, z0 = with_sensors(ctrl_spec, pc, z0, s.sensors, seed, d.ts, d.x0.shape[0])
    return SimSetup(ship, ctrl_spec, d.ps.copy(), d.pg.copy(), pc.copy(), gd.copy(), d.x0.copy(), z0.copy(),
                    w, s.dt, d.nc, s.n_steps, s.name, seed, d.plan)


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
        out[i] = ref[0]
    return out
