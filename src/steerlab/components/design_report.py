r"""The design report of a controller: design model, rule, gains, linearised-loop margins.

What ``steerlab design SCENARIO.toml`` and :meth:`steerlab.components.controller.Controller.describe`
show (docs/design-report.md):

* **design model** (:func:`steerlab.control.design_model.design_model`): first-order Nomoto
  ``K`` [1/s] and ``T`` [s] with their signs (``T < 0``: course-unstable), the rudder
  efficiency ``b2`` [1/s^2], the second-order reading ``T1, T2, T3`` [s] where the ship has a
  sway-yaw linearisation, the speed [m/s] and the gear's limit [rad], rate [rad/s] and servo
  lag ``T_sg`` [s]; and the shared bandwidth rule's ``omega_n`` [rad/s]
  (:func:`steerlab.control.design_model.bandwidth`);
* **rule**: the law's ``ControllerSpec.design_rule`` (``"no stated rule"`` when empty);
* **gains**: the packed parameter record by field name with units (``ControllerSpec.params``);
* **loop**: the law's kernel linearised and closed with the design model (its second-order
  reading where the ship has one: a first-order model can misplace the phase at crossover,
  e.g. the Esso tanker's ``K/T`` is 0.4 of its ``b2``)
  (:mod:`steerlab.components.loop_analysis`): gain, phase and delay margins, crossover and
  closed-loop bandwidth, and one warning per margin under its floor.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any, Optional

import numpy as np

from steerlab.errors import InputError
from steerlab.units import ms_to_knots

if TYPE_CHECKING:
    from steerlab.components.controller import Controller

#: what the report says of a law whose spec states no design rule
NO_RULE = "no stated rule"


def _second_order(ctx) -> dict:
    """``T1, T2, T3`` [s] of the ship's sway-yaw linearisation at the design speed (NaN: none)."""
    ship = ctx.ship
    nan = {"T1": math.nan, "T2": math.nan, "T3": math.nan}
    lin = getattr(ship, "linearise", None)
    if lin is None or not math.isfinite(ctx.speed):
        return nan
    try:
        from steerlab.ships.linear_analysis import nomoto_from_linear

        A1, B1 = lin(ctx.speed, ctx.ship_options) if ship.options_model is not None else lin(ctx.speed)
        n = nomoto_from_linear(A1, B1)
        return {k: float(n.get(k, math.nan)) for k in nan}
    except Exception:  # noqa: BLE001 - a ship whose linearisation has no second-order reading
        return nan


def model_section(ctrl: Controller) -> tuple[Any, dict]:
    """``(DesignModel or None, JSON-able dict)`` of the controller's design context."""
    from steerlab.control.design_model import bandwidth, design_model

    try:
        m = design_model(ctrl.context)
    except InputError as err:
        return None, {"available": False, "reason": f"{err.field}: {err.message}"}
    d = {"available": True, "K": m.K, "T": m.T, "b2": m.b2, "a": m.a, "b": m.b,
         "course_unstable": m.unstable, "speed": m.speed, "delta_max": m.delta_max,
         "rate_max": m.rate_max, "T_sg": m.T_sg, "source": m.source}
    second = {"T1": m.T1, "T2": m.T2, "T3": m.T3}
    if all(math.isnan(v) for v in second.values()):
        second = _second_order(ctrl.context)
    d.update(second)
    try:
        d["omega_n"] = bandwidth(m, law=ctrl.type)
    except InputError as err:
        d["omega_n"] = math.nan
        d["omega_n_refused"] = f"{err.field}: {err.message}"
    return m, d


def gains_section(ctrl: Controller) -> list[dict]:
    """The packed parameter record by field name: ``{"name", "value", "unit", "doc"}`` each."""
    layout: Any = ctrl.spec.params
    p = ctrl.params
    if layout is None or getattr(layout, "size", None) != p.shape[0]:
        return [{"name": f"p[{i}]", "value": float(v), "unit": "", "doc": ""} for i, v in enumerate(p)]
    return [{"name": f.name, "value": float(v), "unit": f.unit, "doc": f.doc}
            for f, v in zip(layout.fields, p)]


def design_report(ctrl: Controller) -> dict:
    """The design report of ``ctrl`` as a JSON-able dict (SI; see the module docstring).

    Keys: ``controller``, ``description``, ``source``, ``sample_time``, ``design_model``,
    ``design_rule``, ``gains``, ``loop`` (:func:`steerlab.components.loop_analysis.loop_margins`,
    or ``{"available": False, "reason": ...}``) and ``warnings`` (one line each).
    """
    from steerlab.components.loop_analysis import FLOORS, loop_margins

    m, model = model_section(ctrl)
    out: dict[str, Any] = {"controller": ctrl.type, "description": ctrl.spec.description, "source": ctrl.spec.source,
           "sample_time": ctrl.sample_time, "design_model": model,
           "design_rule": ctrl.spec.design_rule or NO_RULE, "gains": gains_section(ctrl)}
    if m is None:
        out["loop"] = {"available": False, "reason": "no design model: " + model["reason"]}
    else:
        reading = {k: model[k] for k in ("T1", "T2", "T3")}
        second: Optional[dict] = reading if all(math.isfinite(v) and v != 0.0 for v in reading.values()) else None
        try:
            loop = loop_margins(ctrl, m, second)
            loop["available"] = True
            loop["floors"] = dict(FLOORS)
            loop["plant"] = ("second-order Nomoto (K, T1, T2, T3)" if second else "first-order Nomoto (K, T)") \
                + " + servo lag T_sg, zero-order hold at the sample time"
        except InputError as err:
            loop = {"available": False, "reason": f"{err.field}: {err.message}"}
        out["loop"] = loop
    out["warnings"] = list(out["loop"].get("warnings", []))
    return out


