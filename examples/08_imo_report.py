"""The IMO standard set of manoeuvring trials and its pass/fail report on a catalogue ship.

Teaches: ``run_imo`` (turning circles at the gear's maximum rudder to both sides, 10/10 and
20/20 zig-zags to both sides, a pull-out and a spiral; IMO MSC.137(76) criteria) on the
frigate of van Amerongen (1982) Table 2.5 (Norrbin model, ``frigate-norrbin``) at 16 kn, and
how to read the report: every criterion as value / limit (pass when <= 1). This frigate turns
well (advance 3.6 L) but its tactical diameter (5.1 L) is just above the 5 L limit, so the
ship fails overall. Equivalent command (it also writes ``report.html`` and ``imo.json``):
``steerlab imo --ship frigate-norrbin --out out/imo-frigate``.
"""

import numpy as np

from _common import figure, parse_args, save
from steerlab.trials.imo_standard import run_imo
from steerlab.trials.runner import TrialConditions

args = parse_args(__doc__)
# the whole set takes a few seconds, so --quick runs it unchanged
cond = TrialConditions(ship="frigate-norrbin", speed_kn=16.0)
report, trials = run_imo(cond, progress=print)

verdict = {True: "PASS", False: "FAIL", None: "incomplete"}
for c in report["criteria"]:
    print(f"{c['trial']:<26} {c['criterion']:<52} {c['value']:7.3g} <= {c['limit']:<7.3g} {c['unit']:<4}"
          f" {verdict[c['pass']]}")
cs = report["course_stability"]
print(f"course stability: spiral {cs['spiral_verdict']}, pull-out {cs['pullout_verdict']} (information only)")
print(f"overall: {verdict[report['overall_pass']]}")

fig, ax = figure(1, 2, figsize=(11, 4.8), width_ratios=(1, 1.5))
# left: both turning circles in ship lengths from the execute point
a = ax[0, 0]
L = report["conditions"]["L_m"]
for label, kind, trial in trials:
    if kind != "turning":
        continue
    res = trial.result
    x0 = np.interp(trial.t0, res.time, res.col("x_n"))
    y0 = np.interp(trial.t0, res.time, res.col("y_e"))
    a.plot((res.col("y_e") - y0) / L, (res.col("x_n") - x0) / L, lw=1.2, label=label)
    m = trial.metrics
    a.axvline(trial.sign * m["tactical_diameter_L"], color=a.lines[-1].get_color(), ls=":", lw=0.8)
a.axhline(4.5, color="0.4", lw=0.8, ls="--")
a.text(0, 4.55, "advance limit 4.5 L", ha="center", va="bottom", fontsize=8, color="0.3")
a.set_xlim(-6.0, 6.0)
a.set_ylim(-3.5, 6.0)
a.set_aspect("equal")
a.set_xlabel("east (transfer) [L]")
a.set_ylabel("north (original course) [L]")
a.set_title("turning circles (dotted: tactical diameter)", fontsize=10)
a.legend(fontsize=8, loc="lower center")

# right: every criterion as value / limit
a = ax[0, 1]
rows = report["criteria"]
ratio = np.array([c["value"] / c["limit"] for c in rows])
colours = ["C2" if c["pass"] else "C3" for c in rows]
short = {"initial turning: distance to 10 deg heading change": "initial turning"}
labels = [f"{c['trial']}: {short.get(c['criterion'], c['criterion']).removeprefix('turning: ')}" for c in rows]
y = np.arange(len(rows))[::-1]
a.barh(y, ratio, color=colours)
a.axvline(1.0, color="k", lw=1.0)
for yi, c, rt in zip(y, rows, ratio):
    a.text(rt + 0.02, yi, f"{c['value']:.3g} / {c['limit']:.3g} {c['unit']}", va="center", fontsize=7)
a.set_yticks(y, labels, fontsize=7)
a.set_xlim(0, max(1.5, ratio.max() + 0.45))
a.set_xlabel("value / IMO limit  (pass <= 1)")
a.set_title(f"IMO MSC.137(76) on frigate-norrbin at 16 kn: {verdict[report['overall_pass']]}", fontsize=10)
save(fig, args.out / "08_imo_report.png")
