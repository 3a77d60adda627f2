r"""One cell of the conformance matrix and the scenario it runs.

A :class:`Case` is (ship, controller, operating point, sea). Its scenario is the one a new
user would write: the ship at that point, the controller with its **default settings**
(``[controller] type = ...`` and nothing else), the scenario's default steering gear
(:data:`GEAR`: 35 deg, 2.33 deg/s, servo 1 s; a scale model's Froude-scaled:
:func:`ship_gear`), ``dt`` = :data:`DT`, and a course change of
:data:`~steerlab.conformance.judge.CHANGE_DEG` to starboard at :data:`T_CHANGE`. The sea is
calm, or a JONSWAP spectrum of WMO sea state 5 (Hs 3.25 m, Tp 9.7 s) from 45 deg off the bow,
seed :data:`SEA_SEED` (:data:`SEA`); on a scale model (``ShipSpec.model_scale`` = ``lambda``)
the same sea Froude-scaled to the model, Hs / lambda and Tp / sqrt(lambda), as a towing tank
sets it (:func:`sea_block`: the KVLCC2 L7 model, ``lambda`` = 45.7, gets Hs 7.1 cm, Tp 1.43 s).

How long it runs follows the ship, not the law (:func:`time_scale`): a heading loop on the
first-order Nomoto model ``r' = -r/T + (K/T) delta`` cannot be much faster than the gear lets
it turn the ship through the change, so the time scale is ``t_s = 2 pi / omega_g`` with

.. math::

    \omega_g = \min\Big(\sqrt{\delta_{max} b / \Delta\psi},\ (\dot\delta_{max} b / \Delta\psi)^{1/3}\Big),
    \qquad b = |K / T|

(the natural frequency at which a PD loop's step of ``Delta psi`` asks for the whole rudder,
or for the rudder at its whole rate within ``1/omega``; cf. ``control/design_model.py``, which
keeps a margin below it). The run lasts ``RUN_SCALES t_s`` after the change, at least
:data:`MIN_AFTER` and at most :data:`MAX_AFTER` seconds; the hold window (where the heading
must stay) is the last ``HOLD_SCALES t_s``, at least :data:`MIN_HOLD` s, at most half the time
after the change. A ship without a finite first-order model (``K/T`` not finite or not > 0)
gets :data:`DEFAULT_TIME_SCALE`. For the catalogue's 76 points this gives 14 s (Kosoko at
2.9 kn) to 2 230 s (the B-481 at 0.97 kn), half of them 63-113 s: most runs are the shortest,
1 050 s; the Esso tanker at 8 kn runs 5 540 s, the slowest points 8 050 s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from steerlab.conformance.judge import CHANGE_DEG
from steerlab.conformance.points import OperatingPoint

DT = 0.1
"""Integration step and controller sample time [s] (the scenario default)."""
T_CHANGE = 50.0
"""Time of the course change [s]."""
RUN_SCALES = 10.0
"""Run length after the change, in time scales ``t_s``."""
HOLD_SCALES = 3.0
"""Hold window, in time scales ``t_s``."""
MIN_AFTER, MAX_AFTER = 1000.0, 8000.0
"""Bounds of the run length after the change [s]."""
MIN_HOLD = 300.0
"""Shortest hold window [s]."""
DEFAULT_TIME_SCALE = 300.0
"""Time scale [s] of a ship without a finite first-order Nomoto model at the point."""
CALM, SEA5 = "calm", "sea5"
SEAS = (CALM, SEA5)
SEA = {"model": "spectrum", "spectrum": "jonswap", "sea_state": 5, "wave_angle_deg": 45.0}
"""``[environment.wave]`` of the sea leg."""
SEA_SEED = 1
"""Seed of the sea realisation (one realisation per case)."""


def sea_block(spec) -> dict:
    """``[environment.wave]`` of the sea leg on ship ``spec``: :data:`SEA`, or on a scale model
    (``spec.model_scale`` = ``lambda`` = L_full / L_model) its Froude-scaled equivalent
    ``Hs / lambda``, ``Tp / sqrt(lambda)`` (the full-scale sea state 5 at model scale: the ship's
    lengths scale with ``lambda`` and its times with ``sqrt(lambda)``; ITTC 7.5-02-07-02.1)."""
    lam = getattr(spec, "model_scale", None)
    if not lam:
        return dict(SEA)
    from steerlab.environment.sea_state import sea_state

    row = sea_state(SEA["sea_state"], "environment.wave.sea_state")
    d = {k: v for k, v in SEA.items() if k != "sea_state"}
    return {**d, "Hs": row.Hs / lam, "Tp": row.Tp / math.sqrt(lam)}


def _default_gear() -> dict:
    from steerlab.sim.scenario import GearConfig

    return GearConfig().model_dump()


GEAR = _default_gear()
"""``[gear]``: the scenario's default steering gear (degrees at the edge)."""


