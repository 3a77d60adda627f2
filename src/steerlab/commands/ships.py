"""``steerlab ships``: the ship catalogue (every registered ship) and one ship's parameters."""

from __future__ import annotations

EXAMPLES = """examples:
  steerlab ships                          # id, model, speed range, source of every ship
  steerlab ships --json
  steerlab ships show frigate-norrbin     # parameters with units and source
  steerlab ships show tanker-176k-model-norrbin --json"""


def register(sub, formatter_class):
    p = sub.add_parser("ships", help="list the ship catalogue; 'ships show ID' prints one ship",
                       description="The ships steerlab knows (modules and the data-file catalogue "
                                   "ships/data/*.toml), with model, validity range and source.",
                       epilog=EXAMPLES, formatter_class=formatter_class)
    p.add_argument("action", nargs="?", choices=("list", "show"), default="list",
                   help="list (default) or show one ship")
    p.add_argument("ship", nargs="?", help="ship id for 'show' (as in [ship] model = ...)")
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(func=run)


def _kind(spec) -> str:
    cat = getattr(spec, "catalogue", None)
    if cat:
        return cat["model"]
    return spec.name


def _range(spec) -> str:
    cat = getattr(spec, "catalogue", None)
    if cat and "rpm_range" in cat:
        lo, hi = cat["rpm_range"]
        return f"{lo:g}-{hi:g} rpm"
    from steerlab.units import ms_to_knots

    lo, hi = spec.speed_range
    if hi == float("inf"):
        return "any" if lo == 0.0 else f">= {ms_to_knots(lo):.3g} kn"
    if lo == hi:
        return f"{ms_to_knots(lo):.3g} kn"
    return f"{ms_to_knots(lo):.3g}-{ms_to_knots(hi):.3g} kn"


def _design_speed_kn(spec) -> float:
    """The ship's design speed [kn] (:attr:`steerlab.ships.registry.ShipSpec.design_speed`)."""
    from steerlab.units import ms_to_knots

    return float(ms_to_knots(spec.design_speed))


def list_rows() -> list[dict]:
    """One row per registered ship: id, model, validity range, source."""
    from steerlab.ships.registry import SHIPS

    return [{"id": name, "model": _kind(spec), "range": _range(spec), "source": spec.source,
             "description": spec.description} for name, spec in sorted(SHIPS.items())]


def show(ship_id: str) -> dict:
    """Parameters of one ship with units and source."""
    from steerlab.ships.registry import get_ship

    spec = get_ship(ship_id)
    d = {"id": spec.name, "model": _kind(spec), "description": spec.description,
         "source": spec.source, "range": _range(spec), "design_speed_kn": _design_speed_kn(spec),
         "states": [{"name": n, "unit": u} for n, u in zip(spec.state_names, spec.state_units)]}
    cat = getattr(spec, "catalogue", None)
    if cat:
        d["catalogue"] = cat
    if spec.options_model is not None:
        d["options"] = [{"name": k, "default": f.default, "description": f.description or ""}
                        for k, f in spec.options_model.model_fields.items()]
    if spec.params is not None:
        d["record"] = record_at_design_speed(spec)
    return d


def record_at_design_speed(spec) -> list[dict]:
    """The ship record its kernel reads, as ``pack`` makes it at the design speed with the
    default options: ``[{"name", "value", "unit", "description"}]`` in SI units, from the
    ship's :class:`~steerlab.records.Layout` (the values the equations use, which for some
    models are derived from the source's: e.g. divided through by a mass term)."""
    import numpy as np

    values = np.asarray(spec.pack(spec.design_speed, None, spec.options(None)), dtype=float)
    layout = spec.params
    if values.shape != (layout.size,):
        raise ValueError(f"ship {spec.name!r}: pack made {values.shape[0]} values, its layout has {layout.size}")
    return [{"name": f.name, "value": float(v), "unit": f.unit, "description": f.doc}
            for f, v in zip(layout.fields, values)]


def _print_list(rows):
    from steerlab.text_table import render_table

    print(render_table(("id", "model", "range", "source"),
                       ((r["id"], r["model"], r["range"], r["source"]) for r in rows), align="llll"))


def _print_show(d):
    import textwrap

    from steerlab.text_table import render_table, table_width

    width = table_width()

    def say(label: str, text: str) -> None:
        """``label: text`` wrapped to the table width, continuation lines indented."""
        print(textwrap.fill(str(text), width, initial_indent=f"  {label}: ", subsequent_indent="      ",
                            break_long_words=False, break_on_hyphens=False))

    print(textwrap.fill(f"{d['id']}: {d['description']}", width, subsequent_indent="  "))
    say("model", d["model"])
    say("range", d["range"])
    say("design speed", f"{d['design_speed_kn']:.4g} kn (a scenario without speed_kn runs at it)")
    say("source", d["source"])
    say("states", ", ".join(f"{s['name']} [{s['unit']}]" for s in d["states"]))
    cat = d.get("catalogue")
    if cat:
        say("vessel", f"{cat['vessel']}, L = {cat['length_m']:g} m ({cat['file']})")
        table = render_table([f"{c['name']} [{c['unit']}]" for c in cat["columns"]],
                             ([f"{v:.6g}" for v in row] for row in cat["rows"]),
                             align="r" * len(cat["columns"]), width=width - 2)
        print("\n".join("  " + line for line in table.splitlines()))
        if cat["constants"]:
            say("constants", ", ".join(f"{k} = {v:g}" for k, v in cat["constants"].items()))
        say("notes", cat["notes"])
        if cat.get("vessel_notes"):
            say("vessel notes", cat["vessel_notes"])
    for o in d.get("options", []):
        say(f"option {o['name']} = {o['default']!r}", o["description"])
    record = d.get("record")
    if record:
        print(f"  record at the design speed (the values its equations use, SI):")
        table = render_table(("name", "value", "unit", "what"),
                             ((r["name"], f"{r['value']:.6g}", r["unit"], r["description"]) for r in record),
                             align="lrll", width=width - 2)
        print("\n".join("    " + line for line in table.splitlines()))


def run(args) -> int:
    from steerlab.cli import dump_json
    from steerlab.errors import InputError

    if args.action == "list":
        if args.ship:
            raise InputError("ship", "'steerlab ships' takes no ship id; use 'steerlab ships show ID'")
        rows = list_rows()
        print(dump_json(rows)) if args.json else _print_list(rows)
        return 0
    if not args.ship:
        raise InputError("ship", "'steerlab ships show' needs a ship id (see 'steerlab ships')")
    d = show(args.ship)
    print(dump_json(d)) if args.json else _print_show(d)
    return 0
