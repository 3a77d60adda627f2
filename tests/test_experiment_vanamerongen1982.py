"""Experiment vanamerongen1982-table5-1 (quick mode): de-keizer loss of speed and criterion (3.1)."""

import json

import pytest

from steerlab.experiments import EXPERIMENTS
from steerlab.experiments.vanamerongen1982_table5_1 import _scenario, loss_of_speed_pct
from steerlab.sim.engine import simulate
from steerlab.units import knots_to_ms


def test_table5_1_quick(tmp_path):
    mod = EXPERIMENTS["vanamerongen1982-table5-1"]
    rows = mod.run(tmp_path, quick=True)
    assert json.loads((tmp_path / "comparison.json").read_text()) == rows
    assert (tmp_path / "table5_1.png").stat().st_size > 0
    loss = {r["quantity"]: r["steerlab"] for r in rows if r["quantity"].startswith("loss of speed")}
    J = {r["quantity"]: r["steerlab"] for r in rows if r["quantity"].startswith("criterion (3.1) J")}
    assert len(loss) == 4 and len(J) == 4
    assert all(0.0 < v < 5.0 for v in loss.values())          # a ship-model loss, in percent
    assert all(v > 0 for v in J.values())
    assert all("de-keizer" in r["note"] for r in rows)
    # the thesis' qualitative ordering of criterion (3.1)
    high_raw = J["criterion (3.1) J, high gains (Kp = 3.0), filter no"]
    high_wf = J["criterion (3.1) J, high gains (Kp = 3.0), filter yes"]
    low_raw = J["criterion (3.1) J, low gains (Kp = 0.5), filter no"]
    assert high_wf < high_raw and low_raw < high_raw
    # higher gains turn the ship more in the waves: more loss of speed in the model too
    assert loss["loss of speed, low gains (Kp = 0.5), filter no"] < loss["loss of speed, high gains (Kp = 3.0), filter no"]


def test_loss_of_speed_is_zero_on_a_calm_straight_course():
    s = _scenario("low", False, 100.0).replace(environment={"constant_rudder_deg": 0.0, "waves": False})
    res = simulate(s, "compiled")
    assert loss_of_speed_pct(res, knots_to_ms(12.0)) == pytest.approx(0.0, abs=1e-12)
