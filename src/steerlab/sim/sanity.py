r"""Scenario checks beyond field ranges: refusals of the impossible, warnings of the likely mistake.

Field ranges (pydantic) cannot see combinations or units typed wrong. Here:

* :func:`check_scenario` refuses (``InputError``) what cannot be meant: a course change after
  the end of the run (``guidance.changes[i].t > duration``);
* :func:`scenario_warnings` lists what is allowed but probably a mistake, each
  ``"field: message"``; the CLI prints them as ``steerlab: warning: ...`` lines and writes
  them into the run's ``metrics.json`` (``warnings``):

  - the speed outside the ship's validity range (``ShipSpec.speed_range``; catalogue tables
    already refuse): the model is extrapolated and may diverge (which the finite-state
    check of :mod:`steerlab.sim.divergence` then reports);
  - a rudder limit below :data:`MIN_RUDDER_DEG` degrees or a rudder rate below
    :data:`MIN_RUDDER_RATE_DEG_S` deg/s in a degree field: "did you type radians?"
    (35 deg = 0.61 rad; 2.33 deg/s = 0.041 rad/s);
  - spectrum waves on a ship without beam and block coefficient: the waves' yaw gain is a
    typical hull's of its length (:mod:`steerlab.environment.typical_hull`).
"""

from __future__ import annotations

import math

from steerlab.errors import InputError
from steerlab.units import KNOT

MIN_RUDDER_DEG = 2.0          #: smaller rudder limits [deg] are probably radians
MIN_RUDDER_RATE_DEG_S = 0.2   #: smaller rudder rates [deg/s] are probably radians per second


def check_scenario(s) -> None:
    """Refuse a course change after the end of the run (``InputError`` naming it)."""
    for i, ch in enumerate(s.guidance.changes):
        if ch.t > s.duration:
            raise InputError(f"guidance.changes[{i}].t", f"{ch.t:g} s is after the end of the run "
                                                         f"(duration {s.duration:g} s); allowed [0, {s.duration:g}]")


def scenario_warnings(s) -> list[str]:
    """``"field: message"`` for each likely mistake in scenario ``s`` (see the module docstring)."""
    from steerlab.ships.registry import get_ship

    out = []
    ship = get_ship(s.ship.model)
    lo, hi = ship.speed_range
    v = s.ship.speed()
    if not (lo <= v <= hi):
        out.append(f"ship.speed_kn: {s.ship.speed_in_kn():g} kn is outside the validity range of {ship.name!r} "
                   f"({lo / KNOT:.3g}-{hi / KNOT:.3g} kn); the model is extrapolated")
    limits = [("gear.delta_max_deg", s.gear.delta_max_deg)]
    u_max = getattr(s.controller, "u_max_deg", None)
    if u_max is not None:
        limits.append(("controller.u_max_deg", u_max))
    for field, val in limits:
        if val < MIN_RUDDER_DEG:
            out.append(f"{field}: a rudder limit of {val:g} deg is below {MIN_RUDDER_DEG:g} deg; did you type "
                       f"radians? ({val:g} rad = {val * 57.29577951308232:.3g} deg)")
    if s.gear.rate_max_deg_s < MIN_RUDDER_RATE_DEG_S:
        val = s.gear.rate_max_deg_s
        out.append(f"gear.rate_max_deg_s: a rudder rate of {val:g} deg/s is below {MIN_RUDDER_RATE_DEG_S:g} deg/s; "
                   f"did you type radians? ({val:g} rad/s = {val * 57.29577951308232:.3g} deg/s)")
    wave = getattr(s.environment, "wave", None)
    if wave is not None and wave.model == "spectrum" and wave.yaw_accel_per_slope is None:
        from steerlab.environment.typical_hull import has_hull_data, typical_hull_warning

        L = ship.dims[1]
        if not has_hull_data(ship.dims) and math.isfinite(L) and L > 0.0:
            out.append(typical_hull_warning(ship.name, L))
    if wave is not None and wave.model == "spectrum":
        hint = unfiltered_in_waves(s.controller.type)
        if hint:
            out.append(hint)
    return out


def unfiltered_in_waves(controller_type: str) -> str:
    """The one-line hint for a law that steers on the raw heading in a wave spectrum, or ``""``.

    Without the wave filter a law answers the first-order wave yaw, which no rudder can take
    out: in JONSWAP sea state 5 every built-in law worked its rudder 12-18 times a minute
    (issue 30's conformance matrix: 15 of 836 cases within six reversals a minute), for the same
    mean heading. ``asa`` has the filter built in; the ``+wf`` variants put it in front.
    """
    from steerlab.control.wave_filtered import NOT_WRAPPED, SUFFIX

    if controller_type.endswith(SUFFIX) or controller_type in NOT_WRAPPED:
        return ""
    return f"controller.type: {controller_type!r} chases the wave yaw; {controller_type + SUFFIX!r} filters it out"
