"""The conformance matrix as Markdown (docs/conformance.md) and as a plain-text summary.

:func:`markdown` writes: the totals against the target, a table of counts per law, the
ship x law matrix (one symbol per case: calm water at the low, design and high points, then
sea state 5 at the same points), the refusals grouped by law and field with one message each,
and every failure with its reason.
"""

from __future__ import annotations

from collections import defaultdict

from steerlab.conformance.cases import CALM, SEA5
from steerlab.conformance.judge import FAILS, REFUSED, STEERS
from steerlab.conformance.matrix import TARGET, Matrix

SYMBOLS = {STEERS: "✓", REFUSED: "R", FAILS: "✗"}
"""One character per verdict in the ship x law table."""
POINT_ORDER = ("low", "design", "high")


def _pct(x: float) -> str:
    return f"{100.0 * x:.1f} %"


def _cell(outcomes) -> str:
    by = {(o.sea, o.point): o.verdict for o in outcomes}
    parts = []
    for sea in (CALM, SEA5):
        s = "".join(SYMBOLS[by[(sea, p)]] for p in POINT_ORDER if (sea, p) in by)
        if s:
            parts.append(s)
    return " ".join(parts)


def _md_escape(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ")


def summary_rows(m: Matrix) -> list[tuple]:
    """``(law, steers, refused, fails, steers %)`` rows, then ``all``."""
    rows = []
    for law, c in m.counts("controller").items():
        n = sum(c.values())
        rows.append((law, c[STEERS], c[REFUSED], c[FAILS], _pct(c[STEERS] / max(n, 1))))
    t = m.total()
    rows.append(("all", t[STEERS], t[REFUSED], t[FAILS], _pct(m.fraction_steers)))
    return rows


def text_summary(m: Matrix) -> str:
    """The counts per law as a plain-text table (the CLI's output)."""
    from steerlab.text_table import render_table

    table = render_table(("law", "steers", "refused", "fails", "steers %"), summary_rows(m), align="lrrrr")
    t = m.total()
    n = len(m.outcomes)
    return (f"{table}\n{n} cases: {t[STEERS]} steer ({_pct(m.fraction_steers)}; target >= {_pct(TARGET)}), "
            f"{t[REFUSED]} refused, {t[FAILS]} fail")


def markdown(m: Matrix) -> str:
    """The whole page (see the module docstring)."""
    from steerlab.conformance import cases as C
    from steerlab.conformance import judge as J
    from steerlab.conformance import points as P

    t = m.total()
    n = len(m.outcomes)
    laws = sorted({o.controller for o in m.outcomes})
    ships = list(dict.fromkeys(o.ship for o in m.outcomes))
    out = ["# Conformance matrix", "",
           "Does every autopilot steer every catalogue ship, or say why not? Every catalogue ship at its "
           "design speed and at both ends of its speed range, x every built-in controller with its default "
           "settings, x calm water and a JONSWAP sea of sea state 5: a "
           f"{J.CHANGE_DEG:g} deg course change. Written by `python3 tools/conformance_table.py` "
           "(`steerlab conformance --out DIR` writes the same page and a JSON file); "
           "`tests/test_conformance_matrix.py` runs the same matrix in CI (`.ci/run`'s second step, "
           "`pytest -m conformance`; the default `pytest` run leaves it out).", "",
           f"**{t[STEERS]} of {n} cases steer ({_pct(m.fraction_steers)}; the target is "
           f">= {_pct(TARGET)}), {t[REFUSED]} are refused, {t[FAILS]} fail.**", "",
           "## How a case is judged", "",
           f"* **steers** (✓): after the change the heading settles within {J.TOL_DEG:g} deg of the new course "
           "and stays there for the whole hold window at the end of the run, and the rudder reverses at most "
           f"{J.MAX_REVERSALS_PER_MIN:g} times a minute after the change (a reversal counts once the rudder "
           f"came back {J.REVERSAL_HYST_DEG:g} deg from its last extreme). In waves the heading judged is "
           f"its mean over a triangular window of {J.WAVE_WINDOW:g} s (the course made good; the heading itself swings "
           "at the encounter frequency whatever the autopilot does).",
           "* **refused** (R): the design raised `InputError`, one line naming the field to give "
           "(listed below).",
           "* **fails** (✗), with the reason: `diverged`, `spins` (the heading ran more than "
           f"{J.SPIN_DEG:g} deg from the new course), `never turns` (it never made half the change), "
           "`limit cycle`, `steady offset`, `not settled`, `rudder reversals`, or `crashed` (an exception "
           "other than `InputError`: a defect).",
           "",
           "The runs: the ship's default gear "
           f"({C.GEAR['delta_max_deg']:g} deg, {C.GEAR['rate_max_deg_s']:g} deg/s, servo "
           f"{C.GEAR['T_sg']:g} s; a scale model's Froude-scaled), dt = {C.DT:g} s, the change at "
           f"t = {C.T_CHANGE:g} s; the sea is "
           f"JONSWAP sea state 5 from {C.SEA['wave_angle_deg']:g} deg off the bow, seed {C.SEA_SEED} (on a "
           "scale model Froude-scaled, Hs / lambda and Tp / sqrt(lambda), and its record judged in "
           "full-scale time, t x sqrt(lambda)), and "
           "in it each law runs behind the wave filter designed for the step (`law+wf`; `asa` has its own; "
           "an observer in the law at the loop's bandwidth on a course-stable design model and twice it on "
           "an unstable one, not five times; docs/environment.md); in calm water each law, designed for the "
           "measured heading, runs by the same compiled loop with the filter switched off (its orders bit for "
           "bit the plain law's: `steerlab.conformance.matrix.one_loop`). "
           "A run lasts "
           f"{C.RUN_SCALES:g} time scales after the change ({C.MIN_AFTER:g}-{C.MAX_AFTER:g} s), the hold "
           f"window is the last {C.HOLD_SCALES:g} ({C.MIN_HOLD:g} s at least); the time scale is "
           "`2 pi / omega_g`, the natural frequency at which a loop on the ship's first-order Nomoto "
           "model asks for the whole rudder or its whole rate in the change "
           "(`steerlab.conformance.cases`). Operating points: the design speed "
           "(`ShipSpec.design_speed` where the ship has one, else the middle of its speed range, else "
           f"{P.DEFAULT_SPEED_KN:g} kn) and the ends of the speed range (an open lower end taken as "
           f"{P.OPEN_LOW:g} x, an infinite upper end as {P.OPEN_HIGH:g} x the design speed); the "
           "entries indexed by propeller rate at the ends and middle of their rpm table.", "",
           "## By law", "",
           "| law | steers | refused | fails | steers % |", "|---|---:|---:|---:|---:|"]
    for r in summary_rows(m):
        law = f"**{r[0]}**" if r[0] == "all" else f"`{r[0]}`"
        out.append(f"| {law} | {r[1]} | {r[2]} | {r[3]} | {r[4]} |")
    out += ["", "## Ship x law", "",
            "Each cell: calm water at the low, design and high points, then sea state 5 at the same points "
            "(✓ steers, R refused, ✗ fails; a ship with fewer points has fewer symbols).", "",
            "| ship | points | " + " | ".join(f"`{c}`" for c in laws) + " |",
            "|---|---|" + "---|" * len(laws)]
    by_pair = defaultdict(list)
    for o in m.outcomes:
        by_pair[(o.ship, o.controller)].append(o)
    for ship in ships:
        first = by_pair[(ship, laws[0])]
        pts = {o.point: o.where for o in first if o.sea == CALM}
        where = " / ".join(pts[p] for p in POINT_ORDER if p in pts)
        cells = [_cell(by_pair[(ship, c)]) for c in laws]
        out.append(f"| `{ship}` | {where} | " + " | ".join(cells) + " |")
    refusals = defaultdict(list)
    for o in m.outcomes:
        if o.verdict == REFUSED:
            refusals[(o.controller, o.field_name)].append(o)
    out += ["", "## Refusals", "",
            "Grouped by law and the field named; one message shown (the numbers in it are those of the "
            "first case).", "", "| law | field | cases | ships | message |", "|---|---|---:|---|---|"]
    for (law, fld), os_ in sorted(refusals.items()):
        names = ", ".join(dict.fromkeys(o.ship for o in os_))
        out.append(f"| `{law}` | `{fld}` | {len(os_)} | {names} | {_md_escape(os_[0].reason)} |")
    fails = [o for o in m.outcomes if o.verdict == FAILS]
    out += ["", "## Failures", "", "| law | ship | point | sea | reason |", "|---|---|---|---|---|"]
    for o in sorted(fails, key=lambda o: (o.controller, o.ship, o.sea, POINT_ORDER.index(o.point))):
        out.append(f"| `{o.controller}` | `{o.ship}` | {o.point} ({o.where}) | {o.sea} | {_md_escape(o.reason)} |")
    return "\n".join(out) + "\n"
