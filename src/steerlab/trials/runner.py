"""Run a manoeuvre program on a ship: trial conditions -> :class:`SimSetup` -> :class:`Result`.

A trial setup is built like any run: a scenario dict (ship, speed, ship options, gear) goes
through :func:`steerlab.sim.scenario.scenario_from_dict` and :func:`steerlab.sim.setup.build`
(same validation, same packing); then :func:`dataclasses.replace` swaps in the manoeuvre
program (:data:`~steerlab.trials.program.TRIAL_PROGRAM`, sampled every step) for the
placeholder autopilot. The compiled engine runs it; one loop is compiled per ship model and
process.

"Open loop or with the gear"
----------------------------
* ``gear=True`` (default): the scenario's steering gear (Zwierzewicz et al. 2021 eq 15:
  35 deg, 2.33 deg/s, servo lag 1 s; IMO trials assume a gear of at least that rate). A scale
  model (``ShipSpec.model_scale``, e.g. ``kvlcc2-l7``, ``kosoko``) gets that gear
  Froude-scaled (:func:`steerlab.steering_gear.froude_scaled`: ``kvlcc2-l7`` 15.75 deg/s and
  0.148 s), unless ``gear_config`` says otherwise.
* ``gear=False`` (``--no-gear``, "open loop"): an ideal rudder that follows the order: the
  same gear kernel with no rate limit and a servo lag ``T = dt/1.6`` (the lag RK4 damps
  fastest: the rudder reaches 73 % of a step in one integration step, 98 % in three, i.e.
  within 0.3 s at ``dt = 0.1 s``); the rudder-angle limit stays.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from steerlab.errors import InputError, require_finite_range
from steerlab.sim.engine import simulate
from steerlab.sim.scenario import scenario_from_dict
from steerlab.sim.setup import SimSetup, design, realise
from steerlab.sim.setup import scenario_gear as _scenario_gear
from steerlab.ships.registry import get_ship
from steerlab.steering_gear import SteeringGear
from steerlab.trials.program import TRIAL_PROGRAM, TrialProgramConfig
from steerlab.trials.program import build as build_program
from steerlab.units import KNOT, deg, knots_to_ms, rad
from steerlab.ships.state import IPSI

DEFAULT_SPEED_KN = 16.0
IDEAL_GEAR_LAG_STEPS = 1.6
MAX_DURATION = 200_000.0   # s: no trial program runs longer (about 55 h of ship time)


@dataclass(frozen=True)
class TrialConditions:
    """What a trial is run on.

    ship : registry name; speed_kn : approach speed [kn] (None: :func:`default_speed_kn`);
    options : raw ``[ship.options]`` (validated by the ship; a water depth is the ship's
    ``depth_m`` option where its model has shallow-water terms); gear : scenario steering gear
    (True) or the ideal rudder (False); gear_config : overrides of the ``[gear]`` table
    (``delta_max_deg``, ``rate_max_deg_s``, ``T_sg``; keys left out: the ship's default gear);
    dt : integration step [s]; rpm : propeller rate [rev/min] held through the trial (the
    scenario's ``[ship] rpm``; None: the ship's own, e.g. the self-propulsion rate of the
    approach speed).
    """

    ship: str
    speed_kn: float | None = None
    options: dict = field(default_factory=dict)
    gear: bool = True
    gear_config: dict = field(default_factory=dict)
    dt: float = 0.1
    rpm: float | None = None

    def resolved(self) -> "TrialConditions":
        """A copy with the ship checked and the default speed filled in."""
        ship = get_ship(self.ship)
        v = default_speed_kn(ship) if self.speed_kn is None else self.speed_kn
        lo, hi = ship.speed_range
        require_finite_range("speed_kn", v, 0.0, 40.0, lo_open=True)
        if not (lo <= knots_to_ms(v) <= hi):
            raise InputError("speed_kn", f"{v} kn is outside the validity range of {ship.name!r}: "
                                         f"[{lo / KNOT:.3g}, {hi / KNOT:.3g}] kn")
        require_finite_range("dt", self.dt, 0.0, 5.0, lo_open=True)
        return replace(self, speed_kn=float(v))

    @property
    def speed(self) -> float:
        """Approach speed [m/s]."""
        return knots_to_ms(self.speed_kn)


def default_speed_kn(ship) -> float:
    """16 kn; when 16 kn lies outside the ship's validity range, the speed its source states
    (``service_speed``: ``kvlcc2-l7``'s 1.179 m/s of the free-running tests, Kosoko's 0.5 m/s),
    else the middle of that range."""
    lo, hi = ship.speed_range
    if lo <= knots_to_ms(DEFAULT_SPEED_KN) <= hi:
        return DEFAULT_SPEED_KN
    if ship.service_speed is not None and lo <= ship.service_speed <= hi:
        return float(ship.service_speed) / KNOT
    top = hi if math.isfinite(hi) else 2.0 * lo
    return round(0.5 * (lo + top) / KNOT, 2)


def _scenario(cond: TrialConditions, duration: float):
    return scenario_from_dict({
        "name": f"trial-{cond.ship}", "seed": 0, "dt": cond.dt, "duration": duration,
        "ship": {"model": cond.ship, "speed_kn": cond.speed_kn, "options": dict(cond.options),
                 **({} if cond.rpm is None else {"rpm": cond.rpm})},
        "gear": dict(cond.gear_config),
        "controller": {"type": "pid", "gains": "paper"},        # placeholder, replaced by the manoeuvre program
        "guidance": {"psi0_deg": 0.0, "changes": []},
        "environment": {},
    })


def scenario_gear(scenario) -> SteeringGear:
    """The scenario's steering gear (SI), built the same way as :func:`steerlab.sim.setup.build`."""
    return _scenario_gear(scenario)


def ideal_gear(gear: SteeringGear, dt: float) -> SteeringGear:
    """The ideal rudder of ``--no-gear`` (see the module docstring); keeps the angle limit."""
    return SteeringGear(gear.delta_max, 1e6, dt / IDEAL_GEAR_LAG_STEPS, 0.0)


def gear_limit_deg(cond: TrialConditions) -> float:
    """The rudder-angle limit [deg] of the trial's gear."""
    return float(cond.gear_config.get("delta_max_deg", SteeringGear().delta_max * 180.0 / math.pi))


def trial_setup(cond: TrialConditions, program: TrialProgramConfig, duration: float) -> SimSetup:
    """A :class:`SimSetup` that runs ``program`` on the trial's ship for ``duration`` [s]."""
    cond = cond.resolved()
    if not (0.0 < duration <= MAX_DURATION):
        raise InputError("duration", f"trial duration {duration:.0f} s is outside (0, {MAX_DURATION:.0f}] s")
    scenario = _scenario(cond, duration)
    d = design(scenario)
    base = realise(d, scenario.seed)
    gear = d.gear if cond.gear else ideal_gear(d.gear, cond.dt)
    prog, pc = build_program(program, d.context(gear=gear, sample_time=cond.dt))
    pg = base.pg if cond.gear else gear.pack()
    z0 = prog.init_state(base.x0, (base.x0[IPSI], 0.0))
    return replace(base, controller=TRIAL_PROGRAM, pc=np.asarray(pc, dtype=float), z0=z0, nc=1, pg=pg,
                   name=f"{program.kind}-{cond.ship}")


def run_program(cond: TrialConditions, program: TrialProgramConfig, duration: float, engine: str = "compiled"):
    """Simulate ``program`` on the trial's ship; returns the :class:`Result`."""
    return simulate(trial_setup(cond, program, duration), engine=engine)


def ship_length(cond: TrialConditions) -> float:
    """Ship length L [m]: the ``L`` of the validated ``[ship.options]`` when the ship has one
    (``nomoto1`` takes its length as an option), else ``ShipSpec.dims[1]``."""
    ship = get_ship(cond.ship)
    opts = ship.options(cond.options)
    L = getattr(opts, "L", None) if opts is not None else None
    return float(L) if isinstance(L, (int, float)) and L > 0 else float(ship.dims[1])


def time_scale(cond: TrialConditions) -> dict:
    """Time scales of the ship at the trial speed: ``L/U`` [s] and the Nomoto ``|T|`` [s] (or None).

    Used only to choose durations and hold times; every trial checks afterwards that what it
    measures did become steady and runs longer when not.
    """
    cond = cond.resolved()
    ship = get_ship(cond.ship)
    L = ship_length(cond)
    out = {"L": L, "U": cond.speed, "L_over_U": L / cond.speed, "K": None, "T": None}
    try:
        K, T = ship.nomoto(cond.speed, ship.options(cond.options))
        if math.isfinite(K) and math.isfinite(T) and T != 0.0:
            out["K"], out["T"] = float(K), float(T)
    except (InputError, ValueError, np.linalg.LinAlgError, ZeroDivisionError):
        pass
    out["slow"] = max(out["L_over_U"], abs(out["T"]) if out["T"] is not None else 0.0)
    return out


def run_until(make_program, cond: TrialConditions, duration: float, done, max_doublings: int = 4,
              label: str | None = None):
    """Run, and rerun with twice the duration until ``done(result)`` (at most ``max_doublings`` times).

    Returns ``(result, converged)``.
    """
    res = None
    for _ in range(max_doublings + 1):
        duration = min(duration, MAX_DURATION)
        program = make_program(duration)
        res = run_program(cond, program, duration)
        check_bounded(res, cond, label or program.kind)
        if done(res):
            return res, True
        if duration >= MAX_DURATION:
            break
        duration *= 2.0
    return res, False


def check_bounded(res, cond: TrialConditions, what: str) -> None:
    """Raise :class:`InputError` when the ship model diverged (non-finite state, |r| > 1 rad/s).

    A linear course-unstable model (e.g. ``nomoto1`` with ``T < 0``) has no steady turn: its
    rate of turn grows without bound, and no trial metric means anything.
    """
    r_max = max(1.0, 10.0 * cond.speed / ship_length(cond))
    if not np.all(np.isfinite(res.states)) or float(np.max(np.abs(res.r))) > r_max:
        raise InputError("ship", f"the {cond.ship!r} model diverges during the {what} trial (|r| beyond "
                                 f"{r_max:.3g} rad/s): it has no steady turn with these options")


def rudder_limit_check(cond: TrialConditions, rudder_deg: float, field_name: str = "rudder") -> float:
    """``|rudder_deg|`` within ``(0, gear limit]``, else :class:`InputError`."""
    lim = gear_limit_deg(cond)
    require_finite_range(field_name, rudder_deg, 0.0, lim, lo_open=True)
    return float(rudder_deg)


def speed_of(res) -> np.ndarray:
    """Speed over ground of the reference point ``V = sqrt(u^2 + v^2)`` [m/s]."""
    return np.hypot(res.col("u"), res.col("v"))


def heading_change(res, psi0: float = 0.0) -> np.ndarray:
    """Unwrapped heading change ``psi(t) - psi0`` [rad] (continuous through +-180 deg)."""
    return np.unwrap(res.psi) - psi0


def gear_of(cond: TrialConditions):
    """The scenario's ``[gear]`` table (validated, degrees) the trial runs with (the ship's
    default gear for the keys ``gear_config`` leaves out)."""
    return _scenario(cond.resolved(), 1.0).gear


def gear_description(cond: TrialConditions) -> str:
    """One line: the gear the trial runs with and where its rate and lag come from."""
    if not cond.gear:
        return "ideal rudder (--no-gear)"
    g = gear_of(cond)
    ship = get_ship(cond.ship)
    text = f"gear {g.delta_max_deg:g} deg, {g.rate_max_deg_s:.4g} deg/s, servo lag {g.T_sg:.3g} s"
    if ship.model_scale is not None:
        given = [k for k in ("rate_max_deg_s", "T_sg") if k in cond.gear_config]
        how = ("given" if len(given) == 2 else
               f"Froude-scaled for the 1:{ship.model_scale:g} model"
               + (" (lag given)" if given == ["T_sg"] else " (rate given)" if given else ""))
        text += f" ({how})"
    return text


def conditions_dict(cond: TrialConditions) -> dict:
    """The trial conditions for a JSON report (edge units): the ship, the approach speed, the
    propeller rate, the gear (limit, rate, servo lag), the water depth and the model scale."""
    ts = time_scale(cond)
    ship = get_ship(cond.ship)
    g = gear_of(cond)
    opts = ship.options(cond.options)
    depth = getattr(opts, "depth_m", None) if opts is not None else None
    return {"ship": cond.ship, "speed_kn": cond.speed_kn, "speed_m_s": cond.speed,
            "ship_options": dict(cond.options), "gear": "scenario steering gear" if cond.gear else
            "ideal rudder (--no-gear)", "gear_description": gear_description(cond),
            "rudder_limit_deg": gear_limit_deg(cond),
            "rudder_rate_deg_s": g.rate_max_deg_s if cond.gear else None,
            "servo_lag_s": g.T_sg if cond.gear else cond.dt / IDEAL_GEAR_LAG_STEPS,
            "propeller_rps": None if cond.rpm is None else cond.rpm / 60.0,
            "propeller": ("held at the given rate" if cond.rpm is not None else
                          "the ship's own (MMG ships: the self-propulsion rate of the approach speed, held)"),
            "water_depth_m": depth, "model_scale": ship.model_scale, "dt_s": cond.dt,
            "L_m": ts["L"], "L_over_U_s": ts["L_over_U"], "nomoto_K_1_s": ts["K"], "nomoto_T_s": ts["T"]}


__all__ = ["TrialConditions", "trial_setup", "run_program", "run_until", "time_scale", "deg", "rad"]
