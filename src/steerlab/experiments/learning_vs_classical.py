r"""A learned autopilot beside the classical laws: the shipped ``policy`` against ``pid``, ``adrc``
and ``adrc+wf`` in the same seeded seas.

Not a paper reproduction: steerlab's own comparison (issue 34; docs/learning.md gives the verdict).
Set-up:

* laws: ``policy`` (the shipped network, :data:`steerlab.control.policy.SHIPPED`, trained by
  ``examples/learning/train_policy.py`` on the Esso tanker at 16 kn, eq-39 waves, course keeping
  from offsets of up to 30 deg), ``pid``, ``adrc`` and ``adrc+wf`` with their default (designed)
  gains; every law sees the same seas (the same seeds);
* ships (:data:`SHIPS`): the Esso tanker at 16 kn (the one trained on) and a second ship the
  policy never saw;
* seas (:data:`SEAS`): calm, and sea states 3 to 6 (a Bretschneider spectrum of the WMO sea
  state, :mod:`steerlab.environment.sea`, waves 45 deg off the bow);
* tasks: a 20 deg course change at 10 s, and course keeping at 0 deg (in calm water course
  keeping is trivially exact for every law, so it is run in the seas only); 300 s, dt 0.1 s;
* per run (steerlab.metrics): mean heading error ``IAE / T`` [deg], the speed-loss ``J`` =
  mean(e^2 + 0.1 delta^2) [deg^2], ITAE [deg s^2], rudder travel [deg] and reversals; per
  condition the mean over ``n_seeds`` seeds with its 95 % Student-t interval
  (:func:`steerlab.sweeps.montecarlo.confidence_interval`).

Reproducible from ``seed``: run ``i`` of every condition uses sea seed ``seed + i``.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Callable, Optional

import numpy as np

NAME = "learning-vs-classical"
DESCRIPTION = ("A learned autopilot (the shipped PPO policy) beside pid, adrc and adrc+wf in the same "
               "seeded seas: calm and sea states 3-6, course change and keeping, two ships")

LAWS = ("policy", "pid", "adrc", "adrc+wf")
SHIPS = (("esso", 16.0), ("mss-tanker", 16.0))
SEAS = {"calm": None, "ss3": 3, "ss4": 4, "ss5": 5, "ss6": 6}
TASKS = ("course_change", "course_keeping")
METRICS = (("mean_abs_e_deg", "deg", "mean |heading error|"), ("speed_loss_J", "deg^2", "J = mean(e^2 + 0.1 delta^2)"),
           ("itae_deg_s2", "deg s^2", "ITAE"), ("rudder_travel_deg", "deg", "rudder travel"),
           ("rudder_reversals", "-", "rudder reversals"))
DURATION, DT, CHANGE_T, CHANGE_DEG = 300.0, 0.1, 10.0, 20.0
SEED = 2026


def scenario(law: str, ship: str, speed_kn: float, sea: Optional[int], task: str, seed: int,
             duration: float = DURATION):
    """The scenario of one run (module docstring)."""
    from steerlab.sim.scenario import scenario_from_dict

    env = {} if sea is None else {"wave": {"model": "spectrum", "spectrum": "bretschneider", "sea_state": sea,
                                           "wave_angle_deg": 45.0}}
    changes = [{"t": CHANGE_T, "psi_deg": CHANGE_DEG}] if task == "course_change" else []
    return scenario_from_dict({"name": f"lvc-{law}-{ship}-{sea}-{task}", "seed": seed, "dt": DT, "duration": duration,
                               "ship": {"model": ship, "speed_kn": speed_kn}, "controller": {"type": law},
                               "environment": env, "guidance": {"psi0_deg": 0.0, "changes": changes}})


def conditions(quick: bool = False):
    """``(ship, speed_kn, sea name, sea state, task)`` of every condition (quick: the first ship,
    calm and sea state 5)."""
    ships = SHIPS[:1] if quick else SHIPS
    seas = {k: SEAS[k] for k in ("calm", "ss5")} if quick else SEAS
    for ship, kn in ships:
        for sea_name, sea in seas.items():
            for task in TASKS:
                if sea is None and task == "course_keeping":
                    continue
                yield ship, kn, sea_name, sea, task


def measure(n_seeds: int = 10, seed: int = SEED, quick: bool = False, duration: float = DURATION,
            progress: Optional[Callable[[str], None]] = None, laws=LAWS) -> list[dict]:
    """One record per (condition, law): each metric's per-run values and their mean and 95 % interval."""
    from steerlab.sim.batch import simulate_batch
    from steerlab.sim.setup import build
    from steerlab.sweeps.montecarlo import confidence_interval

    out = []
    conds = list(conditions(quick))
    for c, (ship, kn, sea_name, sea, task) in enumerate(conds):
        for law in laws:
            setups = [build(scenario(law, ship, kn, sea, task, seed + i, duration)) for i in range(n_seeds)]
            m = simulate_batch(setups).metrics
            vals = {"mean_abs_e_deg": np.asarray(m["iae_deg_s"], float) / duration}
            for k, _, _ in METRICS[1:]:
                vals[k] = np.asarray(m[k], float)
            rec = {"ship": ship, "speed_kn": kn, "sea": sea_name, "task": task, "law": law, "n": n_seeds}
            for k, v in vals.items():
                mean, lo, hi = confidence_interval(v)
                rec[k] = {"mean": mean, "ci95": [lo, hi], "runs": v.tolist()}
            out.append(rec)
        if progress is not None:
            progress(f"condition {c + 1}/{len(conds)}: {ship} {sea_name} {task}")
    return out


