"""Plain-text tables of trial metrics for the terminal (and the rows of the HTML report)."""

from __future__ import annotations

import math


def _v(x, fmt="{:.4g}"):
    if x is None:
        return "-"
    if isinstance(x, bool):
        return "yes" if x else "no"
    if isinstance(x, float):
        return "n/a" if not math.isfinite(x) else fmt.format(x)
    return str(x)


def _first_of(values, n: int = 6) -> str:
    """The first ``n`` values (2 decimals) and how many there are in all."""
    text = ", ".join(_v(o, "{:.2f}") for o in values[:n])
    return text + (f", ... ({len(values)} in all; --json lists every one)" if len(values) > n else "")


def turning_rows(m: dict) -> list[tuple[str, str, str]]:
    rows = [("rudder", _v(m["rudder_deg"]) + " " + m["direction"], "deg")]
    for k, lab in (("advance", "advance"), ("transfer", "transfer"), ("tactical_diameter", "tactical diameter"),
                   ("steady_diameter", "steady turning diameter")):
        rows.append((lab, f"{_v(m[k + '_m'])} m = {_v(m[k + '_L'])} L", ""))
    rows += [("steady rate of turn", _v(m["steady_rate_of_turn_deg_s"]), "deg/s"),
             ("steady speed", f"{_v(m['steady_speed_kn'])} kn ({_v(100 * m['speed_ratio'], '{:.1f}')} %)", ""),
             ("steady drift angle", _v(m["steady_drift_angle_deg"]), "deg"),
             ("time to 90 / 180 deg", f"{_v(m['time_to_90deg_s'])} / {_v(m['time_to_180deg_s'])}", "s"),
             ("steady reached", _v(m["steady"]), "")]
    return rows


def zigzag_rows(m: dict) -> list[tuple[str, str, str]]:
    return [("zig-zag", f"{_v(m['rudder_deg'])}/{_v(m['heading_deg'])}, first rudder {m['first_rudder']}", "deg"),
            ("first overshoot", _v(m["first_overshoot_deg"]), "deg"),
            ("second overshoot", _v(m["second_overshoot_deg"]), "deg"),
            ("overshoots", _first_of(m["overshoot_angles_deg"]), "deg"),
            ("time to second execute", _v(m["time_to_second_execute_s"]), "s"),
            ("period (first cycle)", _v(m["period_s"]), "s"),
            ("initial turning distance", _v(m["initial_turning_distance_L"]), "L"),
            ("L/V", _v(m["L_over_V_s"]), "s")]


def _polynomial(terms: list[tuple[float, str, str]]) -> str:
    """``a + b r - c r^2 ...`` from ``(coefficient, format, power)`` terms: each sign written once
    (``- 9.319 r``, not ``+ -9.319 r``)."""
    out = ""
    for i, (value, fmt, power) in enumerate(terms):
        text = format(abs(value), fmt) + power
        if i == 0:
            out = ("-" if value < 0 else "") + text
        else:
            out += (" - " if value < 0 else " + ") + text
    return out


def spiral_rows(m: dict) -> list[tuple[str, str, str]]:
    rows = [("verdict", m["verdict"], ""),
            ("reversed-spiral slope at r=0", _v(m["slope_at_zero_deg_per_deg_s"]), "deg/(deg/s)"),
            ("loop width", _v(m["loop_width_deg"]), "deg"),
            ("loop height", _v(m["loop_height_deg_s"]), "deg/s"),
            ("loop width, direct spiral", " .. ".join(_v(x) for x in m["loop_width_direct_bounds_deg"]), "deg")]
    c = m["cubic_deg"]
    rows.append(("cubic delta = H(r)", _polynomial([(c["c0"], ".3g", ""), (c["c1"], ".4g", " r"),
                                                   (c["c2"], ".3g", " r^2"), (c["c3"], ".4g", " r^3")]),
                 "deg, r in deg/s"))
    rows.append(("all steps steady", _v(m["all_steady"]), ""))
    return rows


def pullout_rows(m: dict) -> list[tuple[str, str, str]]:
    rows = [("rudder before release", _v(m["rudder_deg"]), "deg")]
    for side in ("starboard", "port"):
        s = m[side]
        rows.append((f"{side}: rate before / residual",
                     f"{_v(s['steady_rate_before_deg_s'])} / {_v(s['residual_rate_deg_s'])}", "deg/s"))
    rows += [("verdict", m["verdict"], ""), ("loop height", _v(m["loop_height_deg_s"]), "deg/s")]
    return rows


def imo_rows(criteria: list[dict]) -> list[tuple[str, str, str]]:
    from steerlab.trials.imo_criteria import verdict_text

    out = []
    for c in criteria:
        verdict = verdict_text(c)
        out.append((c["criterion"], f"{_v(c['value'])} <= {_v(c['limit'])} {c['unit']}: {verdict}", c["source"]))
    return out


def format_table(rows, title: str = "", width: int | None = None) -> str:
    """Rows ``(quantity, value, unit)`` as aligned text that fits ``width`` columns.

    ``width`` defaults to the terminal's (100 when not a terminal); a value too long for its
    column (e.g. the list of every zig-zag overshoot) is wrapped onto continuation lines.
    """
    import shutil
    import textwrap

    if width is None:
        width = shutil.get_terminal_size((100, 24)).columns
    w0 = max(len(r[0]) for r in rows)
    w2 = min(max(len(r[2]) for r in rows), 20)
    w1 = min(max(len(r[1]) for r in rows), max(20, width - w0 - w2 - 4))
    w2 = max(10, width - w0 - w1 - 4)
    lines = [title] if title else []
    for a, b, c in rows:
        vals = textwrap.wrap(b, w1, break_on_hyphens=False) or [""]
        units = textwrap.wrap(c, w2, break_on_hyphens=False) or [""]
        for i in range(max(len(vals), len(units))):
            v = vals[i] if i < len(vals) else ""
            u = units[i] if i < len(units) else ""
            lines.append(f"{a if i == 0 else '':<{w0}}  {v:<{w1}}  {u}".rstrip())
    return "\n".join(lines)


ROWS = {"turning": turning_rows, "zigzag": zigzag_rows, "spiral": spiral_rows, "pullout": pullout_rows}
