"""``steerlab cache info|clear|warm|verify``: the on-disk cache of compiled drivers.

Each (ship, controller, guidance) combination's closed loop is compiled once and kept in
the cache (:mod:`steerlab.jit.drivers`), so later processes load it in milliseconds.
``warm`` compiles the common catalogue combinations ahead of time (e.g. once per CI run,
or after installing steerlab), and on request the ships' plant steps and trial loops, the
combinations of scenario files and the Gymnasium environments; ``clear`` deletes the cache (``--stale`` only the entries of
other steerlab versions, and the drivers compiled from plug-in code that has been edited since),
safely beside running commands; ``verify`` checks every cached file against the digest written
beside it and lists each one's state (ok, corrupt, stale): exit status 1 if any is corrupt
(``--repair`` deletes the corrupt and stale ones; a corrupt file is never used in any case: it is
compiled again with one warning).
"""

from __future__ import annotations

import sys

EXAMPLES = """examples:
  steerlab cache info                 # where the cache is, how many drivers, how big
  steerlab cache warm                 # compile the common catalogue pairs (progress bar)
  steerlab cache warm --ships esso --controllers pid adrc --batch
  steerlab cache warm --ships nomoto1 --controllers all   # every controller on one ship
  steerlab cache warm --gym           # also the Gymnasium environments' step and reset
  steerlab cache warm --ships all --controllers pid --plants --trials   # + plant steps, trials
  steerlab cache warm --scenario examples/scenarios/los-route.toml --batch   # what a file uses
  steerlab cache clear --stale        # drop the entries of other steerlab versions and of edited plug-ins
  steerlab cache verify               # every cached file: ok / corrupt / stale (exit 1 if any corrupt)
  steerlab cache verify --repair      # ... and delete the corrupt and stale ones
  STEERLAB_CACHE_DIR=/tmp/slc steerlab cache info"""

COMMON_SHIPS = ("esso", "nomoto1", "de-keizer", "kosoko")
COMMON_CONTROLLERS = ("pid", "adrc")


def register(sub, formatter_class):
    p = sub.add_parser("cache", help="the cache of compiled loops: info, clear, warm, verify",
                       description=__doc__.split("\n\n", 1)[1], epilog=EXAMPLES,
                       formatter_class=formatter_class)
    p.add_argument("action", choices=("info", "clear", "warm", "verify"))
    p.add_argument("--stale", action="store_true",
                   help="clear: only what will not load again: other steerlab versions' entries, "
                        "and drivers compiled from plug-in code edited since")
    p.add_argument("--ships", nargs="+", default=None, metavar="ID",
                   help=f"warm: ship ids, or 'all' (default: {' '.join(COMMON_SHIPS)})")
    p.add_argument("--controllers", nargs="+", default=list(COMMON_CONTROLLERS), metavar="TYPE",
                   help=f"warm: controller types, or 'all' (default: {' '.join(COMMON_CONTROLLERS)})")
    p.add_argument("--batch", action="store_true", help="warm: also the batch engine's loop")
    p.add_argument("--lanes", nargs="+", type=int, default=None, metavar="N",
                   help="warm, with --batch: the batch loop for these numbers of runs per vector group "
                        "(simulate_batch's lanes, 1-64; default: the engine's 16)")
    p.add_argument("--gym", action="store_true",
                   help="warm: also the Gymnasium environments' step and reset (every task) of the Esso "
                        "and of the --ships")
    p.add_argument("--plants", action="store_true",
                   help="warm: also each ship's plant-only step (readable loop, runtime ship, identification), "
                        "and that of the --scenario files' ships")
    p.add_argument("--trials", action="store_true", help="warm: also each ship's manoeuvring-trial loop")
    p.add_argument("--scenario", nargs="+", default=[], metavar="FILE",
                   help="warm: also the combinations these scenario files use (with --batch: batch too)")
    p.add_argument("--repair", action="store_true", help="verify: delete the corrupt and stale entries")
    p.add_argument("--all", action="store_true", help="verify: list the entries that are ok too")
    p.add_argument("--json", action="store_true", help="info, verify: print JSON")
    p.add_argument("--quiet", action="store_true")
    p.set_defaults(func=run)


def _mb(n: int) -> str:
    return f"{n / 1e6:.1f} MB"


