"""The witkowska-ga experiment (quick mode): pymoo GA through steerlab.tuning on the batch engine."""

import json

import numpy as np

from steerlab.experiments import EXPERIMENTS
from steerlab.experiments.witkowska_ga import BOUNDS, CONTROLLERS, LOADINGS, PAPER_SETTINGS


def test_quick_run_rows_bounds_replay_and_elitism(tmp_path):
    rows = EXPERIMENTS["witkowska-ga"].run(tmp_path, quick=True)
    assert json.loads((tmp_path / "comparison.json").read_text()) == rows
    n_fields = sum(len(f) for _, f, _ in CONTROLLERS.values())
    assert len(rows) == len(LOADINGS) * (n_fields + 2 * len(CONTROLLERS) + 1)
    assert all(r["note"] and {"quantity", "paper", "steerlab", "unit", "note"} <= set(r) for r in rows)
    for name in ("fig_ga_steps_ballast.png", "fig_ga_steps_full.png", "fig_ga_convergence.png"):
        assert (tmp_path / name).stat().st_size > 0
    # the published numbers are in place (Table 3: B ballast k2; Table 5: PD full ISE)
    k2 = next(r for r in rows if r["quantity"] == "ballast B k_2 (GA-tuned)")
    assert k2["paper"] == PAPER_SETTINGS[("B", "ballast")][0][1] == 184.252
    ise = next(r for r in rows if r["quantity"] == "full PD ISE (30) of the GA-tuned setting")
    assert ise["paper"] == 0.08804

    rank = next(r for r in rows if r["quantity"] == "ballast ranking by tuned ISE (30)")
    assert rank["paper"] == "B < A < SM < PD"                 # Tables 3 and 5
    assert sorted(rank["steerlab"].split(" < ")) == sorted(CONTROLLERS)

    runs = json.loads((tmp_path / "tuning.json").read_text())["runs"]
    assert len(runs) == len(LOADINGS) * len(CONTROLLERS)
    for r in runs:
        for f, v in r["best"].items():
            lo, hi = BOUNDS[f]
            assert lo <= v <= hi
        # the tuner's cost equals an independent run built from the scenario with the best setting
        assert np.isfinite(r["J_best"]) and r["J_best"] > 0
        assert abs(r["J_replayed"] - r["J_best"]) <= 1e-9 * r["J_best"]
        # GA survival is elitist: the best cost so far never rises
        best = [h["best"] for h in r["history"]]
        assert all(b1 <= b0 for b0, b1 in zip(best, best[1:]))
        assert best[-1] == r["J_best"]
