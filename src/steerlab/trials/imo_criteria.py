r"""IMO manoeuvrability criteria (Resolution MSC.137(76), 2002, "Standards for ship manoeuvrability").

Zig-zag limits as printed in the LOS + ADRC automatic-berthing paper (2019; the Kosoko
tank experiment; ``papers/los-adrc-automatic-berthing-2019``), eq (32), with ``L`` the ship length [m] and ``V`` the speed [m/s]::

    first overshoot of the 10/10 zig-zag     < 10 deg                  L/V < 10 s
                                             < (5 + (L/V)/2) deg       10 s <= L/V < 30 s
                                             < 20 deg                  L/V >= 30 s
    second overshoot of the 10/10 zig-zag    < 25 deg                  L/V < 10 s
                                             < (17.5 + 0.75 L/V) deg   10 s <= L/V < 30 s
                                             < 40 deg                  L/V >= 30 s

Both are continuous: 5 + 10/2 = 10 and 5 + 30/2 = 20; 17.5 + 7.5 = 25 and 17.5 + 22.5 = 40.

The other criteria are from MSC.137(76) Sec. 5.3 itself (not in the paper):

* turning ability (5.3.1): with the maximum rudder angle, advance <= 4.5 L and tactical
  diameter <= 5 L;
* initial turning ability (5.3.2): with 10 deg rudder, the ship has travelled at most 2.5 L
  when the heading has changed 10 deg (measured on the 10/10 zig-zag);
* yaw checking (5.3.3): the 10/10 overshoots above; the first overshoot of the 20/20 zig-zag
  <= 25 deg;
* stopping ability (5.3.4, track reach <= 15 L): not assessed (steerlab's ship models have
  no astern propulsion).

The paper prints strict inequalities, the resolution "should not exceed": a trial passes when
its value is at most the limit. The standards apply to ships of 100 m and more, at full load
and even keel, at a test speed of at least 90 % of the speed at 85 % MCR; steerlab applies
them to whatever ship and speed is asked and reports the ship length so a reader can judge.
"""

from __future__ import annotations

import math

SOURCE_EQ32 = "LOS+ADRC berthing paper (2019) eq (32); IMO MSC.137(76) 5.3.3.1"
SOURCE_MSC137 = "IMO MSC.137(76) Sec. 5.3"

ADVANCE_LIMIT_L = 4.5
TACTICAL_DIAMETER_LIMIT_L = 5.0
INITIAL_TURNING_LIMIT_L = 2.5
FIRST_OVERSHOOT_20_LIMIT_DEG = 25.0


def first_overshoot_10_limit_deg(L_over_V: float) -> float:
    """Limit of the first overshoot angle of the 10/10 zig-zag [deg], eq (32); ``L/V`` in s."""
    if not (L_over_V >= 0.0 and math.isfinite(L_over_V)):
        raise ValueError(f"L/V must be a finite number >= 0 s, got {L_over_V}")
    if L_over_V < 10.0:
        return 10.0
    if L_over_V < 30.0:
        return 5.0 + 0.5 * L_over_V
    return 20.0


def second_overshoot_10_limit_deg(L_over_V: float) -> float:
    """Limit of the second overshoot angle of the 10/10 zig-zag [deg], eq (32); ``L/V`` in s."""
    if not (L_over_V >= 0.0 and math.isfinite(L_over_V)):
        raise ValueError(f"L/V must be a finite number >= 0 s, got {L_over_V}")
    if L_over_V < 10.0:
        return 25.0
    if L_over_V < 30.0:
        return 17.5 + 0.75 * L_over_V
    return 40.0


def model_scale_note(scale: float) -> str:
    """What a verdict on a ``1 : scale`` model means (the criteria are for full-size ships)."""
    return (f"model scale 1:{scale:g}: Froude-scaled, indicative only, not a full-scale verdict "
            f"(MSC.137(76) applies to ships; model tests carry scale effects)")


def mark_model_scale(rows: list[dict], cond) -> list[dict]:
    """Add ``model_scale`` and ``scale_note`` to each criterion of a trial on a scale model."""
    from steerlab.ships.registry import get_ship

    scale = get_ship(cond.ship).model_scale
    if scale is None:
        return rows
    return [{**r, "model_scale": scale, "scale_note": model_scale_note(scale)} for r in rows]


def verdict_text(c: dict, overall: bool | None = None) -> str:
    """``PASS``, ``FAIL`` or ``n/a`` of a criterion row, with ``(model scale 1:N, indicative)``
    when the trial ran on a scale model (never a bare PASS/FAIL for a model)."""
    v = {True: "PASS", False: "FAIL", None: "n/a"}[c["pass"] if overall is None else overall]
    scale = c.get("model_scale")
    return v if scale is None or v == "n/a" else f"{v} (model scale 1:{scale:g}, indicative)"


def criterion(name: str, value: float, limit: float, unit: str, source: str) -> dict:
    """One pass/fail row; ``pass`` is None when the value could not be measured."""
    ok = None if (value is None or not math.isfinite(value)) else bool(value <= limit)
    return {"criterion": name, "value": value, "limit": limit, "unit": unit, "pass": ok, "source": source}


def zigzag_criteria(rudder_deg: float, heading_deg: float, overshoots_deg: list, L_over_V: float,
                    initial_turning_L: float | None = None) -> list[dict]:
    """The IMO rows that apply to a ``rudder_deg``/``heading_deg`` zig-zag (empty for other sizes)."""
    o1 = overshoots_deg[0] if len(overshoots_deg) > 0 else math.nan
    o2 = overshoots_deg[1] if len(overshoots_deg) > 1 else math.nan
    rows = []
    if abs(rudder_deg) == 10.0 and heading_deg == 10.0:
        rows.append(criterion("10/10 first overshoot", o1, first_overshoot_10_limit_deg(L_over_V), "deg",
                              SOURCE_EQ32))
        rows.append(criterion("10/10 second overshoot", o2, second_overshoot_10_limit_deg(L_over_V), "deg",
                              SOURCE_EQ32))
        if initial_turning_L is not None:
            rows.append(criterion("initial turning: distance to 10 deg heading change", initial_turning_L,
                                  INITIAL_TURNING_LIMIT_L, "L", SOURCE_MSC137 + ".2"))
    elif abs(rudder_deg) == 20.0 and heading_deg == 20.0:
        rows.append(criterion("20/20 first overshoot", o1, FIRST_OVERSHOOT_20_LIMIT_DEG, "deg",
                              SOURCE_MSC137 + ".3.2"))
    return rows


def turning_criteria(advance_m: float, tactical_m: float, L: float, rudder_deg: float, cond) -> list[dict]:
    """Turning-ability rows (MSC.137(76) 5.3.1) when the rudder is at the gear's limit, else empty."""
    from steerlab.trials.runner import gear_limit_deg

    if abs(abs(rudder_deg) - gear_limit_deg(cond)) > 1e-9:
        return []
    return [criterion("turning: advance", advance_m / L, ADVANCE_LIMIT_L, "L", SOURCE_MSC137 + ".1"),
            criterion("turning: tactical diameter", tactical_m / L, TACTICAL_DIAMETER_LIMIT_L, "L",
                      SOURCE_MSC137 + ".1")]
