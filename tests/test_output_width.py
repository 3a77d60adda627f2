"""Output people read: the CLI's tables fit 100 columns, and progress is one updating bar on a
terminal and a few plain lines elsewhere (never one line per generation or run)."""

from __future__ import annotations

import io
import re
import subprocess
import sys
from pathlib import Path

import pytest

from steerlab.cli import main
from steerlab.progress import PLAIN_PERIOD, Reporter, bar_message, runs_progress
from steerlab.text_table import MAX_WIDTH, render_pairs, render_table

ROOT = Path(__file__).resolve().parent.parent
SCENARIOS = ROOT / "examples" / "scenarios"


def _widest(text: str) -> int:
    return max((len(line) for line in text.splitlines()), default=0)


# ---------------------------------------------------------------- tables


def test_a_table_of_long_cells_wraps_within_the_width_and_keeps_every_word():
    long = "a published value given only as prose, in a sentence much longer than a column " * 2
    text = render_table(("quantity", "paper", "steerlab", "unit"),
                        [("a quantity", long, 1.23456789, "deg [x]"),
                         ("a quantity with a long name " * 4, 2.0, float("nan"), "-")],
                        title="title [bold]x[/bold]", align="lrrl")
    assert _widest(text) <= MAX_WIDTH
    # wrapped, not cut: the prose reads on once its row's other cells are taken out
    assert " ".join(long.split()) in " ".join(text.split()).replace(" 1.235 deg [x]", "")
    assert len(text.splitlines()) >= 6
    assert "1.235" in text and "n/a" in text
    assert "[bold]x[/bold]" in text and "deg [x]" in text                # no rich markup
    assert "\x1b" not in text and text.isascii()
    assert render_table(("a", "b"), [("x", 1.0)], width=60).splitlines()[0].startswith("a")
    assert _widest(render_pairs([("key", "v " * 200)], width=70)) <= 70


