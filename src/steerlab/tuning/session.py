"""One tuning job end to end: conditions -> parameter map -> optimiser -> result files.

:func:`tune` is what ``steerlab tune`` calls; it is usable from Python as well::

    from steerlab.tuning.session import TuneSpec, tune
    spec = TuneSpec(scenario, controller="pid", params=["kp", "kd", "ki"],
                    bounds=[(0.5, 10), (5, 100), (0, 0.05)], costs=["itae + 0.5*travel"],
                    n_seeds=4, method="de", generations=40, pop_size=30)
    outcome = tune(spec)                         # TuneOutcome: result, evaluator, summary dict
    write_tuning_outputs(out_dir, outcome)       # result.json, history/front tables, figure
"""

from __future__ import annotations

import hashlib
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from steerlab.metrics import METRIC_UNITS
from steerlab.sweeps.conditions import condition_set
from steerlab.sweeps.executors import LocalExecutor
from steerlab.costs import ONLINE, PENALTY, parse_cost
from steerlab.tuning.evaluator import PopulationEvaluator
from steerlab.tuning.optimisers import TuningResult, run_optimiser
from steerlab.tuning.params import build_param_map


@dataclass
class TuneSpec:
    """Everything a tuning job needs (SI inside; the scenario carries the degree edges)."""

    scenario: object
    params: list
    bounds: object                  # (d, 2)
    costs: list = field(default_factory=lambda: ["J"])
    controller: str | None = None   # default: the scenario's controller
    method: str = "de"
    generations: int = 50
    pop_size: int = 30
    seed: int = 0
    n_seeds: int = 1
    speeds_kn: tuple = ()
    wave_powers: tuple = ()
    variants: tuple = ()
    aggregate: str = "mean"
    lam: float = 0.1
    checkpoint: str | None = None
    checkpoint_mode: str = "auto"          # auto, resume or fresh (optimisers.CHECKPOINT_MODES)


@dataclass
class TuneOutcome:
    spec: TuneSpec
    result: TuningResult
    evaluator: PopulationEvaluator
    summary: dict
    wall_s: float


def with_controller(scenario, name: str | None):
    """The scenario with ``[controller]`` of type ``name`` (its defaults) unless it already is one."""
    if name is None or scenario.controller.type == name:
        return scenario
    from steerlab.control.registry import get_controller

    get_controller(name)  # InputError naming controller.type when unknown
    return scenario.replace(controller={"type": name})


def problem_key(spec: TuneSpec, conditions) -> dict:
    """What identifies a tuning problem (a checkpoint resumes only the same problem)."""
    h = hashlib.sha256()
    for c in conditions:
        h.update(c.scenario.model_dump_json().encode())
    return {"conditions": h.hexdigest(), "params": list(spec.params),
            "bounds": np.asarray(spec.bounds, float).round(15).tolist(), "costs": list(spec.costs),
            "aggregate": spec.aggregate, "lambda": float(spec.lam)}


def tune(spec: TuneSpec, executor=None, progress=None) -> TuneOutcome:
    """Run the tuning job (see the module docstring)."""
    say = progress or (lambda msg: None)
    costs = [parse_cost(c, "--cost") for c in spec.costs]
    scenario = with_controller(spec.scenario, spec.controller)
    conditions = condition_set(scenario, spec.n_seeds, spec.speeds_kn, spec.wave_powers, spec.variants)
    pm = build_param_map(conditions, spec.params, np.asarray(spec.bounds, dtype=float))
    ev = PopulationEvaluator(conditions, pm, costs, spec.lam, spec.aggregate, executor or LocalExecutor())
    mode = "packed directly" if pm.all_direct else "designed per candidate (build())"
    say(f"{len(conditions)} condition(s) x population {spec.pop_size}; parameters "
        f"{', '.join(f'{n}->{f}' for n, f in zip(pm.names, pm.fields))} {mode}; "
        f"executor {ev.executor.name}; first generation compiles the loop (a few seconds)")
    t0 = time.perf_counter()
    result = run_optimiser(ev, spec.method, spec.generations, spec.pop_size, spec.seed,
                           spec.checkpoint, problem_key(spec, conditions), say,
                           checkpoint_mode=spec.checkpoint_mode)
    wall = time.perf_counter() - t0
    summary = _summary(spec, conditions, ev, result, wall)
    return TuneOutcome(spec, result, ev, summary, wall)


def _best_metrics(ev: PopulationEvaluator, x) -> list[dict]:
    """All on-line metrics of the best candidate, per condition."""
    from steerlab.costs import LOGGED

    names = set(ONLINE) | (set(LOGGED) if ev.needs_log else set())
    saved, ev.names = ev.names, names
    try:
        m = ev.metrics(np.atleast_2d(x))
    finally:
        ev.names = saved
    return [{"condition": c.label, **{k: float(m[k][0, i]) for k in sorted(names)}}
            for i, c in enumerate(ev.conditions)]


