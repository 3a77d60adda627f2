"""``steerlab imo``: the IMO standard set of manoeuvring trials and a pass/fail report."""

from __future__ import annotations

from pathlib import Path

from steerlab.commands._trial_common import add_ship_arguments, conditions_from_args, flag_names, with_flag_names

EXAMPLES = """examples:
  steerlab imo --ship esso --out out/imo-esso
  steerlab imo --ship nomoto1 --ship-option K=0.08 --ship-option T=60 --speed-kn 12 --out out/imo-n1
  steerlab imo --ship esso --no-gear --json --out out/imo-esso-ideal"""


def register(sub, formatter_class) -> None:
    p = sub.add_parser("imo", help="IMO standard manoeuvring trials with a pass/fail report (HTML + JSON)",
                       description="Turning circles (max rudder, both sides), 10/10 and 20/20 zig-zags "
                                   "(both sides), pull-out and spiral; IMO MSC.137(76) criteria. Writes "
                                   "DIR/report.html (self-contained), DIR/imo.json and the figures.",
                       epilog=EXAMPLES, formatter_class=formatter_class)
    add_ship_arguments(p)
    p.add_argument("--out", required=True, help="output directory")
    p.add_argument("--json", action="store_true", help="also print imo.json to stdout")
    p.set_defaults(func=cmd_imo)


def cmd_imo(args) -> int:
    from steerlab.cli import _progress, dump_json, staged_output
    from steerlab.trials.api import write_figures
    from steerlab.trials.imo_report import write_imo_html
    from steerlab.trials.imo_criteria import model_scale_note, verdict_text
    from steerlab.trials.imo_standard import run_imo
    from steerlab.trials.tables import format_table

    say = _progress(args.quiet)
    cond = conditions_from_args(args)
    report, trials = with_flag_names(run_imo, cond, flags=flag_names(args), progress=say)
    with staged_output(Path(args.out)) as stage:
        figs = {}
        for i, (label, kind, trial) in enumerate(trials):
            figs[label] = write_figures(kind, trial, stage, prefix=f"{i + 1:02d}_")
        dump_json(report, stage / "imo.json")
        write_imo_html(stage / "report.html", report, figs)
    if args.json:
        print(dump_json(report))
    else:
        rows = [(f"{c['trial']}: {c['criterion']}", f"{c['value']:.4g} <= {c['limit']:.4g} {c['unit']}",
                 verdict_text(c)) for c in report["criteria"]]
        cs = report["course_stability"]
        rows.append(("course stability (spiral / pull-out)", f"{cs['spiral_verdict']} / {cs['pullout_verdict']}",
                     f"loop width {cs['loop_width_deg']:.3g} deg"))
        verdict = {True: "PASS", False: "FAIL", None: "incomplete"}[report["overall_pass"]]
        scale = report["conditions"].get("model_scale")
        if scale is not None and report["overall_pass"] is not None:
            verdict += f" ({model_scale_note(scale)})"
        print(format_table(rows, f"IMO trials on {cond.ship} at {cond.speed_kn:g} kn: {verdict}"))
    say(f"wrote {args.out}/report.html and {args.out}/imo.json")
    return 0