def verdict(records: list[dict]) -> dict:
    """Where the policy wins and loses: per metric, the conditions where its mean is the lowest of
    the four laws, and those where its interval lies wholly above the best classical law's."""
    by = {}
    for r in records:
        by.setdefault((r["ship"], r["sea"], r["task"]), {})[r["law"]] = r
    out = {}
    for k, _, _ in METRICS:
        best, worse = [], []
        for cond, laws in by.items():
            if "policy" not in laws:
                continue
            pol = laws["policy"][k]
            classical = [laws[w][k] for w in LAWS[1:] if w in laws]
            top = min(classical, key=lambda s: s["mean"])
            if pol["mean"] < top["mean"]:
                best.append(" ".join(cond))
            lo = pol["ci95"][0] if np.isfinite(pol["ci95"][0]) else pol["mean"]
            hi = top["ci95"][1] if np.isfinite(top["ci95"][1]) else top["mean"]
            if lo > hi:
                worse.append(" ".join(cond))
        out[k] = {"policy_best_in": best, "policy_worse_in": worse, "conditions": len(by)}
    return out


def run(out_dir, progress=None, quick: bool = False, n_seeds: Optional[int] = None, seed: int = SEED) -> list[dict]:
    """Run the comparison; write ``records.json`` and ``comparison.json`` (rows: one per condition,
    law and metric: the mean, with the 95 % interval and n in the note) into ``out_dir``."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    n = n_seeds if n_seeds is not None else (3 if quick else 10)
    records = measure(n, seed, quick, progress=progress)
    rows = []
    for r in records:
        for k, unit, label in METRICS:
            s = r[k]
            rows.append({"quantity": f"{r['ship']} {r['sea']} {r['task']}: {label} ({r['law']})", "paper": "-",
                         "steerlab": s["mean"], "unit": unit,
                         "note": f"95% CI [{s['ci95'][0]:.4g}, {s['ci95'][1]:.4g}], n = {r['n']}, seeds "
                                 f"{seed}..{seed + r['n'] - 1}"})
    v = verdict(records)
    (out_dir / "records.json").write_text(json.dumps({"seed": seed, "n_seeds": n, "records": records,
                                                      "verdict": v}, indent=1))
    (out_dir / "comparison.json").write_text(json.dumps(rows, indent=1))
    return rows