def ship_gear(spec) -> dict:
    """``[gear]`` of a case on ship ``spec``: :data:`GEAR` with the ship's own defaults where it
    has them (a scale model's Froude-scaled rate and lag:
    :meth:`~steerlab.ships.registry.ShipSpec.default_gear`), as a scenario that gives no
    ``[gear]`` gets."""
    from steerlab.sim.scenario import ship_gear_defaults

    return {**GEAR, **ship_gear_defaults(spec.name)}


@dataclass(frozen=True)
class Case:
    """One cell: ship id, controller type, operating point and sea (``"calm"`` or ``"sea5"``)."""

    ship: str
    controller: str
    point: OperatingPoint
    sea: str

    @property
    def key(self) -> tuple:
        """``(ship, controller, point label, sea)``."""
        return (self.ship, self.controller, self.point.label, self.sea)


def point_nomoto(spec, point: OperatingPoint) -> tuple[float, float]:
    """First-order Nomoto ``(K [1/s], T [s])`` of ``spec`` at ``point`` (NaN if it has none)."""
    try:
        options = spec.options({"rpm": point.rpm} if point.rpm is not None else None)
        return tuple(float(x) for x in spec.nomoto(point.speed, options))
    except Exception:  # noqa: BLE001 - any ship without a model there: the default time scale
        return math.nan, math.nan


def time_scale(spec, point: OperatingPoint, gear: dict | None = None) -> float:
    """``t_s = 2 pi / omega_g`` [s] of the ship at the point with the gear (module docstring)."""
    g = ship_gear(spec) if gear is None else gear
    K, T = point_nomoto(spec, point)
    b = abs(K / T) if (math.isfinite(K) and math.isfinite(T) and T != 0.0) else math.nan
    if not (math.isfinite(b) and b > 0.0):
        return DEFAULT_TIME_SCALE
    turn = math.radians(CHANGE_DEG)
    w = min(math.sqrt(math.radians(g["delta_max_deg"]) * b / turn),
            (math.radians(g["rate_max_deg_s"]) * b / turn) ** (1.0 / 3.0))
    return 2.0 * math.pi / w


def run_length(t_s: float) -> tuple[float, float]:
    """``(duration [s], hold [s])`` of a run with time scale ``t_s`` (module docstring)."""
    after = min(max(RUN_SCALES * t_s, MIN_AFTER), MAX_AFTER)
    hold = min(max(HOLD_SCALES * t_s, MIN_HOLD), 0.5 * after)
    return T_CHANGE + after, hold


def controller_type(law: str, sea: str) -> str:
    """The controller type a case runs: the law itself in calm water; in a sea, the law behind
    the wave filter (``law + "+wf"``, its filter designed for the sample time:
    :func:`steerlab.control.wave_filtered.design_filter`), as ``steerlab run`` advises
    (:func:`steerlab.sim.sanity.unfiltered_in_waves`); ``asa`` has its own filter."""
    from steerlab.control.wave_filtered import NOT_WRAPPED, SUFFIX

    return law if sea == CALM or law in NOT_WRAPPED or law.endswith(SUFFIX) else law + SUFFIX


def scenario_dict(case: Case, duration: float) -> dict:
    """The scenario of ``case`` as a plain dict (the TOML shape; degrees and knots)."""
    from steerlab.ships.registry import get_ship

    spec = get_ship(case.ship)
    ship = {"model": case.ship, "speed_kn": case.point.speed_kn}
    if case.point.rpm is not None:
        ship["options"] = {"rpm": case.point.rpm}
    d = {"name": f"conformance-{case.ship}-{case.controller}-{case.point.label}-{case.sea}",
         "seed": SEA_SEED, "dt": DT, "duration": duration, "ship": ship, "gear": ship_gear(spec),
         "controller": {"type": controller_type(case.controller, case.sea)},
         "guidance": {"psi0_deg": 0.0, "changes": [{"t": T_CHANGE, "psi_deg": CHANGE_DEG}]}}
    if case.sea == SEA5:
        d["environment"] = {"wave": sea_block(spec)}
    return d
