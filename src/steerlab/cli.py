"""steerlab command line: thin layer that parses, builds a scenario, runs and reports.

Every command accepts ``--help`` with examples. Bad input (unknown ship or controller,
out-of-range or NaN fields, malformed TOML) prints one line naming the field and the allowed
range and exits with code 2, leaving nothing in ``--out``: outputs are written to a staging
directory first and moved into place only when everything succeeded. A run that diverged
(non-finite state) or spun exits with code 3 and writes nothing (docs/errors.md).
"""

from __future__ import annotations

import argparse
import math
import re
import sys
import textwrap
from pathlib import Path

from steerlab.errors import EXIT_BAD_INPUT, EXIT_DIVERGED, DivergedError, InertSettingWarning, InputError
from steerlab.messages import MAX_MESSAGE, SHOWN_WARNINGS, one_line, print_warning
from steerlab.messages import close_progress as _close_progress
from steerlab.outputs import _clean, _json_default, dump_json, staged_output  # noqa: F401 (re-exported)

def _progress(quiet: bool):
    """The command's progress sink on stderr: status lines and one updating bar
    (:class:`steerlab.progress.Reporter`; sparse plain lines when stderr is not a terminal)."""
    from steerlab.progress import reporter

    return reporter(quiet)


# ---------------------------------------------------------------- commands


def cmd_run(args) -> int:
    from steerlab.report import figure_worker

    # a child imports matplotlib now and draws the figures once the run is done
    # (steerlab.figure_worker); it goes away with this command, however it ends
    figures = figure_worker().start()
    try:
        return _run(args, figures)
    finally:
        figures.cancel()


def _run(args, figures) -> int:
    from steerlab.metrics import METRIC_UNITS, compute_metrics
    from steerlab.report import FIGURE_NAMES, format_metrics_table, report_title, write_run_report
    from steerlab.sim.engine import simulate
    from steerlab.commands._guard import design_checked
    from steerlab.sim.divergence import check_run
    from steerlab.sim.scenario import default_scenario, default_scenario_path, load_scenario

    say = _progress(args.quiet)
    path = Path(args.scenario) if args.scenario else default_scenario_path()
    scenario = load_scenario(path) if args.scenario else default_scenario()
    if args.seed is not None:
        scenario = scenario.replace(seed=args.seed)
    if not (args.lam >= 0.0 and math.isfinite(args.lam)):
        raise InputError("--lambda", f"must be a finite number >= 0, got {args.lam}")
    say(f"scenario {one_line(scenario.name, 80)!r} from {path}")
    from steerlab.commands import _run_options as ro

    ro.check_run_options(args, scenario)      # --record-every, memory estimate: before any allocation
    setup, warnings = design_checked(scenario, args.max_memory)
    say(f"simulating {setup.n_steps} steps of {setup.dt} s with the {args.engine} engine "
        f"({setup.ship.name} + {setup.controller.name})")
    result = simulate(setup, engine=args.engine, record_every=args.record_every)
    try:
        check_run(result, setup)              # a diverged run or a spin: exit 3, no metrics
        ro.check_accumulator(result, setup)
    except DivergedError as err:
        if args.keep_diverged:                # the rows before it, marked diverged; exit 3 all the same
            with staged_output(Path(args.out)) as stage:
                rows = ro.write_diverged(stage, result, scenario, err, args)
            say(f"kept {rows} rows up to the divergence in {args.out} (metrics.json: diverged)")
        raise
    metrics = compute_metrics(result, lam=args.lam)
    say("writing time series, metrics, figures and report")
    with staged_output(Path(args.out)) as stage:
        figures.submit(stage, result, report_title(result, scenario))   # drawn while the data is written
        result.to_csv(stage / "timeseries.csv", ro.csv_progress(say, len(result.time)))
        if args.parquet:
            result.to_parquet(stage / "timeseries.parquet")
        extra = {"warnings": warnings} if warnings else {}
        if args.record_every != 1:
            extra["record_every"] = args.record_every
            extra["note"] = ("integral metrics (iae, ise, itae, J, travel, reversals, mean rudder, max error) "
                             "from every step; step metrics, final error, max rudder and min speed from the "
                             f"log, every {args.record_every * setup.dt:g} s")
        dump_json({"scenario": scenario.name, "seed": scenario.seed, "engine": args.engine,
                   "metrics": metrics, "units": {k: METRIC_UNITS.get(k, "") for k in metrics}, **extra},
                  stage / "metrics.json", digits=None)
        (stage / "scenario.json").write_text(scenario.model_dump_json(indent=2) + "\n", encoding="utf-8")
        write_run_report(stage, result, metrics, scenario, figures=[stage / name for name in FIGURE_NAMES])
        figures.wait()                        # the report names the figures; they are complete here
    print(format_metrics_table(metrics))
    if metrics.get("step_lowpass_s"):           # in waves: say on what the step metrics were judged
        for line in textwrap.wrap(f"step metrics judged on the heading low-passed over {metrics['step_lowpass_s']:g}"
                                  f" s: the sea's wave-frequency yaw (std {metrics['wave_yaw_std_deg']:.2f} deg) is "
                                  "not the autopilot's to take out (docs/environment.md)", 86):
            say(line)
    hint = ro.tracking_hint(metrics, setup.ship.name)
    for line in textwrap.wrap(hint or "", 86):    # within the output width with the time prefix
        say(line)
    say(f"wrote {args.out}/report.html")
    return 0


