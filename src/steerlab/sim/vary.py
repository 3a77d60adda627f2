"""Variations of a scenario by name: ``sl.vary(scenario, {"controller.Kp": [...], ...})``.

A varied quantity is a dotted name into the scenario's TOML-shaped dict
(``controller.Kp``, ``ship.speed_kn``, ``ship.options.K``, ``gear.rate_max_deg_s``,
``environment.wave_power``, ``seed`` ...). Every combination is written into a copy of the
scenario's dict and validated again by the scenario's pydantic model, so a varied scenario
is exactly what the same TOML file would give: bounds are checked (one line naming the field
and the allowed range), and the controller's design rule runs as usual when it is built.

``mode="grid"``: the product of the value lists (the last name varies fastest);
``mode="zip"``: the i-th values together (lists of equal length).

Example::

    import steerlab as sl
    runs = sl.vary(sl.default_scenario(), {"controller.T_settle": [100, 150], "seed": [1, 2, 3]})
    batch = sl.simulate_batch([build(s) for s in runs])        # steerlab.sim.setup.build
"""

from __future__ import annotations

import copy
import itertools
from typing import TYPE_CHECKING, Any, Mapping, Sequence

from steerlab.errors import InputError

if TYPE_CHECKING:
    from steerlab.sim.scenario import Scenario

MAX_VARIATIONS = 100_000
MODES = ("grid", "zip")


def _model_at(scenario, path: tuple):
    """The pydantic model class of the table at ``path`` (None: not a table; ``ship.options``
    is the ship's options model)."""
    import typing

    from pydantic import BaseModel

    if path == ("ship", "options"):
        from steerlab.ships.registry import get_ship

        return get_ship(scenario.ship.model).options_model
    cls, node = type(scenario), scenario
    for part in path:
        value = getattr(node, part, None) if node is not None else None
        if isinstance(value, BaseModel):
            cls, node = type(value), value
            continue
        field = cls.model_fields.get(part) if cls is not None else None
        models = [a for a in (typing.get_args(field.annotation) if field else ())
                  if isinstance(a, type) and issubclass(a, BaseModel)]
        if not models:
            return None
        cls, node = models[0], None              # an optional table that is absent (e.g. sensors)
    return cls


def _check_name(scenario, name) -> tuple:
    if not isinstance(name, str) or not name.strip():
        raise InputError("vary", f"a varied quantity needs a dotted name like 'controller.Kp', got {name!r}")
    path = tuple(name.strip().split("."))
    for i, part in enumerate(path):
        model = _model_at(scenario, path[:i])
        where = ".".join(path[:i]) or "the scenario"
        if model is None:
            raise InputError(name, f"{where} is a value, not a table")
        known = list(model.model_fields)
        if part not in known:
            raise InputError(name, f"unknown field {part!r} of {where}; known fields: {', '.join(known) or 'none'}")
    return path


def _set(d: dict, path: tuple, value) -> None:
    node = d
    for part in path[:-1]:
        if not isinstance(node.get(part), dict):
            node[part] = {}
        node = node[part]
    node[path[-1]] = value


def vary(scenario: Scenario, changes: Mapping[str, Sequence[Any]], mode: str = "grid") -> list[Scenario]:
    """Validated copies of ``scenario`` with the dotted names of ``changes`` set (module docstring).

    Parameters
    ----------
    scenario : steerlab.sim.scenario.Scenario
    changes : dict
        ``{dotted name: sequence of values}`` in the scenario's edge units (degrees, knots).
    mode : {"grid", "zip"}

    Returns
    -------
    list of Scenario
        In grid order (the last name varies fastest) or zip order.
    """
    from steerlab.sim.scenario import scenario_from_dict

    if mode not in MODES:
        raise InputError("mode", f"must be one of {MODES}, got {mode!r}")
    if not isinstance(changes, dict) or not changes:
        raise InputError("vary", "needs a dict {dotted name: [values, ...]} with at least one entry")
    base = scenario.model_dump()
    paths, lists = [], []
    for name, values in changes.items():
        paths.append(_check_name(scenario, name))
        if isinstance(values, (str, bytes)) or not hasattr(values, "__iter__"):
            raise InputError(name, f"needs a list of values, got {values!r}")
        values = list(values)
        if not values:
            raise InputError(name, "needs at least one value")
        lists.append([v.item() if hasattr(v, "item") else v for v in values])
    if mode == "zip":
        if len({len(v) for v in lists}) != 1:
            raise InputError("vary", "mode 'zip' needs value lists of equal length, got "
                                     + ", ".join(f"{n}: {len(v)}" for n, v in zip(changes, lists)))
        combos = list(zip(*lists))
    else:
        total = 1
        for v in lists:
            total *= len(v)
        if total > MAX_VARIATIONS:
            raise InputError("vary", f"{total} combinations; allowed at most {MAX_VARIATIONS}")
        combos = list(itertools.product(*lists))
    out = []
    for combo in combos:
        d = copy.deepcopy(base)
        for path, value in zip(paths, combo):
            _set(d, path, value)
        out.append(scenario_from_dict(d))
    return out
