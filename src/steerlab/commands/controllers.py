"""``steerlab controllers``: the registered controllers with their design rules."""

from __future__ import annotations

EXAMPLES = """examples:
  steerlab controllers                    # name, description, design rule of every controller
  steerlab controllers --json"""

#: what the listing says of a law whose spec states no design rule
NO_RULE = "no stated rule"


def register(sub, formatter_class):
    p = sub.add_parser("controllers", help="list the registered controllers with their design rules",
                       description="The controllers steerlab knows (steerlab.control, plug-ins), each with "
                                   "what it is, the rule its default gains come from and its source. Every "
                                   "controller is also registered behind the wave filter as NAME+wf.",
                       epilog=EXAMPLES, formatter_class=formatter_class)
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(func=run)


def rows(with_wave_filter: bool = False) -> list[dict]:
    """One row per registered controller (the ``+wf`` variants only with ``with_wave_filter``):
    ``name``, ``description``, ``design_rule`` (:data:`NO_RULE` when the spec states none),
    ``source``."""
    from steerlab.control.registry import CONTROLLERS

    out = []
    for name in sorted(CONTROLLERS):
        if name.endswith("+wf") and not with_wave_filter:
            continue
        spec = CONTROLLERS.get_spec(name)
        out.append({"name": name, "description": spec.description,
                    "design_rule": spec.design_rule or NO_RULE, "source": spec.source})
    return out


def run(args) -> int:
    from steerlab.cli import dump_json

    table = rows()
    if args.json:
        print(dump_json(table))
        return 0
    import textwrap

    from steerlab.text_table import table_width

    width = table_width()
    for r in table:
        print(textwrap.fill(f"{r['name']}: {r['description']}", width, subsequent_indent="  "))
        for label in ("design_rule", "source"):
            print(textwrap.fill(str(r[label]), width, initial_indent=f"  {label.replace('_', ' ')}: ",
                                subsequent_indent="      ", break_long_words=False, break_on_hyphens=False))
    print(f"({len(table)} controllers; each also as NAME+wf behind the wave filter)")
    return 0