def _fmt(v: float, spec: str = ".4g") -> str:
    return "n/a" if v is None or (isinstance(v, float) and math.isnan(v)) else format(v, spec)


def format_report(d: dict) -> str:
    """The text form of :func:`design_report` (degrees and dB at this edge)."""
    lines = [f"controller {d['controller']}: {d['description']}", f"  source: {d['source']}",
             f"  sample time {d['sample_time']:g} s", "design model"]
    m = d["design_model"]
    if not m["available"]:
        lines.append(f"  n/a ({m['reason']})")
    else:
        stab = "course-UNSTABLE: T < 0" if m["course_unstable"] else "course-stable"
        lines.append(f"  Nomoto K = {m['K']:.4g} 1/s, T = {m['T']:.4g} s ({stab}); b2 = {m['b2']:.4g} 1/s^2 "
                     f"[{m['source']}]")
        if not all(math.isnan(m[k]) for k in ("T1", "T2", "T3")):
            lines.append(f"  second order: T1 = {_fmt(m['T1'])} s, T2 = {_fmt(m['T2'])} s, T3 = {_fmt(m['T3'])} s")
        speed = m["speed"]
        lines.append("  speed " + ("n/a" if math.isnan(speed) else f"{speed:.4g} m/s ({ms_to_knots(speed):.4g} kn)")
                     + f"; gear {math.degrees(m['delta_max']):.3g} deg, {math.degrees(m['rate_max']):.3g} deg/s, "
                       f"T_sg {m['T_sg']:.3g} s")
        if "omega_n_refused" in m:
            lines.append(f"  bandwidth rule: refused ({m['omega_n_refused']})")
        else:
            lines.append(f"  bandwidth rule: omega_n = {m['omega_n']:.4g} rad/s")
    lines.append(f"design rule: {d['design_rule']}")
    lines.append("gains")
    width = max((len(g["name"]) for g in d["gains"]), default=0)
    for g in d["gains"]:
        unit = f" {g['unit']}" if g["unit"] and g["unit"] != "-" else ""
        lines.append(f"  {g['name']:<{width}} = {g['value']:.6g}{unit}")
    lines.append("linearised loop (broken at the rudder order)")
    lp = d["loop"]
    if not lp["available"]:
        lines.append(f"  n/a ({lp['reason']})")
    else:
        gm = lp["gain_margin"]
        gm_s = "inf" if math.isinf(gm) else f"{gm:.3g} ({lp['gain_margin_db']:.1f} dB)"
        if lp["gain_margin_low"] > 0.0:
            gm_s += f", down to {lp['gain_margin_low']:.3g} ({lp['gain_margin_low_db']:.1f} dB)"
        lines.append(f"  closed loop {'stable' if lp['closed_loop_stable'] else 'UNSTABLE'}; "
                     f"gain margin {gm_s}, phase margin {_fmt(lp['phase_margin_deg'], '.3g')} deg, "
                     f"delay margin {_fmt(lp['delay_margin_s'], '.3g')} s")
        lines.append(f"  crossover {_fmt(lp['crossover_rad_s'])} rad/s, closed-loop bandwidth "
                     f"(psi_ref -> psi, -3 dB) {_fmt(lp['bandwidth_rad_s'])} rad/s")
        if lp.get("states_held"):
            lines.append(f"  the law also reads {', '.join(lp['states_held'])}: held at straight running "
                         "(the design model has no such state)")
        f = lp["floors"]
        lines.append(f"  floors: gain margin {f['gain_margin']:g}, phase margin {f['phase_margin_deg']:g} deg, "
                     f"delay margin {f['delay_margin_s']:g} s; plant: {lp['plant']}")
    for w in d["warnings"]:
        lines.append(f"WARNING: {w}")
    return "\n".join(lines)


def json_ready(d: dict) -> dict:
    """``d`` with non-finite floats as strings (``"inf"``, ``"nan"``) so strict JSON can hold it."""
    def fix(v):
        if isinstance(v, dict):
            return {k: fix(x) for k, x in v.items()}
        if isinstance(v, (list, tuple)):
            return [fix(x) for x in v]
        if isinstance(v, (float, np.floating)) and not math.isfinite(v):
            return str(float(v))
        return v
    return fix(d)