def cmd_experiment(args) -> int:
    from steerlab.experiments import EXPERIMENTS

    if args.name not in EXPERIMENTS:
        raise InputError("experiment", f"unknown experiment {args.name!r}; known: {sorted(EXPERIMENTS)}")
    say = _progress(args.quiet)
    run = EXPERIMENTS[args.name].run
    with staged_output(Path(args.out)) as stage:
        rows = run(stage, progress=say, quick=args.quick)
    from steerlab.text_table import render_table

    # an experiment whose 'paper' column is not a published measurement names its columns (COLUMNS)
    print(render_table(getattr(EXPERIMENTS[args.name], "COLUMNS", ("quantity", "paper", "steerlab", "unit")),
                       ((r["quantity"], r["paper"], r["steerlab"], r["unit"]) for r in rows), align="lrrl"))
    say(f"wrote {args.out}/comparison.json and the figures")
    return 0


def cmd_linearize(args) -> int:
    from steerlab.ships.linear_analysis import linear_summary
    from steerlab.units import knots_to_ms

    from steerlab.ships.registry import get_ship

    try:
        spec = get_ship(args.ship)
    except InputError as err:                   # named as the user gave it: the SHIP argument
        raise InputError("SHIP", err.message) from None
    if args.speed_kn is None:                   # the ship's design speed
        from steerlab.components.linear import default_speed_kn

        args.speed_kn = default_speed_kn(spec)
    if not (math.isfinite(args.speed_kn) and 0.0 < args.speed_kn <= 40.0):
        raise InputError("--speed-kn", f"must be in (0, 40] kn, got {args.speed_kn}")
    if get_ship(args.ship).linearise is None:   # Nomoto/Norrbin/Bech ...: the model's own linear form
        from steerlab.components.linear import print_summary, summary

        s = summary(args.ship, args.speed_kn)
        print(dump_json(s)) if args.json else print_summary(s)
        return 0
    summary = linear_summary(get_ship(args.ship), knots_to_ms(args.speed_kn))
    summary["speed_kn"] = args.speed_kn
    if args.json:
        print(dump_json(summary))
        return 0
    s = summary
    print(f"{s['ship']} at {args.speed_kn:g} kn ({s['speed_m_s']:.4f} m/s), state [v, r]")
    print(f"A1 = [[{s['A1'][0][0]: .5e}, {s['A1'][0][1]: .5e}],\n      [{s['A1'][1][0]: .5e}, {s['A1'][1][1]: .5e}]]")
    print(f"B1 = [{s['B1'][0]: .5e}, {s['B1'][1]: .5e}]   (steerlab sign: delta > 0 to starboard)")
    print("eigenvalues: " + ", ".join(f"{e[0]:.5g}{e[1]:+.3g}j" for e in s["eigenvalues"])
          + ("  -> open-loop UNSTABLE" if s["open_loop_unstable"] else "  -> open-loop stable"))
    print(f"b2 exact    = {s['b2_exact']:.4e} 1/s^2  (paper sign {s['b2_exact_paper']:.4e})")
    print(f"b2 eq (29)  = {s['b2_estimate_eq29']:.4e} 1/s^2  (paper sign {s['b2_estimate_eq29_paper']:.4e})")
    print(f"a0 (eq 36)  = {s['a0']:.4e} 1/s  ({'stable' if s['zero_dynamics_stable'] else 'unstable'} zero dynamics)")
    print(f"Nomoto K = {s['nomoto_K']:.4g} 1/s, T = {s['nomoto_T']:.4g} s "
          f"(T1 {s['nomoto_T1']:.4g}, T2 {s['nomoto_T2']:.4g}, T3 {s['nomoto_T3']:.4g} s)")
    return 0


