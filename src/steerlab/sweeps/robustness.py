r"""Robustness maps: a metric over a grid of model-parameter variations, for any controller.

Morawski & Pomirski (Table 3) report how ITAE of a fixed autopilot changes when the ship's
parameters differ from the design values; this generalises it. The controller is designed
**once, for the nominal scenario** (its packed parameters and initial state are kept), and
the plant is varied over the grid (``redesign=True`` designs it again at every grid point
instead, i.e. a perfectly informed autopilot). Every grid point is validated as a scenario
and all points run in one compiled batch.

A varied quantity is named

* by a scenario path: ``ship.speed_kn``, ``gear.rate_max_deg_s``, ``gear.T_sg``,
  ``environment.wave_power``, ``ship.options.K`` ...;
* or by a bare name: a field of the ship's ``[ship.options]`` (``K``, ``T`` of ``nomoto1``),
  else ``speed_kn``.

A range ``lo:hi:step`` includes both ends (``T=30:70:5`` is 9 values; ``T=50:50:1`` one).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, replace

import numpy as np

from steerlab.errors import InputError
from steerlab.progress import runs_progress
from steerlab.sim.scenario import scenario_from_dict
from steerlab.sweeps.conditions import deep_merge, make_condition
from steerlab.sweeps.executors import LocalExecutor
from steerlab.sim.batch import PackedBatch
from steerlab.costs import ONLINE, metric_arrays, parse_cost

MAX_POINTS = 100_000
SHORTCUTS = {"speed_kn": ("ship", "speed_kn")}


@dataclass
class Variation:
    name: str          # as given
    path: tuple        # scenario path
    values: np.ndarray


@dataclass
class RobustnessResult:
    variations: list
    points: list                 # list of value tuples, row-major over the grid
    metric: str
    metric_values: np.ndarray    # (n_points,)
    table: dict                  # column -> (n_points,)
    nominal: dict                # the nominal point's metric values
    redesign: bool
    ship: str = ""               # the scenario's ship model (for the units of its options)


def parse_vary(text: str, scenario) -> Variation:
    """``NAME=lo:hi:step`` -> :class:`Variation` (InputError naming ``--vary``)."""
    if "=" not in text:
        raise InputError("--vary", f"needs NAME=lo:hi:step, got {text!r}")
    name, rng = (s.strip() for s in text.split("=", 1))
    try:
        lo, hi, step = (float(v) for v in rng.split(":"))
    except ValueError:
        raise InputError("--vary", f"{name}: range {rng!r} is not lo:hi:step with three numbers") from None
    if not all(math.isfinite(v) for v in (lo, hi, step)) or step <= 0 or hi < lo:
        raise InputError("--vary", f"{name}: needs finite lo <= hi and step > 0, got {rng!r}")
    n = int(math.floor((hi - lo) / step + 1e-9)) + 1
    if n > MAX_POINTS:
        raise InputError("--vary", f"{name}: {n} values; allowed at most {MAX_POINTS}")
    values = lo + step * np.arange(n)
    return Variation(name, _resolve_path(name, scenario), values)


def _resolve_path(name: str, scenario) -> tuple:
    if "." in name:
        path = tuple(name.split("."))
        d = scenario.model_dump()
        node = d
        for i, part in enumerate(path[:-1]):
            if not isinstance(node, dict) or (part not in node and not (i == 1 and part == "options")):
                raise InputError("--vary", f"unknown scenario path {name!r}")
            node = node.get(part, {})
        if path[:2] != ("ship", "options") and (not isinstance(node, dict) or path[-1] not in node):
            raise InputError("--vary", f"unknown scenario path {name!r}")
        return path
    from steerlab.ships.registry import get_ship

    ship = get_ship(scenario.ship.model)
    if ship.options_model is not None and name in ship.options_model.model_fields:
        return ("ship", "options", name)
    if name in SHORTCUTS:
        return SHORTCUTS[name]
    opts = list(ship.options_model.model_fields) if ship.options_model is not None else []
    raise InputError("--vary", f"unknown quantity {name!r} for ship {scenario.ship.model!r}; "
                               f"ship options: {opts or 'none'}; or a scenario path like ship.speed_kn, "
                               "gear.rate_max_deg_s, environment.wave_power")


def _set(d: dict, path: tuple, value: float) -> dict:
    over: dict = {}
    node = over
    for part in path[:-1]:
        node = node.setdefault(part, {})
    node[path[-1]] = float(value)
    return deep_merge(d, over)


def run_robustness(scenario, variations: list[Variation], metric: str = "itae", lam: float = 0.1,
                   redesign: bool = False, executor=None, progress=None,
                   max_memory: float | None = None) -> RobustnessResult:
    """Evaluate ``metric`` (a cost expression) over the grid of ``variations``."""
    say = progress or (lambda msg: None)
    if not 1 <= len(variations) <= 3:
        raise InputError("--vary", f"give one to three --vary options, got {len(variations)}")
    if len({v.path for v in variations}) != len(variations):
        raise InputError("--vary", "a quantity is varied twice")
    expr = parse_cost(metric, "--metric")
    if expr.needs_log:
        raise InputError("--metric", f"robustness maps use the on-line metrics only: {', '.join(ONLINE)}")
    n_points = math.prod(len(v.values) for v in variations)   # counted before the grid is built
    if n_points > MAX_POINTS:
        raise InputError("--vary", f"{n_points} grid points "
                                   f"({' x '.join(str(len(v.values)) for v in variations)}); "
                                   f"allowed at most {MAX_POINTS}")
    points = list(itertools.product(*(v.values for v in variations)))
    nominal = make_condition("nominal", scenario)
    base = scenario.model_dump()
    setups = []
    seas = 0                                 # distinct disturbance sequences held so far
    for i, pt in enumerate(points):
        d = base
        for v, val in zip(variations, pt):
            d = _set(d, v.path, val)
        label = ", ".join(f"{v.name}={val:g}" for v, val in zip(variations, pt))
        try:
            s = make_condition(label, scenario_from_dict(d)).setup
        except InputError as err:
            raise InputError(f"--vary {label}", err.message) from None
        if not redesign:
            if s.pc.shape != nominal.setup.pc.shape:
                raise InputError("--vary", "the controller record changes shape over the grid")
            s = replace(s, pc=nominal.setup.pc, z0=nominal.setup.z0)
        if s.w.shape == nominal.setup.w.shape and np.array_equal(s.w, nominal.setup.w):
            s = replace(s, w=nominal.setup.w)   # the same sea: the batch stores it once
        else:
            seas += 1
        if i == 0 or seas == 1:               # the first point tells whether the grid varies the sea
            _check_grid_memory(n_points if seas else 1, s.n_steps, n_points, label, max_memory)
        setups.append(s)
    say(f"{len(points)} grid points ({' x '.join(str(len(v.values)) for v in variations)}), controller "
        f"{'redesigned at every point' if redesign else 'designed for the nominal scenario'}")
    batch = PackedBatch.from_setups(setups + [nominal.setup])
    out = (executor or LocalExecutor()).run(batch, None, runs_progress(say))
    names = set(ONLINE)
    m = metric_arrays(out.acc, lam, names)
    values = np.asarray(expr(metric_arrays(out.acc, lam, expr.names)), dtype=float)
    bad = out.diverged                     # a diverged point failed: infinite metric, not a number
    if bad.any():
        values = np.where(bad, np.inf, values)
        m = {k: np.where(bad, np.nan, v) for k, v in m.items()}
        say(f"warning: {int(bad[:-1].sum())} of {len(points)} grid points diverged (non-finite state): "
            "metric inf, flagged in table.csv (column diverged)"
            + ("; the NOMINAL scenario diverged too" if bad[-1] else ""))
    table = {v.name: np.array([pt[j] for pt in points]) for j, v in enumerate(variations)}
    table["metric"] = values[:-1]
    table.update({k: m[k][:-1] for k in sorted(names)})
    if bad.any():
        table["diverged"] = bad[:-1].astype(np.int8)
    nominal_row = {"metric": float(values[-1]), **{k: float(m[k][-1]) for k in sorted(names)}}
    return RobustnessResult(variations, points, expr.text, values[:-1], table, nominal_row, redesign,
                            scenario.ship.model)


def _check_grid_memory(n_seas: int, n_steps: int, n_points: int, label: str, max_memory) -> None:
    """Refuse a grid whose disturbance sequences (one per point when the grid varies the sea)
    would not fit (:mod:`steerlab.resources`)."""
    from steerlab.resources import BASE_BYTES, check_memory, sweep_bytes

    need = BASE_BYTES + sweep_bytes(n_seas + 1, n_steps, shared_seas=False) + 8.0 * 64 * (n_points + 1)
    check_memory("--vary", need, f"a grid of {n_points} points with {n_seas} distinct sea(s) of {n_steps} steps "
                                 f"(first point: {label})", "use fewer points or a shorter duration", max_memory)


def write_robustness_outputs(stage, res: RobustnessResult, scenario_name: str) -> None:
    """``robustness.json``, ``table.csv/.parquet`` and ``heatmap.png`` (or ``line.png`` for one variation)."""
    from pathlib import Path

    from steerlab.outputs import dump_json
    from steerlab.sweeps.tables import new_figure, save_figure, write_table

    stage = Path(stage)
    dump_json({"scenario": scenario_name, "metric": res.metric, "redesign": res.redesign,
               "variations": [{"name": v.name, "path": ".".join(v.path), "values": v.values}
                              for v in res.variations],
               "nominal": res.nominal, "rows": [dict(zip(res.table, vals)) for vals in zip(*res.table.values())]},
              stage / "robustness.json")
    write_table(stage, "table", res.table)
    title = f"{scenario_name}: {res.metric}"
    if len(res.variations) == 1:
        v = res.variations[0]
        fig, (ax,) = new_figure()
        ax.plot(v.values, res.metric_values, "o-")
        ax.axhline(res.nominal["metric"], color="k", lw=0.8, ls="--", label="nominal")
        ax.set_xlabel(v.name)
        ax.set_ylabel(res.metric)
        ax.legend()
        ax.set_title(title, parse_math=False)
        save_figure(fig, stage / "line.png")
        return
    a, b = res.variations[0], res.variations[1]
    n_rest = len(res.points) // (len(a.values) * len(b.values))
    grid = res.metric_values.reshape(len(a.values), len(b.values), n_rest)[:, :, 0]
    finite = grid[np.isfinite(grid)]
    scale = _decade(np.max(np.abs(finite)) if finite.size else 1.0)
    shown = grid / 10.0**scale
    fig, (ax,) = new_figure((max(7.0, 2.5 + 0.62 * len(b.values)), max(5.0, 1.8 + 0.42 * len(a.values))))
    ax.grid(False)
    im = ax.pcolormesh(_edges(b.values), _edges(a.values), shown, shading="flat", cmap="viridis")
    fig.colorbar(im, ax=ax, label=metric_label(res.metric, scale))
    ax.set_xlabel(quantity_label(b, res.ship), parse_math=False)
    ax.set_ylabel(quantity_label(a, res.ship), parse_math=False)
    _ticks(ax.set_xticks, b.values)
    _ticks(ax.set_yticks, a.values)
    extra = f" (first value of {res.variations[2].name})" if len(res.variations) > 2 else ""
    ax.set_title(title + extra, parse_math=False)
    if grid.size <= 200:
        lo, hi = (float(np.min(shown[np.isfinite(shown)])), float(np.max(shown[np.isfinite(shown)]))) \
            if finite.size else (0.0, 1.0)
        for i, av in enumerate(a.values):
            for j, bv in enumerate(b.values):
                v = shown[i, j]
                light = np.isfinite(v) and hi > lo and (v - lo) / (hi - lo) > 0.6     # viridis: yellow end
                ax.text(bv, av, f"{v:.2f}" if np.isfinite(v) else "-", ha="center", va="center",
                        fontsize=7, color="k" if light else "w")
    save_figure(fig, stage / "heatmap.png")


def _decade(x: float) -> int:
    """Power of ten (a multiple of 3 beyond +-2) that brings ``x`` near 1-999 for cell labels."""
    if not (np.isfinite(x) and x > 0):
        return 0
    e = int(math.floor(math.log10(x)))
    return 0 if -1 <= e <= 2 else 3 * (e // 3)


def _ticks(set_ticks, values) -> None:
    """A tick at every grid value, or at every k-th when there are more than 12."""
    values = np.asarray(values)
    step = max(1, int(math.ceil(len(values) / 12)))
    set_ticks(values[::step], [f"{v:g}" for v in values[::step]])


def quantity_label(v: Variation, ship: str = "") -> str:
    """``name [unit]`` of a varied quantity: the unit from its field description (a ship option's
    from the ship's options model), else from its name's suffix (``_deg``, ``_kn``, ...)."""
    if v.path[:2] == ("ship", "options") and len(v.path) == 3:
        from steerlab.ships.registry import get_ship

        model = get_ship(ship).options_model if ship else None
        field = model.model_fields.get(v.path[2]) if model is not None else None
        unit = _unit_in(field.description if field is not None else "")
    else:
        unit = _unit_of_path(v.path)
    return f"{v.name} [{unit}]" if unit else v.name


def metric_label(metric: str, scale: int = 0) -> str:
    """``itae [deg s^2]`` (with a ``10^k`` factor when the cell labels are scaled)."""
    from steerlab.costs import LOGGED, ONLINE

    unit = ONLINE[metric][1] if metric in ONLINE else LOGGED.get(metric)
    factor = f"10^{scale} " if scale else ""
    if unit and unit != "-":
        return f"{metric} [{factor}{unit}]"
    return f"{metric} [{factor.strip()}]" if factor else metric


def _unit_in(text: str | None):
    import re

    m = re.search(r"\[([^\]]+)\]", text or "")
    return m.group(1) if m else None


_SUFFIX_UNITS = (("_deg_s", "deg/s"), ("_m_s", "m/s"), ("_kn", "kn"), ("_deg", "deg"), ("_rpm", "rpm"),
                 ("_s", "s"), ("_m", "m"))


def _unit_of_path(path: tuple):
    """The unit of a scenario field: from its pydantic description, else from its name's suffix."""
    from steerlab.sim.scenario import Scenario

    model, field = Scenario, None
    for part in path:
        field = getattr(model, "model_fields", {}).get(part)
        if field is None:
            break
        model = field.annotation
    unit = _unit_in(field.description) if field is not None else None
    if unit:
        return unit
    for suffix, u in _SUFFIX_UNITS:
        if path[-1].endswith(suffix):
            return u
    return None


def _edges(v):
    v = np.asarray(v, float)
    if len(v) == 1:
        return np.array([v[0] - 0.5, v[0] + 0.5])
    mid = 0.5 * (v[1:] + v[:-1])
    return np.concatenate([[v[0] - (mid[0] - v[0])], mid, [v[-1] + (v[-1] - mid[-1])]])
