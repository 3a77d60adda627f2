"""``steerlab robustness``: a metric over a grid of model-parameter variations (heat map + table)."""

from __future__ import annotations

EXAMPLES = """examples:
  # ITAE of the scenario's autopilot (designed for the nominal ship) over Nomoto K and T
  steerlab robustness examples/scenarios/nomoto1-pid.toml --vary T=30:70:5 --vary K=0.07:0.2:0.01 --out out/robust
  # speed-loss J over speed and rudder rate, autopilot redesigned at every point
  steerlab robustness examples/scenarios/esso-pid.toml --vary ship.speed_kn=8:16:2 --vary gear.rate_max_deg_s=2:5:1 \\
      --metric J --redesign --out out/robust-J

A bare name is a field of the ship's [ship.options] (nomoto1: K, T) or speed_kn; otherwise
give a scenario path (ship.options.K, gear.T_sg, environment.wave_power ...). Ranges
lo:hi:step include both ends. Writes robustness.json, table.csv/.parquet and heatmap.png
(line.png for one --vary)."""


def register(sub, formatter_class) -> None:
    p = sub.add_parser("robustness", help="a metric over a grid of model-parameter variations",
                       description="Run the scenario's controller (designed for the nominal model) on "
                                   "varied models, all grid points in one compiled batch.",
                       epilog=EXAMPLES, formatter_class=formatter_class)
    p.add_argument("scenario", help="scenario TOML file")
    p.add_argument("--vary", action="append", required=True, metavar="NAME=lo:hi:step",
                   help="a varied quantity and its range (one to three times)")
    p.add_argument("--metric", default="itae",
                   help="metric or expression of on-line metrics for the map (default itae)")
    p.add_argument("--controller", default=None, help="controller type (default: the scenario's)")
    p.add_argument("--redesign", action="store_true",
                   help="design the controller again for every grid point (default: nominal design)")
    p.add_argument("--lambda", dest="lam", type=float, default=0.1,
                   help="rudder weight of the speed-loss criterion J (default 0.1)")
    from steerlab.commands._sweep_args import add_executor_args

    add_executor_args(p)
    p.add_argument("--out", required=True, help="output directory")
    p.add_argument("--quiet", action="store_true", help="no progress messages")
    p.set_defaults(func=cmd_robustness)


def cmd_robustness(args) -> int:
    from pathlib import Path

    from steerlab.cli import _progress, staged_output
    from steerlab.commands._sweep_args import executor_from_args
    from steerlab.sim.scenario import load_scenario
    from steerlab.sweeps.robustness import parse_vary, run_robustness, write_robustness_outputs
    from steerlab.tuning.session import with_controller

    say = _progress(args.quiet)
    scenario = with_controller(load_scenario(args.scenario), args.controller)
    from steerlab.commands._guard import design_checked

    design_checked(scenario, args.max_memory)
    variations = [parse_vary(v, scenario) for v in args.vary]
    executor = executor_from_args(args)
    try:
        res = run_robustness(scenario, variations, args.metric, args.lam, args.redesign, executor, say,
                             args.max_memory)
    finally:
        executor.close()
    if "diverged" in res.table:
        from steerlab.commands._guard import warn

        warn([f"grid: {int(res.table['diverged'].sum())} of {len(res.points)} points diverged (non-finite "
              "state): metric inf, flagged in table.csv (column diverged)"])
    with staged_output(Path(args.out)) as stage:
        write_robustness_outputs(stage, res, scenario.name)
    from steerlab.text_table import render_table

    names = [v.name for v in res.variations]
    print(render_table((*names, res.metric), ((*(f"{x:.4g}" for x in pt), f"{val:.6g}")
                                              for pt, val in zip(res.points, res.metric_values)),
                       align="r" * (len(names) + 1)))
    print(f"nominal: {res.nominal['metric']:.6g}")
    say(f"wrote {args.out}/robustness.json and the map")
    return 0
