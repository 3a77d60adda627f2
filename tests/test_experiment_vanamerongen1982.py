"""Experiment vanamerongen1982-table5-1 (quick mode): rows, figures, honest proxy notes."""

import json

from steerlab.experiments import EXPERIMENTS


def test_table5_1_quick(tmp_path):
    mod = EXPERIMENTS["vanamerongen1982-table5-1"]
    rows = mod.run(tmp_path, quick=True)
    assert json.loads((tmp_path / "comparison.json").read_text()) == rows
    assert (tmp_path / "table5_1.png").stat().st_size > 0
    J = {r["quantity"]: r["steerlab"] for r in rows if r["unit"] == "%"}
    assert len(J) == 4 and all(v > 0 for v in J.values())
    assert all("proxy" in r["note"] for r in rows)
    high_raw = J["loss of speed, high gains (Kp = 3.0), filter no"]
    high_wf = J["loss of speed, high gains (Kp = 3.0), filter yes"]
    low_raw = J["loss of speed, low gains (Kp = 0.5), filter no"]
    assert high_wf < high_raw and low_raw < high_raw        # the thesis' qualitative ordering
