"""Run report: PNG figures, self-contained HTML page, terminal metrics table."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from steerlab.metrics import METRIC_UNITS, compute_metrics
from steerlab.report import (FIGURE_NAMES, format_metrics_table, format_value, unwrapped_heading_deg,
                             write_run_figures, write_run_report)
from steerlab.sim.engine import simulate
from steerlab.sim.scenario import default_scenario

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def run():
    """A short default run (course change at t = 100 s, JONSWAP sea state 6): scenario, result, metrics."""
    scenario = default_scenario().replace(duration=300.0)
    result = simulate(scenario)
    return scenario, result, compute_metrics(result)


@pytest.fixture(scope="module")
def report(run, tmp_path_factory):
    scenario, result, metrics = run
    out = tmp_path_factory.mktemp("report")
    path = write_run_report(out, result, metrics, scenario=scenario,
                            title="run <script>alert('x')</script> & co")
    return out, path, path.read_text(encoding="utf-8")


def test_report_writes_png_figures(report):
    out, _, _ = report
    for name in FIGURE_NAMES:
        p = out / name
        assert p.is_file(), name
        data = p.read_bytes()
        assert data[:8] == PNG_MAGIC, name
        assert len(data) > 10_000, f"{name} suspiciously small: {len(data)} bytes"


def test_figures_only_the_four(report):
    out, _, _ = report
    assert sorted(p.name for p in out.glob("*.png")) == sorted(FIGURE_NAMES)
    assert set(FIGURE_NAMES) == {"heading.png", "rudder.png", "yaw_rate.png", "track.png"}


def test_write_run_figures_returns_paths(run, tmp_path):
    _, result, _ = run
    paths = write_run_figures(tmp_path / "sub" / "dir", result, title="t")
    assert [p.name for p in paths] == list(FIGURE_NAMES)
    assert all(p.is_file() and p.parent == tmp_path / "sub" / "dir" for p in paths)


def test_report_html_links_images_and_lists_metrics(report, run):
    out, path, text = report
    scenario, result, metrics = run
    assert path == out / "report.html" and path.is_file()
    assert text.startswith("<!DOCTYPE html>")
    for name in FIGURE_NAMES:
        assert f'<img src="{name}"' in text
    # every <img> has alt text
    imgs = re.findall(r"<img [^>]*>", text)
    assert len(imgs) == 4 and all('alt="' in tag and 'alt=""' not in tag for tag in imgs)
    for name in metrics:
        assert f"<td>{name}</td>" in text, name
    assert "not settled" in text or "n/a" in text or all(v is not None for v in metrics.values())
    # meta and scenario
    assert scenario.name in text and scenario.description in text
    for key in ("ship", "controller", "engine", "seed", "dt", "duration"):
        assert f"<th>{key}</th>" in text, key
    assert "<pre>" in text and "&quot;T_settle&quot;" in text


def test_report_has_no_internet_assets(report):
    _, _, text = report
    assert "http://" not in text and "https://" not in text
    assert "<script" not in text.lower()
    assert "<link" not in text.lower()


def test_report_escapes_title(report):
    _, _, text = report
    assert "<script>" not in text
    assert "&lt;script&gt;alert(&#x27;x&#x27;)&lt;/script&gt; &amp; co" in text


def test_report_default_title_without_scenario(run, tmp_path):
    _, result, metrics = run
    path = write_run_report(tmp_path, result, metrics)
    text = path.read_text(encoding="utf-8")
    assert f"<h1>{result.meta['name']}</h1>" in text
    assert "<pre>" not in text
    assert "<th>dt</th><td>0.1 s</td>" in text
    assert "<th>duration</th><td>300 s</td>" in text


def test_format_metrics_table_one_line_per_metric(run):
    _, _, metrics = run
    table = format_metrics_table(metrics)
    lines = table.splitlines()
    assert len(lines) == len(metrics)
    for line, (name, value) in zip(lines, metrics.items()):
        assert line.split()[0] == name
        unit = METRIC_UNITS.get(name, "")
        if unit:
            assert line.endswith(unit)
    # every metric has a unit, and the unit column starts at one position (values aligned)
    assert set(metrics) <= set(METRIC_UNITS)
    assert len({line.rfind("  ") for line in lines}) == 1


def test_format_metrics_table_missing_values():
    table = format_metrics_table({"overshoot_pct": 3.0, "settling_time_2pct_s": None,
                                  "settling_time_1deg_s": None, "rise_time_s": None,
                                  "iae_deg_s": float("nan"), "rudder_reversals": 7})
    rows = {line.split()[0]: line for line in table.splitlines()}
    assert "not settled" in rows["settling_time_2pct_s"]
    assert "not settled" in rows["settling_time_1deg_s"]
    assert "n/a" in rows["rise_time_s"]
    assert "n/a" in rows["iae_deg_s"]
    assert rows["rudder_reversals"].split()[1] == "7"
    # no set-point change: a missing 2 % settling time is not applicable rather than unsettled
    table = format_metrics_table({"overshoot_pct": None, "settling_time_2pct_s": None,
                                  "settling_time_1deg_s": None})
    assert "n/a" in table.splitlines()[1] and "n/a" in table.splitlines()[2]
    assert format_metrics_table({}) == ""


@pytest.mark.parametrize("value, text", [
    (None, "n/a"), (float("nan"), "n/a"), (0.0, "0"), (3, "3"), (np.int64(12), "12"),
    (1.23456, "1.235"), (1234.56, "1235"), (0.0123456, "0.01235"), (123456.7, "123457"),
    (np.float64(-2.5), "-2.500"), (1.5e-6, "1.500e-06"),
])
def test_format_value(value, text):
    assert format_value(value) == text


def test_unwrapped_heading_is_continuous_across_north():
    # 359 deg -> 1 deg (through north) must plot as a 2 deg change, not a 358 deg jump
    psi = np.radians(np.array([358.0, 359.0, 0.5, 1.0]))
    psi = np.arctan2(np.sin(psi), np.cos(psi))        # wrapped to (-pi, pi]
    ref = np.radians(np.array([359.0, 1.0, 1.0, 1.0]))  # in [0, 2 pi)
    psi_d, ref_d = unwrapped_heading_deg(psi, ref)
    assert np.max(np.abs(np.diff(psi_d))) < 2.0
    assert np.max(np.abs(np.diff(ref_d))) < 3.0
    # same branch: psi starts next to psi_ref, not a full turn away
    assert abs(psi_d[0] - ref_d[0]) < 180.0
    assert math.isclose(ref_d[-1] - psi_d[-1], 0.0, abs_tol=1e-9)