def cmd_bench(args) -> int:
    from steerlab.bench import run_bench

    if args.n_batch < 1 or args.n_batch > 100_000:
        raise InputError("--n-batch", f"must be in [1, 100000], got {args.n_batch}")
    if args.repeats < 1 or args.repeats > 100:
        raise InputError("--repeats", f"must be in [1, 100], got {args.repeats}")
    say = _progress(args.quiet)
    out = run_bench(n_batch=args.n_batch, repeats=args.repeats, progress=say)
    if args.json:
        print(dump_json(out))
    else:
        from steerlab.text_table import render_pairs

        print(render_pairs(out.items()))
    return 0


# ---------------------------------------------------------------- parser

EXAMPLES = {
    "run": """examples:
  steerlab run --out out/default            # bundled default: Esso tanker + ADRC, 20 deg change, sea state 6
  steerlab run examples/scenarios/calm_default.toml --out out/calm   # the default up to 0.1.0 (eq 39 noise)
  steerlab run examples/scenarios/esso-pid.toml --out out/esso-pid --parquet
  steerlab run examples/scenarios/los-route.toml --out out/los        # route following: track figure with the route
  steerlab run --seed 7 --engine readable --out out/seed7""",
    "experiment": """examples:
  steerlab experiment zwierzewicz2021 --out out/zw2021
  steerlab experiment zwierzewicz2021 --quick --out /tmp/zw-quick""",
    "linearize": """examples:
  steerlab linearize esso --speed-kn 16 --json
  steerlab linearize esso --speed-kn 10""",
    "bench": """examples:
  steerlab bench --json
  steerlab bench --n-batch 200 --repeats 3""",
}


class _OneLineParser(argparse.ArgumentParser):
    """argparse's parser whose usage errors are one line, as every other bad input (exit 2):
    argparse prints the whole usage block first, 28 lines for ``steerlab autopilot``."""

    def error(self, message: str):  # type: ignore[override]
        print(f"steerlab: error: {one_line(message)} (see '{self.prog} --help')", file=sys.stderr)
        raise SystemExit(EXIT_BAD_INPUT)


