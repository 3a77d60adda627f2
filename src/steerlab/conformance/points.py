r"""Where the conformance matrix runs a ship: its design speed and the two ends of its range.

Every catalogue ship is tried at up to three operating points (:func:`operating_points`):

* ``design``: the ship's design speed, :attr:`ShipSpec.design_speed` where the ship has one;
  else (:func:`design_speed`) the middle of a finite validity range ``speed_range``, else
  16 kn (the Esso tanker's service speed, Zwierzewicz et al. 2021, Table 1, and the scenario
  default up to 0.1.0), clipped into the range;
* ``low`` and ``high``: the ends of ``speed_range``. An open end is clipped to something a
  ship is steered at: a lower end of 0 to half the design speed (:data:`OPEN_LOW`), an
  infinite upper end to 1.25 times the design speed (:data:`OPEN_HIGH`: a 25 % overspeed);
  both also to the scenario's 0.01-40 kn. A closed end is used as tabulated, however slow
  (the B-481's 0.972 kn: a ship the matrix must then steer, or refuse, at that speed).

Catalogue entries indexed by propeller rate (the Capella, van Amerongen 1982 Table 2.4) have
no speed range: their points are the tabulated rpm range's ends and its middle row, given as
``[ship.options] rpm``, at the design speed. A ship tabulated at one speed has one point;
points that coincide are kept once (the design point wins).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Optional

from steerlab.units import KNOT

DEFAULT_SPEED_KN = 16.0
"""Design speed [kn] of a ship without one and without a finite speed range."""
OPEN_LOW = 0.5
"""An open lower end of the speed range (0) is taken as this fraction of the design speed."""
OPEN_HIGH = 1.25
"""An infinite upper end of the speed range is taken as this multiple of the design speed."""
SCENARIO_SPEED_KN = (0.01, 40.0)
"""The speeds a scenario accepts [kn] (``[ship] speed_kn``)."""


@dataclass(frozen=True)
class OperatingPoint:
    """One operating point of a ship in the matrix.

    Attributes
    ----------
    label : str
        ``"design"``, ``"low"`` or ``"high"``.
    speed : float
        Speed [m/s] (the scenario's ``speed_kn`` is ``speed / KNOT``).
    rpm : float or None
        ``[ship.options] rpm`` [rev/min] of a catalogue entry indexed by propeller rate.
    how : str
        How the point was chosen (for the table's notes).
    """

    label: str
    speed: float
    rpm: Optional[float] = None
    how: str = field(default="", compare=False)

    @property
    def speed_kn(self) -> float:
        """Speed [kn]."""
        return self.speed / KNOT

    def describe(self) -> str:
        """``"16 kn"`` or ``"160 rpm"``: the point as the table prints it."""
        return f"{self.rpm:g} rpm" if self.rpm is not None else f"{self.speed_kn:.3g} kn"


def _clip_kn(v: float) -> float:
    lo, hi = SCENARIO_SPEED_KN
    return min(max(v, lo * KNOT), hi * KNOT)


def design_speed(spec) -> tuple[float, str]:
    """``(speed [m/s], how)``: the ship's design speed, clipped into its validity range.

    ``spec.design_speed`` where the ship has one (a property of :class:`ShipSpec` in
    versions that carry it); else the middle of a finite ``speed_range``; else
    :data:`DEFAULT_SPEED_KN`. NaN, zero or negative values fall through to the next rule.
    """
    lo, hi = spec.speed_range
    v = getattr(spec, "design_speed", None)
    if callable(v):
        v = v()
    how = "ShipSpec.design_speed"
    if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0.0):
        if math.isfinite(hi) and hi > 0.0:
            v, how = 0.5 * (lo + hi), "middle of the speed range"
        else:
            v, how = DEFAULT_SPEED_KN * KNOT, f"{DEFAULT_SPEED_KN:g} kn (no speed range)"
    v = min(max(float(v), lo), hi) if hi >= lo else float(v)
    return _clip_kn(v), how


def _rpm_range(spec) -> Optional[tuple[float, float, float]]:
    """``(low, nominal, high)`` [rev/min] of a catalogue entry indexed by propeller rate, else None."""
    cat = getattr(spec, "catalogue", None)
    if not cat or "rpm_range" not in cat or spec.options_model is None:
        return None
    lo, hi = (float(x) for x in cat["rpm_range"])
    nominal = float(spec.options_model().rpm)
    return lo, nominal, hi


def operating_points(spec) -> list[OperatingPoint]:
    """The ship's operating points: design, low and high (see the module docstring)."""
    vd, how = design_speed(spec)
    rpms = _rpm_range(spec)
    if rpms is not None:
        lo, nom, hi = rpms
        pts = [OperatingPoint("design", vd, nom, f"middle row of the rpm table; speed: {how}"),
               OperatingPoint("low", vd, lo, "lowest tabulated rpm"),
               OperatingPoint("high", vd, hi, "highest tabulated rpm")]
    else:
        lo, hi = spec.speed_range
        low = (_clip_kn(lo), "lowest speed of the range") if lo > 0.0 else \
            (_clip_kn(OPEN_LOW * vd), f"open lower end: {OPEN_LOW:g} x design speed")
        high = (_clip_kn(hi), "highest speed of the range") if math.isfinite(hi) else \
            (_clip_kn(OPEN_HIGH * vd), f"open upper end: {OPEN_HIGH:g} x design speed")
        pts = [OperatingPoint("design", vd, None, how), OperatingPoint("low", low[0], None, low[1]),
               OperatingPoint("high", high[0], None, high[1])]
    out: list[OperatingPoint] = []
    for p in pts:
        if not any(abs(q.speed - p.speed) <= 1e-9 * max(q.speed, 1.0) and q.rpm == p.rpm for q in out):
            out.append(p)
    return out
