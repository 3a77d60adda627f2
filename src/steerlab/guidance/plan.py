"""Turn a validated ``[guidance]`` section into what the engines run: kernel, record, state.

Guidance kinds (``[guidance] type``)::

    course         time-only schedule of set courses (optionally turn-rate limited):
                   :func:`~steerlab.guidance.reference_models.course_reference`
    rate_limited   van Amerongen's rate-of-turn-limited course-change model (Fig. 3.4 / 4.9)
    third_order    3rd-order reference model with rate and acceleration limits
                   (both :mod:`steerlab.guidance.course_models`)
    los            line-of-sight route following, eqs (1)-(3) of the berthing paper
    berthing       LOS to the berth with the stepwise propeller-rate reduction (Sec. 4)
                   (both :mod:`steerlab.guidance.los`)

Guidance kernel interface (all kinds but ``course``)::

    guide(t, x, gd, gz, ref, h)

``t`` [s], ``x`` the plant state (rudder last), ``gd`` the packed record, ``gz`` the
guidance's own state (advanced in place), ``ref`` the reference vector
(:mod:`steerlab.guidance.reference_vector`), ``h`` the controller sample [s]. It is called
at every controller sample, before the controller, by every engine. ``course`` has
``guide = None`` in :class:`GuidancePlan` (it has no state, and sweeps vary its record
freely); the engines run it as the kernel
:func:`~steerlab.guidance.reference_models.course_guide`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable, Optional

import numpy as np

from steerlab.errors import InputError, require_finite_range
from steerlab.guidance import course_models, los
from steerlab.guidance.reference_models import course_schedule
from steerlab.units import knots_to_ms, rad

KINDS = ("course", "rate_limited", "third_order", "los", "berthing")


@dataclass(frozen=True)
class GuidancePlan:
    """What the engines need: ``guide`` (None = time-only ``course_reference``), ``gd``,
    ``gz0``, ``rpm_slot`` (index in the ship record of the propeller rate the guidance's
    order overwrites; -1: none) and, for routes, the geometry for metrics and plots."""

    kind: str
    gd: np.ndarray
    guide: Optional[Callable] = None
    gz0: np.ndarray = field(default_factory=lambda: np.zeros(0))
    rpm_slot: int = -1
    route: Optional[np.ndarray] = None          # (n, 2) [m]
    xte_tolerance: float = math.nan             # [m], |XTE| counted "on route" below it
    berth: Optional[tuple] = None               # (x_n, y_e) [m]
    success_radius: float = math.nan            # [m]
    berth_speed_max: float = math.nan           # [m/s] (model scale)


def propeller_slot(ship, ps: np.ndarray) -> int:
    """Index of the constant propeller rate in an MMG ship record (the berthing plan's order).

    Only the MMG ships (``ships/mmg.py``) take a propeller rate; their record keeps the
    constant rate at ``P_NCONST`` (:mod:`steerlab.ships.rpm_schedule` block).
    """
    from steerlab.ships import mmg

    if ship.rhs not in (mmg.mmg_rhs, mmg.mmg_rhs_constant_rate):
        raise InputError("guidance.type", f"berthing orders the propeller rate; ship {ship.name!r} has no "
                                          "rpm input (use an MMG ship, e.g. kosoko, or type = 'los')")
    if int(ps[mmg.PARAMS.index("rpm.n_points")]) != 0:
        raise InputError("ship.options.rpm_schedule", "berthing plans the propeller rate itself; "
                                                      "remove the rpm_schedule")
    return mmg.P_NCONST


def _route(cfg) -> np.ndarray:
    if cfg.route and cfg.route_file:
        raise InputError("guidance.route", "give either route or route_file, not both")
    if cfg.route_file:
        return los.read_route_csv(cfg.route_file)
    if not cfg.route:
        raise InputError("guidance.route", f"type {cfg.type!r} needs a route: at least 2 waypoints "
                                           "[[x_n, y_e], ...] in metres (or route_file)")
    return los.check_route(cfg.route)


def build_guidance(cfg, ship, ps: np.ndarray) -> GuidancePlan:
    """The plan for a validated :class:`~steerlab.sim.scenario.GuidanceConfig`.

    ``ship`` (a ShipSpec) gives the length ``L`` for ``Delta = lookahead_L * L`` and the
    default radii; ``ps`` is its packed record (berthing overwrites its propeller rate).
    """
    kind = cfg.type
    for i, v in enumerate(cfg.start):
        require_finite_range(f"guidance.start[{i}]", v, -1e8, 1e8)
    psi0 = rad(cfg.psi0_deg)
    if kind == "course":
        for i, c in enumerate(cfg.changes):
            if c.direction != "shortest":
                raise InputError(f"guidance.changes[{i}].direction",
                                 "type 'course' turns the short way; use type 'rate_limited' or "
                                 "'third_order' for a chosen direction")
        gd = course_schedule(psi0, [(c.t, rad(c.psi_deg)) for c in cfg.changes], rad(cfg.rate_max_deg_s))
        return GuidancePlan(kind, gd)
    if kind in course_models.KINDS:
        if cfg.rate_max_deg_s <= 0.0:
            raise InputError("guidance.rate_max_deg_s", f"type {kind!r} needs a rate-of-turn limit > 0 deg/s "
                                                        "(allowed: 0 < rate_max_deg_s <= 10)")
        amax = math.inf if cfg.accel_max_deg_s2 is None else rad(cfg.accel_max_deg_s2)
        gd = course_models.pack_course_model(
            kind, psi0, [(c.t, rad(c.psi_deg), c.direction) for c in cfg.changes],
            cfg.omega_n, cfg.zeta, rad(cfg.rate_max_deg_s), amax)
        return GuidancePlan(kind, gd, course_models.course_model_guidance,
                            course_models.initial_course_state(gd))
    if kind not in ("los", "berthing"):  # pragma: no cover - the schema admits only KINDS
        raise InputError("guidance.type", f"must be one of {KINDS}, got {kind!r}")
    L = float(ship.dims[1])
    route = _route(cfg)
    R = L if cfg.accept_radius_m is None else cfg.accept_radius_m
    tol = R if cfg.xte_tolerance_m is None else cfg.xte_tolerance_m
    if kind == "los":
        if cfg.rpm_plan:
            raise InputError("guidance.rpm_plan", "only type 'berthing' orders the propeller rate")
        gd = los.pack_los(route, cfg.lookahead_L * L, R)
        return GuidancePlan(kind, gd, los.los_guidance, los.initial_los_state(gd), -1, route, tol)
    slot = propeller_slot(ship, ps)
    stages = [(d, rpm / 60.0) for d, rpm in cfg.rpm_plan]
    stop = cfg.stop_radius_m
    gd = los.pack_los(route, cfg.lookahead_L * L, R, stages, stop)
    success = 0.5 * L if cfg.success_radius_m is None else cfg.success_radius_m
    v_max = knots_to_ms(cfg.berth_speed_max_kn) / math.sqrt(cfg.model_scale)
    return GuidancePlan(kind, gd, los.los_guidance, los.initial_los_state(gd), slot, route, tol,
                        tuple(route[-1]), success, v_max)