def build_parser() -> argparse.ArgumentParser:
    fmt = argparse.RawDescriptionHelpFormatter
    p = _OneLineParser(
        prog="steerlab", formatter_class=fmt,
        description="steerlab: design, tune, assess and run ship autopilots.",
        epilog="examples:\n  steerlab run --out out/default\n  steerlab experiment zwierzewicz2021 --out out/zw"
               "\n  steerlab linearize esso --speed-kn 16 --json\n  steerlab bench --json\n\n"
               "Run 'steerlab COMMAND --help' for a command's options.")
    p.add_argument("--version", action="version", version=_version())
    sub = p.add_subparsers(dest="command", metavar="COMMAND", parser_class=_OneLineParser)
    sub.required = True

    r = sub.add_parser("run", help="run one scenario and write metrics, time series, figures and a report",
                       description="Run one scenario (TOML); without a file, the bundled default.",
                       epilog=EXAMPLES["run"], formatter_class=fmt)
    r.add_argument("scenario", nargs="?", help="scenario TOML file (default: the bundled default scenario)")
    r.add_argument("--out", required=True, help="output directory")
    r.add_argument("--engine", choices=("compiled", "readable"), default="compiled")
    r.add_argument("--seed", type=int, default=None, help="override the scenario's seed")
    r.add_argument("--lambda", dest="lam", type=float, default=0.1,
                   help="rudder weight of the speed-loss criterion J (default 0.1)")
    r.add_argument("--parquet", action="store_true", help="also write timeseries.parquet (needs pyarrow)")
    from steerlab.commands._run_options import add_run_options

    add_run_options(r)
    r.add_argument("--quiet", action="store_true", help="no progress messages")
    r.set_defaults(func=cmd_run)

    e = sub.add_parser("experiment", help="reproduce a paper's results next to the published numbers",
                       description="Reproduce a paper: figures plus comparison.json (paper vs steerlab).",
                       epilog=EXAMPLES["experiment"], formatter_class=fmt)
    e.add_argument("name", help="experiment name, e.g. zwierzewicz2021 (an unknown name lists the known ones)")
    e.add_argument("--out", required=True, help="output directory")
    e.add_argument("--quick", action="store_true", help="shorter runs (for smoke tests)")
    e.add_argument("--quiet", action="store_true")
    e.set_defaults(func=cmd_experiment)

    lz = sub.add_parser("linearize", help="linear sway-yaw model, b2, zero dynamics and Nomoto K, T",
                        description="Linearise a ship at a speed (Zwierzewicz et al. 2021, eqs 16-18, 29, 36).",
                        epilog=EXAMPLES["linearize"], formatter_class=fmt)
    lz.add_argument("ship", help="ship name, e.g. esso")
    lz.add_argument("--speed-kn", type=float, default=None,
                    help="speed [kn] (default: the ship's design speed, 16 kn for esso)")
    lz.add_argument("--json", action="store_true", help="print JSON")
    lz.set_defaults(func=cmd_linearize)

    b = sub.add_parser("bench", help="speed benchmark W1 (single run, batch, plain-Python reference)",
                       description="Workload W1: Esso + gear + PID, RK4, dt 0.1 s, 3000 s, 20 deg change.",
                       epilog=EXAMPLES["bench"], formatter_class=fmt)
    b.add_argument("--n-batch", type=int, default=1000, help="runs in the batch (default 1000)")
    b.add_argument("--repeats", type=int, default=5, help="timing repeats, median reported (default 5)")
    b.add_argument("--json", action="store_true", help="print JSON")
    b.add_argument("--quiet", action="store_true")
    b.set_defaults(func=cmd_bench)

    from steerlab.commands import command_modules

    for module in command_modules():
        module.register(sub, fmt)
    return p


def _version() -> str:
    from steerlab import __version__

    return f"steerlab {__version__}"


_NEGATIVE_LIST = re.compile(r"^-[0-9.][0-9.eE+-]*(,[-+0-9.eE]+)+$")


