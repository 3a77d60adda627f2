"""``steerlab trial turning|zigzag|spiral|pullout``: one manoeuvring trial on any ship.

Prints the metrics as JSON (``--json``) or as a table; ``--out DIR`` writes the figures and
``<trial>.json`` (staged: nothing is left in DIR on error).
"""

from __future__ import annotations

import sys
from pathlib import Path

from steerlab.commands._trial_common import add_ship_arguments, conditions_from_args, flag_names, with_flag_names

EXAMPLES = """examples:
  steerlab trial zigzag --ship esso --rudder 20 --heading 20 --json
  steerlab trial turning --ship esso --rudder 35 --side both --out out/turning
  steerlab trial spiral --ship esso --max-rudder 10 --step 2 --out out/spiral
  steerlab trial pullout --ship nomoto1 --ship-option K=0.1 --ship-option T=80 --no-gear
  steerlab trial zigzag --ship nomoto1 --speed-kn 12 --rudder 10 --heading 10 --port-first
  steerlab trial turning --ship kvlcc2-l7 --speed-m-s 1.179 --propeller-rps 11 --rudder-rate 15.68 --servo-lag 0.1"""

HELP = {
    "turning": "turning circle: advance, transfer, tactical and steady diameter, steady speed and rate",
    "zigzag": "zig-zag delta/psi: overshoot angles, time to second execute, period, IMO limits",
    "spiral": "direct and reversed (Bech) spiral: r(delta) curve, course-stability verdict, loop width",
    "pullout": "pull-out: residual rate of turn after a steady turn (course stability)",
}


def register(sub, formatter_class) -> None:
    p = sub.add_parser("trial", help="run a manoeuvring trial (turning, zigzag, spiral, pullout) on a ship",
                       description="Standard manoeuvring trials on any ship of the registry, with the "
                                   "steering gear or an ideal rudder (--no-gear).",
                       epilog=EXAMPLES, formatter_class=formatter_class)
    ts = p.add_subparsers(dest="trial", metavar="TRIAL")
    ts.required = True
    for kind, help_text in HELP.items():
        t = ts.add_parser(kind, help=help_text, description=help_text, epilog=EXAMPLES,
                          formatter_class=formatter_class)
        add_ship_arguments(t)
        t.add_argument("--json", action="store_true", help="print the metrics as JSON")
        t.add_argument("--out", default=None, help="directory for the figures and <trial>.json")
        if kind == "turning":
            t.add_argument("--rudder", type=float, default=35.0, help="rudder angle [deg] (default 35)")
            t.add_argument("--side", choices=("starboard", "port", "both"), default="starboard")
        elif kind == "zigzag":
            t.add_argument("--rudder", type=float, default=10.0, help="rudder angle delta [deg] (default 10)")
            t.add_argument("--heading", type=float, default=None,
                           help="heading change psi that reverses the rudder [deg] (default: = --rudder)")
            t.add_argument("--port-first", action="store_true", help="first rudder to port")
        elif kind == "spiral":
            t.add_argument("--max-rudder", type=float, default=10.0, help="largest rudder angle [deg] (default 10)")
            t.add_argument("--step", type=float, default=2.0, help="rudder step [deg] (default 2)")
            t.add_argument("--points", type=int, default=21, help="reversed-spiral set rates (default 21)")
            t.add_argument("--hold-s", type=float, default=None, help="time per step [s] (default: from the ship)")
        elif kind == "pullout":
            t.add_argument("--rudder", type=float, default=20.0, help="rudder angle of the turn [deg] (default 20)")
        t.set_defaults(func=cmd_trial, trial_kind=kind)


def _options(args) -> dict:
    k = args.trial_kind
    if k == "turning":
        return {"rudder_deg": args.rudder, "side": args.side}
    if k == "zigzag":
        return {"rudder_deg": args.rudder, "heading_deg": args.rudder if args.heading is None else args.heading,
                "port_first": args.port_first}
    if k == "spiral":
        return {"max_rudder_deg": args.max_rudder, "step_deg": args.step, "n_rates": args.points,
                "hold_s": args.hold_s}
    return {"rudder_deg": args.rudder}


def _table(kind, metrics) -> str:
    from steerlab.trials.tables import ROWS, format_table, imo_rows

    blocks = []
    parts = [metrics["starboard"], metrics["port"]] if (kind == "turning" and "starboard" in metrics) else [metrics]
    for m in parts:
        rows = ROWS[kind](m)
        if m.get("imo"):
            rows += imo_rows(m["imo"])
        blocks.append(format_table(rows))
    c = parts[0]["conditions"]
    prop = "" if c.get("propeller_rps") is None else f", propeller {c['propeller_rps']:.4g} rev/s"
    head = (f"{kind} trial on {c['ship']} at {c['speed_kn']:.4g} kn ({c['speed_m_s']:.4g} m/s){prop} "
            f"(L = {c['L_m']:.4g} m, L/U = {c['L_over_U_s']:.3g} s)\n{c.get('gear_description', c['gear'])}")
    return head + "\n" + "\n\n".join(blocks)


def cmd_trial(args) -> int:
    from steerlab.cli import _progress, dump_json, staged_output
    from steerlab.trials.api import check_trial_options, run_trial, write_figures

    say = _progress(args.quiet)
    cond = conditions_from_args(args)
    with_flag_names(check_trial_options, args.trial_kind, cond, flags=flag_names(args), **_options(args))
    say(f"{args.trial_kind} trial on {cond.ship} at {cond.speed_kn:g} kn "
        f"(first run compiles the ship's trial loop, a few seconds)")
    trial, metrics = with_flag_names(run_trial, args.trial_kind, cond, flags=flag_names(args), **_options(args))
    if args.out:
        with staged_output(Path(args.out)) as stage:
            dump_json(metrics, stage / f"{args.trial_kind}.json")
            paths = write_figures(args.trial_kind, trial, stage)
        say("wrote " + ", ".join(f"{args.out}/{p.name}" for p in paths))
    if args.json:
        print(dump_json(metrics))
    else:
        print(_table(args.trial_kind, metrics))
        if not args.out:
            print("(figures: add --out DIR)", file=sys.stderr)
    return 0
