"""The command line: outputs, determinism, and bad input (exit 2, nothing half-written)."""

import json
import math

import pytest

from steerlab.cli import main

SHORT = """
name = "short"
seed = 3
dt = 0.1
duration = {duration}
[ship]
model = "{ship}"
speed_kn = 16.0
[gear]
delta_max_deg = {dmax}
[controller]
type = "{ctrl}"
[guidance]
psi0_deg = 0.0
changes = [{{ t = 20.0, psi_deg = 10.0 }}]
[environment]
waves = true
"""


def _scenario(tmp_path, name="s.toml", duration="300.0", ship="esso", ctrl="adrc", dmax="35.0"):
    p = tmp_path / name
    p.write_text(SHORT.format(duration=duration, ship=ship, ctrl=ctrl, dmax=dmax))
    return p


def test_run_writes_all_outputs(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["run", str(_scenario(tmp_path)), "--out", str(out), "--quiet", "--parquet"]) == 0
    for name in ("metrics.json", "timeseries.csv", "timeseries.parquet", "report.html",
                 "heading.png", "rudder.png", "yaw_rate.png", "track.png"):
        assert (out / name).stat().st_size > 0, name
    m = json.loads((out / "metrics.json").read_text())
    assert m["scenario"] == "short"
    assert m["units"]["iae_deg_s"] == "deg s"
    assert math.isfinite(m["metrics"]["iae_deg_s"]) and m["metrics"]["iae_deg_s"] > 0
    header = (out / "timeseries.csv").read_text().splitlines()[0]
    assert header.startswith("time [s],x_n [m],y_e [m],psi [rad]")
    assert len((out / "timeseries.csv").read_text().splitlines()) == 3002  # header + 3001 rows
    assert "iae_deg_s" in capsys.readouterr().out
    assert not list(tmp_path.glob(".out.partial-*"))


def test_same_scenario_same_bytes(tmp_path):
    s = _scenario(tmp_path)
    for d in ("a", "b"):
        assert main(["run", str(s), "--out", str(tmp_path / d), "--quiet"]) == 0
    assert (tmp_path / "a" / "timeseries.csv").read_bytes() == (tmp_path / "b" / "timeseries.csv").read_bytes()
    assert main(["run", str(s), "--out", str(tmp_path / "c"), "--quiet", "--seed", "4"]) == 0
    assert (tmp_path / "a" / "timeseries.csv").read_bytes() != (tmp_path / "c" / "timeseries.csv").read_bytes()


@pytest.mark.parametrize("kwargs, field", [
    ({"ship": "titanic"}, "ship.model"),
    ({"ctrl": "fuzzy"}, "controller"),
    ({"duration": "0.0"}, "duration"),
    ({"duration": "-5.0"}, "duration"),
    ({"duration": "nan"}, "duration"),
    ({"dmax": "0.0"}, "gear.delta_max_deg"),
    ({"dmax": "inf"}, "gear.delta_max_deg"),
])
def test_bad_scenario_exit_2_nothing_written(tmp_path, capsys, kwargs, field):
    out = tmp_path / "out"
    assert main(["run", str(_scenario(tmp_path, **kwargs)), "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert field in err and err.startswith("steerlab: error:")
    assert "Traceback" not in err
    assert not out.exists()
    assert not list(tmp_path.glob(".out.partial-*"))


def test_dt_out_of_range_names_bound(tmp_path, capsys):
    p = tmp_path / "dt.toml"
    p.write_text('dt = 0.0\n[controller]\ntype = "pid"\n')
    assert main(["run", str(p), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "dt" in err and "greater than or equal to 0.0001" in err   # the lower bound 1e-4 s (issue 15)


def test_malformed_toml(tmp_path, capsys):
    p = tmp_path / "bad.toml"
    p.write_text("name = 'x'\n[ship\nmodel = esso\n")
    assert main(["run", str(p), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "malformed TOML" in err and "bad.toml" in err
    assert not (tmp_path / "o").exists()


def test_missing_file(tmp_path, capsys):
    """The path as given: a missing file is often a wrong folder, which the name alone hides."""
    missing = tmp_path / "scenarios" / "nope.toml"
    assert main(["run", str(missing), "--out", str(tmp_path / "o")]) == 2
    assert f"cannot read {str(missing)!r}: No such file or directory" in capsys.readouterr().err


def test_existing_out_keeps_old_files_on_failure(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "keep.txt").write_text("old")
    assert main(["run", str(_scenario(tmp_path, dmax="-1")), "--out", str(out)]) == 2
    assert [p.name for p in out.iterdir()] == ["keep.txt"]


def test_linearize_json(capsys):
    assert main(["linearize", "esso", "--speed-kn", "16", "--json"]) == 0
    s = json.loads(capsys.readouterr().out)
    assert s["b2_exact_paper"] == pytest.approx(-7.54e-4, rel=5e-3)
    assert s["b2_estimate_eq29_paper"] == pytest.approx(-9.18e-4, rel=5e-3)
    assert s["open_loop_unstable"] is True
    assert s["a0"] < 0
    assert max(e[0] for e in s["eigenvalues"]) > 0
    assert {"A1", "B1", "nomoto_K", "nomoto_T"} <= set(s)


def test_linearize_bad_input(capsys):
    assert main(["linearize", "nessie"]) == 2               # named as given: the SHIP argument
    assert capsys.readouterr().err.startswith("steerlab: error: SHIP: unknown ship 'nessie'")
    assert main(["linearize", "esso", "--speed-kn", "-3"]) == 2
    assert "--speed-kn" in capsys.readouterr().err


def test_unknown_experiment(tmp_path, capsys):
    assert main(["experiment", "nobody2099", "--out", str(tmp_path / "o")]) == 2
    assert "unknown experiment" in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("cmd", ["run", "experiment", "linearize", "bench"])
def test_help_has_examples(cmd, capsys):
    with pytest.raises(SystemExit) as exc:
        main([cmd, "--help"])
    assert exc.value.code == 0
    assert "examples:" in capsys.readouterr().out


def test_experiment_quick_via_cli(tmp_path, capsys):
    out = tmp_path / "zw"
    assert main(["experiment", "zwierzewicz2021", "--quick", "--quiet", "--out", str(out)]) == 0
    rows = json.loads((out / "comparison.json").read_text())
    assert all(set(r) == {"quantity", "paper", "steerlab", "unit", "note"} for r in rows)
    assert "b2" in capsys.readouterr().out
    assert sorted(p.name for p in out.glob("*.png"))


@pytest.mark.parametrize("argv, line", [
    (["autopilot", "--safe-action", "stop"],
     "steerlab: error: argument --safe-action: invalid choice: 'stop' (choose from 'midships', 'hold') "
     "(see 'steerlab autopilot --help')"),
    (["run"], "steerlab: error: the following arguments are required: --out (see 'steerlab run --help')"),
    (["nosuchcommand"], "steerlab: error: argument COMMAND: invalid choice: 'nosuchcommand'"),
    (["autopilot-command", "--to", "127.0.0.1:10111", "--mode", "sideways"],    # was sent, refused unseen
     "steerlab: error: argument --mode: invalid choice: 'sideways' (choose from 'compass', 'route', 'plotter')"),
], ids=["bad-choice", "missing", "unknown-command", "command-mode"])
def test_a_usage_error_is_one_line_with_exit_2(argv, line, capsys):
    """argparse printed its whole usage block before the error (28 lines for autopilot)."""
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and err.startswith(line)