def test_rich_is_imported_only_when_a_table_is_printed():
    out = subprocess.run([sys.executable, "-c", "import sys, steerlab, steerlab.text_table, steerlab.progress; "
                          "print('rich' in sys.modules)"], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "False"


@pytest.mark.parametrize("argv", [
    ["ships", "list"],
    ["ships", "show", "small-tanker-bech"],
    ["cache", "info"],
    ["linearize", "esso", "--speed-kn", "16"],
    ["trial", "zigzag", "--ship", "small-tanker-bech", "--quiet"],
])
def test_quick_commands_print_lines_of_at_most_100_columns(argv, capsys):
    assert main(argv) == 0
    out, err = capsys.readouterr()
    assert out.strip() and _widest(out) <= MAX_WIDTH, out
    assert _widest(err) <= MAX_WIDTH, err


def test_run_montecarlo_and_robustness_fit_100_columns(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)             # relative paths, as a user in a project folder types them
    Path("short.toml").write_text((SCENARIOS / "sea-state-5.toml").read_text()
                                  .replace("duration = 1500.0", "duration = 300.0"))
    Path("nomoto1-pid.toml").write_text((SCENARIOS / "nomoto1-pid.toml").read_text())
    assert main(["run", "short.toml", "--out", "out/run"]) == 0
    assert main(["montecarlo", "short.toml", "--runs", "3", "--out", "out/mc"]) == 0
    assert main(["robustness", "nomoto1-pid.toml", "--vary", "T=30:70:20", "--vary", "K=0.07:0.2:0.065",
                 "--out", "out/rob"]) == 0
    out, err = capsys.readouterr()
    assert "95% CI of mean" in out and "rudder_travel_deg" in out
    assert _widest(out) <= MAX_WIDTH, out
    assert _widest(err) <= MAX_WIDTH, err


def test_experiment_and_bench_tables_fit_100_columns(tmp_path, monkeypatch, capsys):
    from types import SimpleNamespace

    import steerlab.bench
    from steerlab.experiments import EXPERIMENTS

    prose = "the paper states this only in words, over several lines of a long sentence"
    rows = [{"quantity": f"fig {i}: a quantity whose name is long enough to need wrapping, case {i}",
             "paper": prose if i % 2 else 12.5, "steerlab": 12.3456789 * i, "unit": "deg s^2"}
            for i in range(5)]
    monkeypatch.setitem(EXPERIMENTS, "wide-table", SimpleNamespace(run=lambda out, progress, quick: rows))
    assert main(["experiment", "wide-table", "--out", str(tmp_path / "e"), "--quiet"]) == 0
    monkeypatch.setattr(steerlab.bench, "run_bench",
                        lambda **kw: {"design_reference": "DESIGN.md section 'Speed' " * 6, "speed": 12.9e6})
    assert main(["bench", "--quiet"]) == 0
    out = capsys.readouterr().out
    assert _widest(out) <= MAX_WIDTH, out
    assert set(prose.replace(",", " ").split()) <= set(out.replace(",", " ").split())     # wrapped, not cut
    assert "1.29e+07" in out and out.count("fig ") == 5


# ---------------------------------------------------------------- progress


class _Clock:
    def __init__(self):
        self.t = 0.0

    def __call__(self):
        return self.t


def test_progress_off_a_terminal_is_sparse_plain_lines():
    """1 000 bar updates over 300 s: one line per PLAIN_PERIOD and the last one, status lines
    all kept, no carriage returns."""
    stream, clock = io.StringIO(), _Clock()
    say = Reporter(stream=stream, tty=False, clock=clock)
    say("tuning 4 controllers")
    for i in range(1, 1001):
        clock.t = 0.3 * i
        say(bar_message(i, 1000, f"gen {i}/1000"))
    say("wrote out/")
    lines = stream.getvalue().splitlines()
    assert "\r" not in stream.getvalue()
    assert lines[0].endswith("tuning 4 controllers") and lines[-1].endswith("wrote out/")
    bars = [line for line in lines if "gen " in line]
    assert len(bars) <= 300.0 / PLAIN_PERIOD + 2
    assert bars[-1].endswith("[####################] gen 1000/1000")
    assert all(re.match(r"^\[\s*\d+\.\d s\] ", line) for line in lines)


def test_progress_on_a_terminal_is_one_updating_line():
    stream, clock = io.StringIO(), _Clock()
    say = Reporter(stream=stream, tty=True, clock=clock)
    say("4 runs of 15000 steps")
    report = runs_progress(say, period=0.0)
    for i in range(1, 201):
        clock.t = 0.05 * i
        report(i, 200)
    say("wrote out/")
    text = stream.getvalue()
    lines = text.split("\n")
    # the status line, ONE line rewritten in place (\r) ending with the finished bar, the last status line
    assert len(lines) == 4 and lines[-1] == "", lines
    assert lines[1].count("\r") > 10 and lines[1].rstrip("\x1b[K").endswith("200/200 runs")
    assert lines[2].endswith("wrote out/")
    assert Reporter(stream=(s := io.StringIO()), tty=True, quiet=True)("x") is None and s.getvalue() == ""


def test_every_bar_of_the_package_is_a_bar_message():
    """The bar producers go through steerlab.progress.bar_message (so the sink knows progress
    from status): no module formats its own bar."""
    src = ROOT / "src" / "steerlab"
    offenders = [str(p.relative_to(src)) for p in src.rglob("*.py")
                 if re.search(r"from steerlab\.progress import [^\n]*\bbar\b(?!_)", p.read_text(encoding="utf-8"))]
    producers = [p.name for p in src.rglob("*.py") if "bar_message" in p.read_text(encoding="utf-8")]
    assert {"optimisers.py", "witkowska_ga.py", "imo_standard.py"} <= set(producers)
    assert offenders == []


@pytest.mark.slow
def test_witkowska_ga_quick_prints_a_bounded_number_of_progress_lines(tmp_path):
    """The GA reproduction (here --quick) off a terminal: a handful of lines, not one per
    generation (it printed 1 009 before)."""
    proc = subprocess.run([sys.executable, "-m", "steerlab", "experiment", "witkowska-ga", "--quick",
                           "--out", str(tmp_path / "ga")], capture_output=True, text=True, timeout=1200)
    assert proc.returncode == 0, proc.stderr[-2000:]
    err = [line for line in proc.stderr.splitlines() if line.strip()]
    assert 2 <= len(err) <= 40, proc.stderr
    assert "\r" not in proc.stderr
    assert _widest(proc.stdout) <= MAX_WIDTH and _widest(proc.stderr) <= 2 * MAX_WIDTH
