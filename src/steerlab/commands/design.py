"""``steerlab design SCENARIO.toml``: the design report of a scenario's controller.

The design model (Nomoto K, T with signs, b2, second-order T1-T3, speed, gear), the law's
design rule, its gains by name with units, and the linearised loop's gain, phase and delay
margins and bandwidth (python-control), with one warning line on stderr per margin under its
floor (docs/design-report.md).
"""

from __future__ import annotations

EXAMPLES = """examples:
  steerlab design examples/scenarios/esso-pid.toml
  steerlab design examples/scenarios/nomoto1-pid.toml --json"""


def register(sub, formatter_class):
    p = sub.add_parser("design", help="design report: design model, rule, gains, loop margins and bandwidth",
                       description="The design report of a scenario's controller: its design model, the rule "
                                   "its gains come from, the gains with units, and the gain, phase and delay "
                                   "margins and bandwidth of its loop linearised on the design model "
                                   "(docs/design-report.md). A margin under its floor is a warning on stderr.",
                       epilog=EXAMPLES, formatter_class=formatter_class)
    p.add_argument("scenario", help="scenario TOML file")
    p.add_argument("--json", action="store_true", help="print JSON (non-finite numbers as \"inf\"/\"nan\")")
    p.set_defaults(func=run)


def scenario_controller(scenario):
    """The scenario's controller, designed through the one design path
    (:func:`steerlab.sim.setup.design`), as a :class:`~steerlab.components.controller.Controller`."""
    from steerlab.components.controller import Controller
    from steerlab.sim.setup import design

    d = design(scenario)
    return Controller(d.ctrl_spec, d.ctrl, d.pc, d.ctx)


def run(args) -> int:
    from pathlib import Path

    from steerlab.cli import dump_json, print_warning
    from steerlab.components.design_report import design_report, format_report, json_ready
    from steerlab.sim.scenario import load_scenario

    ctrl = scenario_controller(load_scenario(Path(args.scenario)))
    report = design_report(ctrl)
    if args.json:
        print(dump_json(json_ready(report)))
    else:
        print(format_report(report))
    for w in report["warnings"]:
        print_warning(f"{report['controller']}: {w}")
    return 0
