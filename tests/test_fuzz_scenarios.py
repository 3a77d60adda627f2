"""Fuzz: mutated scenario files give exit 0 or a one-line exit 2, never a traceback (issue 15).

300 seeded mutants (:mod:`scenario_mutator`) of the bundled default and four other scenarios
go through ``steerlab run`` in process up to the simulation (the engine is replaced by a
stub, so the test measures loading, validation and design, not integration): every file
either reaches the simulation (stderr: warnings only) or is rejected with exit code 2, one
line ``steerlab: error: FIELD: ...`` of at most 300 characters after the prefix, and nothing
in ``--out`` (no staging leftovers either). ``benchmarks/fuzz_scenarios.py`` runs the same
check over any number of mutants.
"""

from __future__ import annotations

import contextlib
import io
import subprocess
import sys
import time
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import scenario_mutator  # noqa: E402

from steerlab.cli import MAX_MESSAGE, main  # noqa: E402

PREFIX = "steerlab: error: "


class _Reached(Exception):
    """Raised by the stub engine: the scenario was accepted and designed."""


def _stub_simulate(setup, engine="compiled", record_every=1):
    raise _Reached(setup.n_steps)


def check_one(path: Path, out: Path) -> str:
    """Run ``steerlab run path --out out`` up to the engine; assert the contract; return the outcome."""
    err = io.StringIO()
    t0 = time.perf_counter()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        try:
            rc = main(["run", str(path), "--out", str(out), "--quiet"])
        except _Reached:
            rc = None
    elapsed = time.perf_counter() - t0
    lines = err.getvalue().splitlines()
    assert elapsed < 60.0, f"{path.name}: {elapsed:.1f} s"          # a hang guard
    if rc is None:
        assert all(line.startswith("steerlab: warning: ") for line in lines), (path.name, lines)
        return "accepted"
    assert rc == 2, (path.name, rc, lines)
    assert len(lines) == 1 and lines[0].startswith(PREFIX), (path.name, lines)
    assert len(lines[0]) <= len(PREFIX) + MAX_MESSAGE, (path.name, lines[0])
    assert ": " in lines[0][len(PREFIX):], lines[0]          # names a field
    assert not out.exists(), path.name
    assert not list(out.parent.glob(f".{out.name}.partial-*")), path.name
    return "rejected"


def check_one_real(path: Path, out: Path, limit_s: float = 30.0) -> str:
    """Run ``steerlab run path --out out`` with the real engine; assert the contract of issue 15
    for an accepted file: exit 0 with finite time series and metrics, or exit 3 (divergence)
    with one line and nothing in ``--out``; a rejected file as :func:`check_one`. Returns
    ``"accepted"``, ``"diverged"`` or ``"rejected"``."""
    import json
    import math

    import numpy as np

    err = io.StringIO()
    t0 = time.perf_counter()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        rc = main(["run", str(path), "--out", str(out), "--quiet"])
    elapsed = time.perf_counter() - t0
    lines = [ln for ln in err.getvalue().splitlines() if not ln.startswith("steerlab: warning: ")]
    lines = [ln for ln in lines if "compiling" not in ln and not ln.startswith("  ")]   # compile notices
    assert elapsed < limit_s, f"{path.name}: {elapsed:.1f} s"
    if rc == 0:
        data = np.loadtxt(out / "timeseries.csv", delimiter=",", skiprows=1, ndmin=2)
        assert np.all(np.isfinite(data)), path.name
        metrics = json.loads((out / "metrics.json").read_text())["metrics"]
        assert all(v is None or math.isfinite(v) for v in metrics.values()), (path.name, metrics)
        return "accepted"
    assert len(lines) == 1 and lines[0].startswith(PREFIX), (path.name, rc, lines)
    assert not out.exists(), path.name
    if rc == 3:
        return "diverged"
    assert rc == 2, (path.name, rc, lines)
    return "rejected"