def join_negative_lists(argv: list) -> list:
    """``--opt -33.9,151.2`` as ``--opt=-33.9,151.2``: argparse takes a value that starts with
    ``-`` and is not a plain number (a comma list, e.g. a southern or western ``--origin``) for
    an option and refuses it ("expected one argument"). Only a comma list of numbers right after
    a long option without ``=`` is joined; everything else is left as it is."""
    out = []
    for tok in argv:
        if out and isinstance(tok, str) and _NEGATIVE_LIST.match(tok) and out[-1].startswith("--") \
                and "=" not in out[-1] and out[-1] != "--":
            out[-1] = f"{out[-1]}={tok}"
        else:
            out.append(tok)
    return out


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(join_negative_lists(sys.argv[1:] if argv is None else list(argv)))
    if not getattr(args, "quiet", False):
        from steerlab.jit import drivers

        drivers.on_compile = _say_compiling
    restore = None
    shown_by = _warnings_as_lines()
    try:
        if getattr(args, "out", None):        # every command that writes: --out checked before any work
            _name_command(args)
            restore = _prepare_out(args.out)
        elif args.command in RUNS_UNTIL_STOPPED:
            restore = _unwind_on_sigterm()
        return args.func(args)
    except InputError as err:
        _close_progress()
        print(f"steerlab: error: {one_line(err)}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except DivergedError as err:
        _close_progress()
        print(f"steerlab: error: {one_line(err, 2 * MAX_MESSAGE)}", file=sys.stderr)
        return EXIT_DIVERGED
    except BrokenPipeError:                   # "steerlab ships list | head": the reader left
        import os

        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    except KeyboardInterrupt as err:
        _close_progress()
        print("steerlab: interrupted", file=sys.stderr)
        return 143 if isinstance(err, _Terminated) else 130
    finally:
        _close_progress(forget=True)
        if restore is not None:
            restore()
        import warnings

        warnings.showwarning = shown_by


def console_main() -> None:
    """The ``steerlab`` command and ``python -m steerlab``: :func:`main`, then the exit (a
    finished ``run`` skips the interpreter's teardown: :mod:`steerlab.jit.fast_exit`). The
    command's process-wide settings are made here, not at ``import steerlab``
    (:mod:`steerlab.jit.command`)."""
    from steerlab.jit import command

    command.settings()
    argv = sys.argv[1:]
    code = main(argv)
    if argv[:1] == ["run"]:
        from steerlab.jit.fast_exit import exit_now

        exit_now(code)
    sys.exit(code)


def _say_compiling(msg: str) -> None:
    """The compile notice on stderr, below an open progress bar, wrapped to 100 columns."""
    import textwrap

    _close_progress()
    print(textwrap.fill(msg, 100, subsequent_indent="  "), file=sys.stderr, flush=True)


def _warnings_as_lines():
    """Show steerlab's :class:`~steerlab.errors.InertSettingWarning` and
    :class:`~steerlab.jit.cache_check.CacheWarning` as one line (:func:`print_warning`) instead of Python's two-line form with a source line; other
    warnings as Python shows them. Returns the previous ``warnings.showwarning`` (restored
    when the command ends)."""
    import warnings

    from steerlab.jit.cache_check import CacheWarning

    previous = warnings.showwarning
    SHOWN_WARNINGS.clear()

    def show(message, category, filename, lineno, file=None, line=None):
        if not issubclass(category, (InertSettingWarning, CacheWarning)):
            return previous(message, category, filename, lineno, file, line)
        print_warning(str(message))

    warnings.showwarning = show
    return previous


#: commands that run until stopped (a ship server, an autopilot): SIGTERM (``kill``, a service
#: manager's stop) unwinds them like Ctrl-C, through their shutdown path, exit 143
RUNS_UNTIL_STOPPED = ("serve-ship", "autopilot")


class _Terminated(KeyboardInterrupt):
    """SIGTERM during a command that writes or runs until stopped: unwinds like Ctrl-C (exit 143)."""


def _prepare_out(out: str):
    """Refuse a bad ``--out`` before any work, repair leftovers of killed runs, and make SIGTERM
    unwind like Ctrl-C so the stage folder is removed (docs/reliability-outputs.md). Returns the
    function that restores the default SIGTERM handling (or None)."""
    from steerlab.outputs import prepare_out

    prepare_out(out)
    return _unwind_on_sigterm()


def _name_command(args) -> None:
    """Name the running command in the marker of the folders it writes (its subcommand too)."""
    from steerlab.outputs import set_command

    words = [str(getattr(args, "command", "") or "")]
    for attr in ("name", "kind", "trial"):
        value = getattr(args, attr, None)
        if isinstance(value, str) and len(value) <= 40:
            words.append(value)
            break
    set_command(" ".join(w for w in words if w))


def _unwind_on_sigterm():
    """Make SIGTERM raise :class:`_Terminated` (unwinding like Ctrl-C) in the main thread, when
    nothing else handles it. Returns the function that restores the default handling (or None)."""
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread() \
            or signal.getsignal(signal.SIGTERM) is not signal.SIG_DFL:
        return None

    def _terminated(signum, frame):
        raise _Terminated

    signal.signal(signal.SIGTERM, _terminated)
    return lambda: signal.signal(signal.SIGTERM, signal.SIG_DFL)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
