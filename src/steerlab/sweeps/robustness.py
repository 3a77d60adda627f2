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
from steerlab.sweeps.packed import PackedBatch
from steerlab.tuning.cost import ONLINE, metric_arrays, parse_cost

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
                   redesign: bool = False, executor=None, progress=None) -> RobustnessResult:
    """Evaluate ``metric`` (a cost expression) over the grid of ``variations``."""
    say = progress or (lambda msg: None)
    if not 1 <= len(variations) <= 3:
        raise InputError("--vary", f"give one to three --vary options, got {len(variations)}")
    if len({v.path for v in variations}) != len(variations):
        raise InputError("--vary", "a quantity is varied twice")
    expr = parse_cost(metric, "--metric")
    if expr.needs_log:
        raise InputError("--metric", f"robustness maps use the on-line metrics only: {', '.join(ONLINE)}")
    points = list(itertools.product(*(v.values for v in variations)))
    if len(points) > MAX_POINTS:
        raise InputError("--vary", f"{len(points)} grid points; allowed at most {MAX_POINTS}")
    nominal = make_condition("nominal", scenario)
    base = scenario.model_dump()
    setups = []
    for pt in points:
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
    return RobustnessResult(variations, points, expr.text, values[:-1], table, nominal_row, redesign)


def write_robustness_outputs(stage, res: RobustnessResult, scenario_name: str) -> None:
    """``robustness.json``, ``table.csv/.parquet`` and ``heatmap.png`` (or ``line.png`` for one variation)."""
    from pathlib import Path

    from steerlab.cli import dump_json
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
    fig, (ax,) = new_figure((7.0, 5.5))
    ax.grid(False)
    im = ax.pcolormesh(_edges(b.values), _edges(a.values), grid, shading="flat", cmap="viridis")
    fig.colorbar(im, ax=ax, label=res.metric)
    ax.set_xlabel(b.name)
    ax.set_ylabel(a.name)
    extra = f" (first value of {res.variations[2].name})" if len(res.variations) > 2 else ""
    ax.set_title(title + extra, parse_math=False)
    if grid.size <= 150:
        for i, av in enumerate(a.values):
            for j, bv in enumerate(b.values):
                ax.text(bv, av, f"{grid[i, j]:.3g}", ha="center", va="center", fontsize=7, color="w")
    save_figure(fig, stage / "heatmap.png")


def _edges(v):
    v = np.asarray(v, float)
    if len(v) == 1:
        return np.array([v[0] - 0.5, v[0] + 0.5])
    mid = 0.5 * (v[1:] + v[:-1])
    return np.concatenate([[v[0] - (mid[0] - v[0])], mid, [v[-1] + (v[-1] - mid[-1])]])
