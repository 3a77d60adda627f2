"""The Zwierzewicz et al. (2021) reproduction runs end to end (quick mode) and reports sanely."""

import json
from pathlib import Path

import pytest

from steerlab.experiments import EXPERIMENTS
from steerlab.experiments import zwierzewicz2021 as zw

REQUIRED_KEYS = {"quantity", "paper", "steerlab", "unit", "note"}
FIGURES = ("fig2_step_responses.png", "fig2b_printed_readings.png", "fig3_constant_disturbance.png",
           "fig4_coloured_noise.png", "fig5_noise_response.png", "fig6_adrc_vs_pid.png")
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def quick_run(tmp_path_factory):
    """``(out, rows, messages)`` of one quick run, made once per test session (the tests of
    this module may run in several pytest-xdist workers)."""
    from conftest import once_per_session

    def make(out: Path) -> dict:
        messages: list = []
        rows = zw.run(out, progress=messages.append, quick=True)
        return {"out": str(out), "rows": rows, "messages": messages}

    made = once_per_session(tmp_path_factory, "zwierzewicz2021-quick", make)
    return Path(made["out"]), made["rows"], made["messages"]


def _find(rows, prefix):
    hits = [r for r in rows if r["quantity"].startswith(prefix)]
    assert len(hits) == 1, f"expected one row starting with {prefix!r}, got {[r['quantity'] for r in hits]}"
    return hits[0]


def test_registered():
    assert EXPERIMENTS["zwierzewicz2021"] is zw
    assert isinstance(zw.DESCRIPTION, str) and "\n" not in zw.DESCRIPTION


def test_comparison_json_matches_return_value(quick_run, request):
    out, rows, messages = quick_run
    # a test of a fixture made once per session shares that fixture's pytest-xdist worker (conftest)
    group = request.node.get_closest_marker("xdist_group")
    assert group is not None and group.args == ("test_experiment_zwierzewicz2021.quick_run",)
    assert request.node.get_closest_marker("realtime") is None
    with open(out / "comparison.json", encoding="utf-8") as fh:
        data = json.load(fh)
    assert data == rows
    assert len(data) >= 15
    for row in data:
        assert set(row) == REQUIRED_KEYS, row
        assert isinstance(row["quantity"], str) and row["quantity"]
        assert isinstance(row["note"], str) and row["note"]
        assert row["steerlab"] is None or isinstance(row["steerlab"], float), row
    assert len(messages) >= 5 and all(isinstance(m, str) for m in messages)


def test_model_constants(quick_run):
    _, rows, _ = quick_run
    b2_est = _find(rows, "b2 (c0) by eq (29)")
    assert b2_est["paper"] == -9.18e-4
    assert b2_est["steerlab"] == pytest.approx(-9.18e-4, rel=5e-3)
    b2_exact = _find(rows, "b2 exact from the linearisation")
    assert b2_exact["paper"] == -7.54e-4
    assert b2_exact["steerlab"] == pytest.approx(-7.54e-4, rel=5e-3)
    rpm = _find(rows, "propeller rate for 16 kn")
    assert rpm["unit"] == "rpm" and abs(rpm["steerlab"] - 80.0) < 1.0
    assert _find(rows, "open-loop linear model")["steerlab"] > 0.0       # course-unstable
    assert _find(rows, "zero-dynamics pole a0")["steerlab"] < 0.0        # stable zero dynamics


def test_figures_are_pngs(quick_run):
    out, _, _ = quick_run
    for name in FIGURES:
        path = out / name
        assert path.is_file(), name
        with open(path, "rb") as fh:
            assert fh.read(8) == PNG_MAGIC, name
        assert path.stat().st_size > 10_000, name


def test_constant_disturbance_is_rejected(quick_run):
    """ADRC's integral action (the ESO's x3) removes a constant disturbance completely."""
    _, rows, _ = quick_run
    final = _find(rows, "steady-state heading error, ADRC")
    assert final["paper"] == 0.0
    assert abs(final["steerlab"]) < 0.2
    peak = _find(rows, "max heading deviation, ADRC")
    assert 1.0 < peak["steerlab"] < 35.0                # the disturbance does move the ship
    settle = _find(rows, "settling within 1 deg after onset, ADRC")
    assert settle["steerlab"] is not None and settle["steerlab"] > 0.0


def test_step_responses_settle_and_printed_law_does_not(quick_run):
    _, rows, _ = quick_run
    for T in zw.T_SETTLES:
        row = _find(rows, f"fig 2: 2% settling time, T_settle = {T:g} s")
        assert row["paper"] == T
    # nominal T_settle = 150 s settles within the quick run
    assert _find(rows, "fig 2: 2% settling time, T_settle = 150 s")["steerlab"] is not None
    # the printed +Kd x2 law swings far beyond the 20 deg change (unstable, rudder-bounded)
    assert _find(rows, "fig 2b: max |heading error| with printed law")["steerlab"] > 30.0


def test_noise_heading_deviation_is_small(quick_run):
    _, rows, _ = quick_run
    assert _find(rows, "heading deviation std under coloured noise")["steerlab"] < 0.5