def test_mutated_scenarios_exit_0_or_one_line_2(tmp_path, monkeypatch):
    import steerlab.sim.engine as engine

    monkeypatch.setattr(engine, "simulate", _stub_simulate)
    # no figure child (steerlab.figure_worker): with the engine stubbed it never draws, and
    # forking then killing one per file was half of this test's CPU time
    monkeypatch.setenv("STEERLAB_FORK_JOBS", "0")
    outcomes = {"accepted": 0, "rejected": 0}
    for i, path in enumerate(scenario_mutator.mutants(300, seed=15, folder=tmp_path / "in")):
        outcomes[check_one(path, tmp_path / f"out{i}")] += 1
    # both outcomes occur (a mutator that only breaks files, or never does, tests little)
    assert outcomes["accepted"] >= 30 and outcomes["rejected"] >= 150, outcomes


@pytest.mark.slow
def test_accepted_mutants_run_to_finite_results_or_a_clear_divergence(tmp_path):
    """The real engine on mutants (no stub): an accepted file gives finite time series and
    metrics, or exit 3 with one line and nothing written (a first run of a combination may
    compile: 120 s per file here; the long script holds 30 s on a warm cache)."""
    outcomes = {"accepted": 0, "diverged": 0, "rejected": 0}
    for i, path in enumerate(scenario_mutator.mutants(60, seed=16, folder=tmp_path / "in")):
        outcomes[check_one_real(path, tmp_path / f"out{i}", limit_s=120.0)] += 1
    assert outcomes["accepted"] >= 5 and outcomes["rejected"] >= 20, outcomes


def _issue_case(tmp_path, kind) -> Path:
    base = scenario_mutator.to_toml(scenario_mutator.BASES["los"]).encode()
    (tmp_path / "route.csv").write_text(scenario_mutator.ROUTE_CSV)
    if kind == "utf8":
        data = base.replace(b'name = "los"', b'name = "l\xffs"')
    elif kind == "deep":
        data = b"x = " + b"[" * 400 + b"]" * 400 + b"\n" + base
    elif kind == "dotted":
        data = b"x" + b".a" * 100_000 + b" = 1\n" + base
    else:
        (tmp_path / "route.csv").write_bytes(bytes(range(256)))
        data = base
    p = tmp_path / "s.toml"
    p.write_bytes(data)
    return p


EXPECTED = {"utf8": "scenario: s.toml: not valid UTF-8 at byte 9 (line 1)",
            "deep": "scenario: s.toml: nesting deeper than 32 levels at line 1",
            "dotted": "scenario: s.toml: nesting deeper than 32 levels at line 1",
            "route": "guidance.route_file: route.csv: binary file (NUL byte at byte 0"}


@pytest.mark.parametrize("kind", sorted(EXPECTED))
def test_classes_of_the_issue_give_one_line(tmp_path, capsys, kind):
    """Invalid UTF-8, ~400 levels of arrays (RecursionError before), 10^5 dotted keys (a
    minute, then MemoryError before) and a binary route file: exit 2, one line naming the
    cause (the MemoryError and RecursionError of before gave other lines). The time is only a
    hang guard, generous for a loaded machine."""
    t0 = time.perf_counter()
    assert main(["run", str(_issue_case(tmp_path, kind)), "--out", str(tmp_path / "out"), "--quiet"]) == 2
    assert time.perf_counter() - t0 < 60.0
    err = capsys.readouterr().err
    assert err.startswith(PREFIX + EXPECTED[kind]) and len(err.splitlines()) == 1, err
    assert not (tmp_path / "out").exists()


def test_deep_nesting_through_the_real_command_line(tmp_path):
    """The RecursionError class through a real process: exit 2, no traceback."""
    out = tmp_path / "out"
    proc = subprocess.run([sys.executable, "-m", "steerlab", "run", str(_issue_case(tmp_path, "deep")),
                           "--out", str(out), "--quiet"], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2, proc.stderr
    assert "Traceback" not in proc.stderr and len(proc.stderr.splitlines()) == 1
    assert EXPECTED["deep"] in proc.stderr
    assert not out.exists()