BOUND_TOLERANCE = 1e-3
"""A best parameter within this fraction of its range from a bound is reported as on the bound."""


def tuning_warnings(pm, r: TuningResult) -> list[str]:
    """Warnings about the result: a best parameter on a bound of its range (the optimum may lie
    outside: widen the bounds), and a best cost of :data:`PENALTY` or more (every candidate failed)."""
    out = []
    for name, (lo, hi), v in zip(pm.names, pm.bounds, np.asarray(r.x, dtype=float)):
        tol = BOUND_TOLERANCE * (hi - lo)
        if hi > lo and (v - lo <= tol or hi - v <= tol):
            side, b = ("lower", lo) if v - lo <= tol else ("upper", hi)
            out.append(f"{name}: the optimum {v:.6g} is on its {side} bound {b:g}; the best value may lie "
                       "outside the bounds (widen them)")
    if r.front_x is None and np.any(np.asarray(r.f, dtype=float) >= PENALTY):
        out.append("cost: every candidate failed (diverged or undefined cost); the result means nothing")
    return out


def _summary(spec, conditions, ev, r: TuningResult, wall) -> dict:
    pm = ev.param_map
    out = {
        "scenario": spec.scenario.name,
        "controller": conditions[0].scenario.controller.type,
        "method": r.method,
        "costs": list(spec.costs),
        "aggregate": spec.aggregate,
        "lambda": spec.lam,
        "parameters": [{"name": n, "field": f, "lower": float(lo), "upper": float(hi),
                        "mapping": "direct" if d is not None else "designed"}
                       for n, f, (lo, hi), d in zip(pm.names, pm.fields, pm.bounds, pm.direct)],
        "conditions": [c.label for c in conditions],
        "seed": spec.seed,
        "generations": r.n_generations,
        "pop_size": spec.pop_size,
        "n_simulations": r.n_sims,
        "steps_per_simulation": conditions[0].setup.n_steps,
        "resumed_from_generation": r.resumed_from,
        "wall_s": wall,
        "best": {"parameters": pm.values_dict(r.x), "costs": [float(v) for v in r.f]},
        "best_metrics_per_condition": _best_metrics(ev, r.x),
        "metric_units": {k: (METRIC_UNITS.get(v[0], v[1]) if v[0] else v[1]) for k, v in ONLINE.items()},
        "history": r.history,
    }
    warnings = tuning_warnings(pm, r)
    if warnings:
        out["warnings"] = warnings
    if r.front_x is not None:
        out["front"] = [{**pm.values_dict(x), **{f"cost{j}": float(v) for j, v in enumerate(f)}}
                        for x, f in zip(r.front_x, r.front_f)]
    return out


def write_tuning_outputs(stage: Path, outcome: TuneOutcome) -> list[Path]:
    """``result.json``, ``history.csv/.parquet``, ``front.csv/.parquet`` (NSGA-II) and a figure."""
    from steerlab.outputs import dump_json
    from steerlab.sweeps.tables import new_figure, save_figure, write_table

    stage = Path(stage)
    s = outcome.summary
    r = outcome.result
    dump_json(s, stage / "result.json")
    paths = [stage / "result.json"]
    if r.history:
        keys = list(r.history[0])
        paths += write_table(stage, "history", {k: [h.get(k) for h in r.history] for k in keys})
    title = f"{s['scenario']}: {s['controller']} by {s['method']}"
    if r.front_x is not None:
        cols = {n: r.front_x[:, j] for j, n in enumerate(r.names)}
        cols.update({f"cost{j}": r.front_f[:, j] for j in range(r.front_f.shape[1])})
        paths += write_table(stage, "front", cols)
        fig, (ax,) = new_figure()
        ax.plot(r.front_f[:, 0], r.front_f[:, 1], "o-", ms=4)
        ax.set_xlabel(s["costs"][0])
        ax.set_ylabel(s["costs"][1])
        ax.set_title(f"{title} - Pareto front ({len(r.front_f)} points)", parse_math=False)
        paths.append(save_figure(fig, stage / "pareto_front.png"))
    else:
        fig, (ax,) = new_figure()
        g = [h["generation"] for h in r.history]
        ax.plot(g, [h["best"] for h in r.history], label="best")
        ax.plot(g, [h["mean"] for h in r.history], label="population mean", alpha=0.6)
        if min(min(h["best"] for h in r.history), min(h["mean"] for h in r.history)) > 0:
            ax.set_yscale("log")
        ax.set_xlabel("generation")
        ax.set_ylabel(s["costs"][0])
        ax.legend()
        ax.set_title(f"{title} - convergence", parse_math=False)
        paths.append(save_figure(fig, stage / "convergence.png"))
    return paths
