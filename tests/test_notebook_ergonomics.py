"""Plots into a given Axes, Result.plot, Result.to_pandas and the batch's per-run DataFrame."""

import numpy as np
import pytest

from steerlab.sim.engine import simulate
from steerlab.units import rad

TURN = {"changes": [{"t": 5.0, "psi_deg": 20.0}]}


@pytest.fixture(scope="module")
def res():
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).parent))
    from conftest import make_scenario

    return simulate(make_scenario(duration=30.0, guidance=TURN, environment={"waves": True}))


def test_draw_functions_draw_into_the_given_axes(res):
    from matplotlib.figure import Figure

    from steerlab.report import draw_heading, draw_rudder, draw_track, draw_yaw_rate

    fig = Figure()
    axes = fig.subplots(2, 2)
    for draw, ax in zip((draw_heading, draw_rudder, draw_yaw_rate, draw_track), axes.ravel()):
        assert draw(ax, res, "mine") is ax
    heading_lines = axes[0, 0].get_lines()
    np.testing.assert_allclose(heading_lines[1].get_ydata(), np.degrees(res.psi))   # psi in degrees
    assert axes[0, 0].get_ylabel() == "heading [deg]" and "mine" in axes[0, 0].get_title()
    assert len(axes[0, 1].get_lines()) >= 3                                          # order, actual, zero


def test_plot_result_uses_given_axes(res):
    from matplotlib.figure import Figure

    from steerlab.report import plot_result

    axes = Figure().subplots(3, 1)
    assert list(plot_result(res, axes)) == list(axes)
    assert axes[2].get_ylabel() == "yaw rate [deg/s]"


def test_to_pandas_has_time_index_and_unit_columns(res):
    pd = pytest.importorskip("pandas")
    df = res.to_pandas()
    assert isinstance(df, pd.DataFrame) and df.index.name == "time [s]"
    assert len(df) == len(res.time) and df.index[-1] == pytest.approx(30.0)
    np.testing.assert_array_equal(df["psi [rad]"].to_numpy(), res.psi)
    np.testing.assert_array_equal(df["delta_cmd [rad]"].to_numpy(), res.delta_cmd)
    assert "d_rudder [rad]" in df.columns and df["d_rudder [rad]"].abs().max() > 0.0


def test_batch_to_pandas_one_row_per_run():
    pytest.importorskip("pandas")
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).parent))
    from conftest import make_scenario

    from steerlab.sim.batch import simulate_batch, vary_controller
    from steerlab.sim.setup import build

    s = build(make_scenario(duration=30.0, guidance=TURN))
    rows = np.tile(s.pc, (3, 1))
    rows[:, 0] *= [0.5, 1.0, 1.5]
    df = simulate_batch(vary_controller(s, rows)).to_pandas()
    assert list(df.index) == [0, 1, 2] and df.index.name == "run"
    assert {"iae_deg_s", "psi_final"} <= set(df.columns)
    assert df["psi_final"].iloc[2] > df["psi_final"].iloc[0] > rad(1.0)    # more Kp, further turned
