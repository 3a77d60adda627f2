"""Experiment ``morawski``: runs end to end (quick) once the catalogue ship is there."""

import json

import pytest

from steerlab.errors import InputError
from steerlab.experiments import EXPERIMENTS
from steerlab.experiments import morawski
from steerlab.ships.registry import SHIPS


def test_registered():
    assert EXPERIMENTS["morawski"] is morawski


@pytest.mark.skipif(morawski.SHIP_ID in SHIPS, reason="the catalogue ship is present")
def test_without_the_ship_it_refuses_naming_the_ship(tmp_path):
    with pytest.raises(InputError, match=r"ship\.model"):
        morawski.run(tmp_path / "out", quick=True)


@pytest.mark.skipif(morawski.SHIP_ID not in SHIPS, reason="waiting for the catalogue ship")
def test_quick_run_rows_and_figures(tmp_path):
    out = tmp_path / "out"
    rows = morawski.run(out, quick=True)
    assert json.loads((out / "comparison.json").read_text()) == rows
    for f in ("table3_itae.png", "fig7_fig8_turn30.png", "fig7_fig8_rate_sweep.png", "sensitivity.png"):
        assert (out / f).stat().st_size > 10_000
    by = {r["quantity"]: r for r in rows}
    assert set(rows[0]) == {"quantity", "paper", "steerlab", "unit", "note"}
    # eq (10) as printed and steerlab's design agree (c2 = 2.15 reading)
    for q in ("H1 (proportional)", "H2 (integral)", "H3 (derivative)"):
        assert by[q]["steerlab"] == pytest.approx(by[q]["paper"], rel=1e-4)
    # Table 3's trend: ITAE grows with T_m and falls with k_m (the paper's conclusion)
    tm = [by[f"Table 3 ITAE, k_m = 0.1256, T_m = {t:g} s"]["steerlab"] for t, _ in morawski.TABLE3_TM]
    km = [by[f"Table 3 ITAE, T_m = 48.5 s, k_m = {k:g}"]["steerlab"] for k, _ in morawski.TABLE3_KM]
    assert tm[2] < tm[3] < tm[4] and km[0] > km[1] > km[2] > km[3]
    # the limiter removes the saturation of the 30 deg turn (Figs 7-8)
    assert by["Fig 8 (limiter 1.2 deg/s): time the rudder order is saturated (35 deg)"]["steerlab"] == 0.0
    assert by["Fig 7 (no limiter): time the rudder order is saturated (35 deg)"]["steerlab"] > 0.0
    assert (by["Fig 8 (limiter 1.2 deg/s): overshoot of the 30 deg turn"]["steerlab"]
            < by["Fig 7 (no limiter): overshoot of the 30 deg turn"]["steerlab"])
