"""``steerlab montecarlo``: metric distributions and confidence intervals over sea realisations."""

from __future__ import annotations

EXAMPLES = """examples:
  steerlab montecarlo examples/scenarios/sea-state-5.toml --runs 500 --out out/mc
  steerlab montecarlo examples/scenarios/esso-pid.toml --runs 200 --record-every 10 --lambda 0.1 --out out/mc
  steerlab montecarlo examples/scenarios/esso-pid.toml --runs 2000 --dask local --out out/mc-dask

Seeds are scenario.seed + i. Writes montecarlo.json (mean, 95 % CI of the mean, std,
percentiles of every metric), runs.csv/.parquet (one row per seed), bands.csv/.parquet and
percentile_bands.png (5-95 %, 25-75 % and median of heading error and rudder angle)."""


def register(sub, formatter_class) -> None:
    p = sub.add_parser("montecarlo", help="metric distributions and confidence intervals over sea realisations",
                       description="Run a scenario over N seeds in one compiled batch and report the "
                                   "distribution and 95 % confidence interval of every metric.",
                       epilog=EXAMPLES, formatter_class=formatter_class)
    p.add_argument("scenario", help="scenario TOML file")
    p.add_argument("--runs", type=int, required=True, help="number of sea realisations (>= 2)")
    p.add_argument("--record-every", type=int, default=None,
                   help="log interval in steps for the bands and step metrics (default: fit a memory budget)")
    p.add_argument("--lambda", dest="lam", type=float, default=0.1,
                   help="rudder weight of the speed-loss criterion J (default 0.1)")
    from steerlab.commands._sweep_args import add_executor_args

    add_executor_args(p)
    p.add_argument("--out", required=True, help="output directory")
    p.add_argument("--quiet", action="store_true", help="no progress messages")
    p.set_defaults(func=cmd_montecarlo)


def cmd_montecarlo(args) -> int:
    from pathlib import Path

    from steerlab.cli import _progress, staged_output
    from steerlab.commands._sweep_args import executor_from_args
    from steerlab.sim.scenario import load_scenario
    from steerlab.sweeps.montecarlo import run_montecarlo, write_montecarlo_outputs

    say = _progress(args.quiet)
    scenario = load_scenario(args.scenario)
    from steerlab.commands._guard import design_checked

    from steerlab.sweeps.montecarlo import check_montecarlo_memory, check_runs

    check_runs(args.runs)                     # the options first: no design warning before their error
    check_montecarlo_memory(scenario, args.runs, args.record_every, args.max_memory)   # before any set-up
    design_checked(scenario, args.max_memory)
    executor = executor_from_args(args)
    try:
        res = run_montecarlo(scenario, args.runs, args.lam, args.record_every, executor, say, args.max_memory)
    finally:
        executor.close()
    if res.n_diverged:
        from steerlab.commands._guard import warn
        from steerlab.errors import DivergedError
        from steerlab.sim.divergence import likely_cause
        from steerlab.sim.setup import build

        if res.n_diverged == len(res.seeds):
            raise DivergedError(None, f"all {len(res.seeds)} runs left the finite numbers",
                                likely_cause(build(scenario)))
        warn([f"runs: {res.n_diverged} of {len(res.seeds)} runs diverged (non-finite state); left out of the "
              "statistics and the bands, flagged in runs.csv (column diverged)"])
    with staged_output(Path(args.out)) as stage:
        write_montecarlo_outputs(stage, res, scenario.name)
    from steerlab.text_table import render_table

    print(render_table(("metric", "mean", "95% CI of mean", "p5", "p95", "unit"),
                       ((k, f"{s['mean']:.5g}", f"[{s['ci95_low']:.4g}, {s['ci95_high']:.4g}]", s["p5"], s["p95"],
                         s["unit"]) for k, s in res.stats.items()),
                       title=f"{len(res.seeds)} runs, seeds {res.seeds[0]}..{res.seeds[-1]}", align="lrrrrl"))
    say(f"wrote {args.out}/montecarlo.json and percentile_bands.png")
    return 0
