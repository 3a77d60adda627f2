"""``steerlab conformance``: every catalogue ship x every built-in law x calm and sea state 5.

Runs the conformance matrix (steerlab.conformance): a 20 deg course change per case, judged
steers / refused (one line naming a field) / fails (with the reason); prints the counts per
law. --out DIR writes matrix.json (every case) and conformance.md (the page of
docs/conformance.md).
"""

from __future__ import annotations

EXAMPLES = """examples:
  steerlab conformance                                  # the whole matrix (a few minutes)
  steerlab conformance --ships esso --controllers adrc
  steerlab conformance --sea-points design --json       # sea state 5 at the design speed only
  steerlab conformance --out out/conformance            # matrix.json + conformance.md"""


def register(sub, formatter_class):
    p = sub.add_parser("conformance", help="every catalogue ship x every law: does it steer, refuse or fail",
                       description=__doc__.split("\n\n", 1)[1], epilog=EXAMPLES,
                       formatter_class=formatter_class)
    p.add_argument("--ships", nargs="+", default=None, metavar="ID", help="ship ids (default: every built-in ship)")
    p.add_argument("--controllers", nargs="+", default=None, metavar="TYPE",
                   help="controller types (default: every built-in law, without the +wf variants)")
    p.add_argument("--sea-points", nargs="*", default=["design", "low", "high"], metavar="POINT",
                   help="operating points that also run in sea state 5: design, low, high (none: calm only)")
    p.add_argument("--workers", type=int, default=None, metavar="N",
                   help="processes (default: 2, or the cores if fewer)")
    p.add_argument("--json", action="store_true", help="print every case as JSON")
    p.add_argument("--out", default=None, metavar="DIR", help="write matrix.json and conformance.md here")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=run)


def _check(args) -> None:
    from steerlab.conformance.matrix import builtin_controllers
    from steerlab.control.registry import get_controller
    from steerlab.errors import InputError
    from steerlab.ships.registry import get_ship

    for s in args.ships or ():
        get_ship(s)                                   # InputError naming ship.model
    for c in args.controllers or ():
        get_controller(c)                             # InputError naming controller.type
        if "+" in c and c not in builtin_controllers():
            raise InputError("--controllers", f"{c!r}: the matrix runs the laws themselves, not the '+wf' variants")
    for p in args.sea_points:
        if p not in ("design", "low", "high"):
            raise InputError("--sea-points", f"must be design, low or high, got {p!r}")
    if args.workers is not None and not 1 <= args.workers <= 64:
        raise InputError("--workers", f"must be 1-64, got {args.workers}")


def run(args) -> int:
    from pathlib import Path

    from steerlab.cli import dump_json, staged_output
    from steerlab.conformance.matrix import run_matrix
    from steerlab.conformance.table import markdown, text_summary
    from steerlab.outputs import prepare_out
    from steerlab.progress import reporter, runs_progress

    _check(args)
    if args.out:
        prepare_out(Path(args.out))                  # --out checked before any work
    say = reporter(args.quiet)
    m = run_matrix(args.ships, args.controllers, args.sea_points, args.workers,
                   progress=runs_progress(say, "cases"))
    say.close()
    if args.out:
        with staged_output(Path(args.out)) as stage:
            dump_json(m.to_dict(), stage / "matrix.json")
            (stage / "conformance.md").write_text(markdown(m), encoding="utf-8")
    print(dump_json(m.to_dict())) if args.json else print(text_summary(m))
    return 0