def run(args) -> int:
    from steerlab.jit import drivers

    if args.action == "info":
        info = drivers.cache_info()
        if args.json:
            from steerlab.cli import dump_json

            print(dump_json(info))
        else:
            from steerlab.text_table import render_pairs

            print(render_pairs([
                ("cache root", info["root"]),
                ("this steerlab", info["current"]),
                ("drivers", f"{info['drivers']} ({info['compiled_files']} compiled entry points, "
                            f"{_mb(info['bytes'])})"),
                ("edited plug-ins", f"{info['outdated_drivers']} (drivers of code edited since, "
                                    f"{_mb(info['outdated_bytes'])}; never loaded again)"),
                ("other versions", f"{len(info['stale_versions'])} ({_mb(info['stale_bytes'])}; "
                                   "'steerlab cache clear --stale' removes them and those above)")]))
        return 0
    if args.action == "clear":
        freed = drivers.cache_clear(stale_only=args.stale)
        print(f"freed {_mb(freed)}")
        return 0
    if args.action == "verify":
        return _verify(args)
    return _warm(args)


def _verify(args) -> int:
    """``steerlab cache verify``: exit 1 if a corrupt entry was found, else 0."""
    from steerlab.jit import cache_verify

    found = cache_verify.verify_tree(cache_verify.folders_to_verify(), repair=args.repair)
    counts = {state: sum(s == state for s, _, _ in found) for state in ("ok", "corrupt", "stale")}
    if args.json:
        from steerlab.cli import dump_json

        print(dump_json({"counts": counts, "repaired": bool(args.repair),
                         "entries": [{"state": s, "path": p, "reason": r} for s, p, r in found]}))
    else:
        for state, path, reason in found:
            if state != "ok" or args.all:
                print(f"{state:8s} {path}" + (f"  ({reason})" if reason else ""))
        done = " (deleted: compiled again at next use)" if args.repair and (counts["corrupt"] or counts["stale"]) else ""
        print(f"{len(found)} cached files: {counts['ok']} ok, {counts['corrupt']} corrupt, "
              f"{counts['stale']} stale{done}")
    return 1 if counts["corrupt"] else 0


def _lanes(args):
    """The batch loop's group sizes to warm (``--lanes``, checked, only with --batch), or None
    for the engine's default."""
    from steerlab.errors import InputError
    from steerlab.sim.lanes import check_lanes

    if args.lanes is None:
        return None
    if not args.batch:
        raise InputError("--lanes", "warms the batch loop: give --batch too")
    return tuple(dict.fromkeys(check_lanes(n, "--lanes") for n in args.lanes))


def _warm(args) -> int:
    from steerlab.control.registry import get_controller
    from steerlab.ships.registry import get_ship
    from steerlab.jit import drivers
    from steerlab.sim.scenario import load_scenario
    from steerlab.warm import warm_gym, warm_pair, warm_plant, warm_scenario_file, warm_trial

    from steerlab.control.registry import CONTROLLERS
    from steerlab.ships.registry import SHIPS

    given = args.ships or []
    ships = sorted(SHIPS) if given == ["all"] else (given or list(COMMON_SHIPS))
    controllers = sorted(CONTROLLERS) if args.controllers == ["all"] else args.controllers
    pairs = [(s, c) for s in ships for c in controllers]
    for s, c in pairs:            # validate every name and file before compiling anything
        get_ship(s)
        get_controller(c)
    for path in args.scenario:
        load_scenario(path)
    lanes = _lanes(args)
    jobs = [(f"{s} + {c}", warm_pair, (s, c, args.batch, lanes)) for s, c in pairs]
    jobs += [(f"{s} plant step", warm_plant, (s,)) for s in ships if args.plants]
    jobs += [(f"{s} trial loop", warm_trial, (s,)) for s in ships if args.trials]
    jobs += [(str(path), warm_scenario_file, (path, args.batch, args.plants, lanes)) for path in args.scenario]
    from steerlab.cli import _progress
    from steerlab.progress import runs_progress

    say = _progress(args.quiet)
    report = runs_progress(say, "combinations", period=0.0)
    for i, (what, warm, warm_args) in enumerate(jobs):
        status = warm(*warm_args)
        if status != "ok":
            say(f"{what}: {status}")
        report(i + 1, len(jobs))
    if args.gym:
        warm_gym(("esso", *(ships if given else ())))
    if not args.quiet:
        print(f"warm: {len(jobs)} combination(s) compiled or already cached in "
              f"{drivers.drivers_dir()}", file=sys.stderr)
    return 0
