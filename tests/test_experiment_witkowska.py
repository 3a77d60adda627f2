"""The witkowska experiment (quick mode): rows, figures and the published numbers in place."""

import json

from steerlab.experiments import EXPERIMENTS
from steerlab.experiments.witkowska import PAPER


def test_quick_run_writes_rows_and_figures(tmp_path):
    rows = EXPERIMENTS["witkowska"].run(tmp_path, quick=True)
    assert json.loads((tmp_path / "comparison.json").read_text()) == rows
    assert {"quantity", "paper", "steerlab", "unit", "note"} <= set(rows[0])
    assert len(rows) == 2 * 6 * 4                      # loadings x controllers x indices, one speed
    assert (tmp_path / "fig_switch.png").stat().st_size > 0
    pd = [r for r in rows if r["quantity"].startswith("ballast PD M_p")][0]
    assert pd["paper"] == PAPER[("PD", "ballast")][1]
    assert all(r["note"] for r in rows)
