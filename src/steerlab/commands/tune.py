"""``steerlab tune``: optimiser-based tuning of a controller over a set of conditions."""

from __future__ import annotations

EXAMPLES = """examples:
  # PID on the scenario's ship: minimise ITAE + rudder travel over 4 sea realisations
  steerlab tune examples/scenarios/esso-pid.toml --controller pid --params kp,kd,ki --bounds 0.5:10,5:100,0:0.05 \\
      --cost "itae + 0.5*travel" --seeds 4 --out out/tune-pid
  # the speed-loss criterion J (lambda 0.1) by a genetic algorithm (pymoo), resumable
  steerlab tune examples/scenarios/esso-pid.toml --params kp,kd --bounds 0.1:5,1:100 --cost J --method ga \\
      --checkpoint out/ga.ckpt --out out/tune-ga
  # Pareto front ITAE vs rudder travel (NSGA-II), over two speeds and two sea states
  steerlab tune examples/scenarios/esso-pid.toml --params kp,kd --bounds 0.1:5,1:100 --cost itae --cost travel \\
      --method nsga2 --speeds-kn 10,16 --wave-power 1e-4,4e-4 --out out/front
  # the same on a local dask cluster (a remote one: --dask tcp://HOST:8786)
  steerlab tune examples/scenarios/esso-pid.toml --params kp,kd --bounds 0.1:5,1:100 --cost J --dask local --out out/d

cost metrics: itae ise iae J e2 d2 travel reversals mean_rudder max_error (on-line) and
overshoot settling max_rudder (need a recorded log); + - * / ** sqrt log exp abs min max.
Parameters are the controller's config fields (case-insensitive): pid Kp Ki Kd u_max_deg,
adrc T_settle c0 (numeric) observer_bandwidth lqr_r ...  See docs/tuning.md."""


def register(sub, formatter_class) -> None:
    p = sub.add_parser("tune", help="tune a controller's parameters against a cost over many conditions",
                       description="Tune controller parameters with scipy differential evolution (de), a pymoo "
                                   "genetic algorithm (ga) or pymoo NSGA-II (nsga2, two or more costs), "
                                   "evaluating each generation over all conditions in one compiled batch.",
                       epilog=EXAMPLES, formatter_class=formatter_class)
    p.add_argument("scenario", help="scenario TOML file")
    p.add_argument("--controller", default=None, help="controller type (default: the scenario's)")
    p.add_argument("--params", required=True, help="comma-separated parameter names, e.g. kp,kd,ki")
    p.add_argument("--bounds", required=True, help="comma-separated lo:hi per parameter, e.g. 0.5:10,5:100,0:0.05")
    p.add_argument("--cost", action="append", default=None,
                   help="cost expression over the metrics (repeat for several objectives; default J)")
    p.add_argument("--method", choices=("de", "ga", "nsga2"), default=None,
                   help="optimiser (default: de for one cost, nsga2 for several)")
    p.add_argument("--generations", type=int, default=50, help="generations (default 50)")
    p.add_argument("--pop-size", type=int, default=30, help="population size (default 30)")
    p.add_argument("--seed", type=int, default=0, help="optimiser seed (default 0)")
    p.add_argument("--aggregate", choices=("mean", "max"), default="mean",
                   help="combine a candidate's conditions by the mean or the worst case (default mean)")
    p.add_argument("--lambda", dest="lam", type=float, default=0.1,
                   help="rudder weight of the speed-loss criterion J (default 0.1)")
    from steerlab.commands._sweep_args import add_condition_args, add_executor_args

    add_condition_args(p)
    add_executor_args(p)
    p.add_argument("--checkpoint", default=None, metavar="FILE",
                   help="write a checkpoint after every generation; resume from it if it exists (a finished "
                        "one is reported without another generation)")
    again = p.add_mutually_exclusive_group()
    again.add_argument("--resume", dest="checkpoint_mode", action="store_const", const="resume", default="auto",
                       help="continue the --checkpoint FILE, which must exist")
    again.add_argument("--fresh", dest="checkpoint_mode", action="store_const", const="fresh",
                       help="ignore an existing --checkpoint FILE: start over and overwrite it")
    p.add_argument("--out", required=True, help="output directory")
    p.add_argument("--quiet", action="store_true", help="no progress messages")
    p.set_defaults(func=cmd_tune)


def cmd_tune(args) -> int:
    from pathlib import Path

    from steerlab.cli import _progress, staged_output
    from steerlab.commands._sweep_args import condition_kwargs, executor_from_args
    from steerlab.errors import InputError
    from steerlab.sim.scenario import load_scenario
    from steerlab.tuning.params import parse_bounds
    from steerlab.tuning.session import TuneSpec, tune, write_tuning_outputs

    say = _progress(args.quiet)
    if args.checkpoint_mode != "auto" and not args.checkpoint:
        raise InputError(f"--{args.checkpoint_mode}", "needs --checkpoint FILE")
    scenario = load_scenario(args.scenario)
    from steerlab.commands._guard import design_checked
    from steerlab.tuning.session import with_controller

    design_checked(with_controller(scenario, args.controller), args.max_memory)
    names = [n.strip() for n in args.params.split(",") if n.strip()]
    if not names:
        raise InputError("--params", "needs at least one parameter name")
    bounds = parse_bounds(args.bounds, len(names))
    costs = args.cost or ["J"]
    method = args.method or ("nsga2" if len(costs) > 1 else "de")
    if args.seed < 0:
        raise InputError("--seed", f"must be >= 0, got {args.seed}")
    spec = TuneSpec(scenario, names, bounds, costs, args.controller, method, args.generations,
                    args.pop_size, args.seed, aggregate=args.aggregate, lam=args.lam,
                    checkpoint=args.checkpoint, checkpoint_mode=args.checkpoint_mode, **condition_kwargs(args))
    _check_tune_memory(spec, args.max_memory)
    executor = executor_from_args(args)
    try:
        outcome = tune(spec, executor, say)
    finally:
        executor.close()
    with staged_output(Path(args.out)) as stage:
        write_tuning_outputs(stage, outcome)
    s = outcome.summary
    print(f"{s['controller']} tuned by {s['method']}: {s['n_simulations']} simulations of "
          f"{s['steps_per_simulation']} steps in {s['wall_s']:.2f} s")
    for k, v in s["best"]["parameters"].items():
        print(f"  {k:<12} {v:.6g}")
    for c, v in zip(s["costs"], s["best"]["costs"]):
        print(f"  cost {c!r}: {v:.6g}")
    if "front" in s:
        print(f"  Pareto front: {len(s['front'])} points (front.csv, pareto_front.png)")
    from steerlab.commands._guard import warn

    warn(s.get("warnings", ()))
    say(f"wrote {args.out}/result.json")
    return 0


def _check_tune_memory(spec, max_memory) -> None:
    """Refuse a tuning job whose conditions' seas (each held twice: set-up and packed batch) and
    per-run records (population x conditions) would not fit (:mod:`steerlab.resources`), before any set-up."""
    from steerlab.resources import BASE_BYTES, check_memory, sweep_bytes

    n_cond = (max(1, len(spec.variants)) * max(1, len(spec.speeds_kn)) * max(1, len(spec.wave_powers))
              * max(1, int(spec.n_seeds)))
    need = BASE_BYTES + sweep_bytes(n_cond, spec.scenario.n_steps) + 8.0 * 256 * spec.pop_size * n_cond
    check_memory("--seeds", need, f"{n_cond} conditions of {spec.scenario.n_steps} steps x a population of "
                              f"{spec.pop_size}", "use fewer conditions or seeds, a smaller population or a shorter "
                              "duration", max_memory)
