"""``steerlab sea``: files, summary target vs generated, bad input."""

import json

import pytest

from steerlab.cli import main

TOML = """name = "sea-test"
seed = 2
dt = 0.5
duration = 6000.0
[ship]
model = "esso"
[controller]
type = "pid"
[environment]
wind_speed = 10.0
wind_dir_deg = 30.0
[environment.wave]
model = "{model}"
sea_state = 4
wave_angle_deg = 60.0
yaw_rate_std_deg_s = 0.2
[environment.gusts]
speed_std = 1.5
dir_std_deg = 8.0
"""


@pytest.mark.parametrize("model,series", [("spectrum", "elevation"), ("thesis", "yaw_rate")])
def test_sea_command_writes_figures_and_summary(tmp_path, model, series, capsys):
    toml = tmp_path / "s.toml"
    toml.write_text(TOML.format(model=model))
    out = tmp_path / "out"
    assert main(["sea", str(toml), "--out", str(out), "--quiet"]) == 0
    for f in ("sea_spectrum.png", "wind_rose.png", "sea_timeseries.png", "sea.csv", "sea.json"):
        assert (out / f).stat().st_size > 0
    s = json.loads((out / "sea.json").read_text())
    w = s["waves"][series]
    assert w["variance_generated"] == pytest.approx(w["variance_target"], rel=0.2)
    assert w["peak_frequency_generated_rad_s"] == pytest.approx(w["peak_frequency_target_rad_s"], rel=0.1)
    assert s["wind"]["speed_mean_m_s"] == pytest.approx(10.0, abs=0.5)
    assert s["wind"]["speed_std_m_s"] == pytest.approx(1.5, rel=0.25)
    assert s["wind"]["dir_mean_deg"] == pytest.approx(30.0, abs=3.0)
    if model == "spectrum":
        assert w["Hs_generated_m"] == pytest.approx(1.88, rel=0.05)


def test_sea_command_bad_input(tmp_path, capsys):
    toml = tmp_path / "bad.toml"
    toml.write_text(TOML.format(model="spectrum").replace("sea_state = 4", "sea_state = 12"))
    out = tmp_path / "out"
    assert main(["sea", str(toml), "--out", str(out), "--quiet"]) == 2
    assert "environment.wave.sea_state" in capsys.readouterr().err
    assert not out.exists()


def test_sea_without_wind_writes_no_wind_rose(tmp_path, capsys):
    """The default scenario (JONSWAP waves, no wind): no empty wind rose, and it says why."""
    out = tmp_path / "out"
    assert main(["sea", "--out", str(out)]) == 0
    assert not (out / "wind_rose.png").exists() and (out / "sea_spectrum.png").exists()
    assert "no wind" in capsys.readouterr().err


def test_sea_does_not_warn_about_the_autopilot(tmp_path, capsys):
    """``sea`` draws the sea: the design's warning about the law (ADRC without the wave filter in
    a spectrum) is for ``run``, which still gives it; a warning about the sea itself is kept."""
    p = tmp_path / "s.toml"
    p.write_text('[controller]\ntype = "adrc"\n[ship]\nmodel = "mss-mariner"\nspeed_kn = 25.0\n[environment.wave]\nmodel = "spectrum"\n'
                 'spectrum = "jonswap"\nsea_state = 5\n', encoding="utf-8")
    assert main(["run", str(p), "--out", str(tmp_path / "r"), "--quiet"]) in (0, 3)
    assert "chases the wave yaw" in capsys.readouterr().err
    assert main(["sea", str(p), "--out", str(tmp_path / "o"), "--quiet"]) == 0
    err = capsys.readouterr().err
    assert "chases the wave yaw" not in err and "ship.speed_kn" in err
