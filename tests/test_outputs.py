"""All-or-nothing ``--out``: the whole folder swapped, leftovers of dead runs repaired, and a bad
``--out`` refused before any work (docs/reliability-outputs.md)."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from steerlab.cli import main
from steerlab.errors import InputError
from steerlab.outputs import MARKER, OLD, PARTIAL, check_out, repair_leftovers, staged_output


def _dead_pid() -> int:
    p = subprocess.Popen([sys.executable, "-c", "pass"])
    p.wait()
    return p.pid


def _files(d):
    return sorted(p.name for p in d.iterdir())


def test_the_whole_folder_is_replaced_and_old_files_do_not_survive(tmp_path):
    out = tmp_path / "o"
    with staged_output(out) as stage:
        (stage / "timeseries.parquet").write_text("old run")
        (stage / "a.txt").write_text("1")
    assert _files(out) == [MARKER, "a.txt", "timeseries.parquet"]
    with staged_output(out) as stage:
        (stage / "a.txt").write_text("2")
    assert _files(out) == [MARKER, "a.txt"]                 # the earlier run's parquet is gone
    assert (out / "a.txt").read_text() == "2"
    assert _files(tmp_path) == ["o"]                          # no stage, no old folder


def test_a_failure_leaves_the_old_folder_untouched(tmp_path):
    out = tmp_path / "o"
    with staged_output(out) as stage:
        (stage / "a.txt").write_text("1")
    with pytest.raises(RuntimeError):
        with staged_output(out) as stage:
            (stage / "a.txt").write_text("half")
            raise RuntimeError("boom")
    assert (out / "a.txt").read_text() == "1"
    assert _files(tmp_path) == ["o"]


@pytest.mark.parametrize("make, words", [
    (lambda d: (d / "o").write_text("x") and d / "o", "not a directory"),
    (lambda d: (d / "f").write_text("x") and d / "f" / "o", "not a directory"),
    (lambda d: ((d / "o").mkdir(), (d / "o" / "mine.txt").write_text("x"), d / "o")[2], "did not write"),
    (lambda d: d, "current folder"),
    (lambda d: d.parent, "current folder"),
    (lambda d: d.anchor and type(d)(d.anchor), "root folder"),
])
def test_bad_out_is_refused(tmp_path, monkeypatch, make, words):
    monkeypatch.chdir(tmp_path)
    target = make(tmp_path)
    with pytest.raises(InputError, match=words) as exc:
        check_out(target)
    assert exc.value.field == "--out"


@pytest.mark.skipif(os.name != "posix" or os.geteuid() == 0, reason="permissions do not bind root")
def test_read_only_parent_is_refused(tmp_path):
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o500)
    try:
        with pytest.raises(InputError, match="permission denied"):
            check_out(ro / "sub" / "o")
    finally:
        ro.chmod(0o700)


def test_empty_or_new_or_own_folder_is_accepted(tmp_path):
    (tmp_path / "empty").mkdir()
    assert check_out(tmp_path / "empty") == tmp_path.resolve() / "empty"
    assert check_out(tmp_path / "new" / "deeper") == tmp_path.resolve() / "new" / "deeper"
    with staged_output(tmp_path / "own") as stage:
        (stage / "x").write_text("1")
    check_out(tmp_path / "own")


def test_repair_removes_an_unfinished_stage_of_a_dead_run(tmp_path):
    out = tmp_path / "o"
    out.mkdir()
    (out / MARKER).write_text("")
    (out / "a.txt").write_text("old")
    dead = _dead_pid()
    stage = tmp_path / f".o{PARTIAL}{dead}"
    stage.mkdir()
    (stage / "a.txt").write_text("trunc")
    assert repair_leftovers(out.resolve())
    assert _files(tmp_path) == ["o"] and (out / "a.txt").read_text() == "old"


def test_repair_finishes_a_swap_killed_between_the_two_renames(tmp_path):
    dead = _dead_pid()
    old = tmp_path / f".o{OLD}{dead}"                 # the old folder renamed aside ...
    old.mkdir()
    (old / "a.txt").write_text("old")
    stage = tmp_path / f".o{PARTIAL}{dead}"           # ... the complete new one not yet in place
    stage.mkdir()
    (stage / "a.txt").write_text("new")
    repair_leftovers((tmp_path / "o").resolve())
    assert _files(tmp_path) == ["o"] and (tmp_path / "o" / "a.txt").read_text() == "new"


def test_repair_removes_an_old_folder_whose_delete_was_killed(tmp_path):
    (tmp_path / "o").mkdir()
    (tmp_path / "o" / "a.txt").write_text("new")
    dead = _dead_pid()
    (tmp_path / f".o{OLD}{dead}").mkdir()
    repair_leftovers((tmp_path / "o").resolve())
    assert _files(tmp_path) == ["o"] and (tmp_path / "o" / "a.txt").read_text() == "new"


def test_repair_leaves_a_live_run_alone(tmp_path):
    live = os.getppid()                               # a process that exists and is not this one
    stage = tmp_path / f".o{PARTIAL}{live}"
    stage.mkdir()
    assert repair_leftovers((tmp_path / "o").resolve()) == []
    assert stage.exists()


def test_bad_out_is_refused_before_any_work(tmp_path, capsys):
    """A montecarlo whose --out is a file stops at once: no scenario design, no runs."""
    (tmp_path / "o").write_text("a file")
    scen = tmp_path / "missing.toml"                 # not even read: --out is checked first
    assert main(["montecarlo", str(scen), "--runs", "4", "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "--out" in err and "not a directory" in err and "missing.toml" not in err


@pytest.mark.parametrize("argv", [
    ["run"], ["experiment", "zwierzewicz2021"], ["robustness", "x.toml", "--vary", "K=1:2:0.5"],
    ["tune", "x.toml", "--params", "kp", "--bounds", "0:1"], ["imo", "--ship", "esso"], ["sea", "x.toml"],
    ["identify", "x.csv", "--model", "nomoto1"], ["trial", "turning", "--ship", "esso"],
])
def test_every_writing_command_checks_out_first(tmp_path, capsys, argv):
    (tmp_path / "o").write_text("a file")
    code = main([*argv, "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert code == 2 and "--out" in err and "not a directory" in err, err


def test_existing_foreign_folder_is_kept_and_refused(tmp_path, capsys):
    out = tmp_path / "o"
    out.mkdir()
    (out / "thesis.tex").write_text("precious")
    assert main(["run", "--out", str(out), "--quiet"]) == 2
    assert "did not write" in capsys.readouterr().err
    assert _files(out) == ["thesis.tex"]


def test_an_output_of_an_earlier_version_without_marker_is_replaced(tmp_path):
    out = tmp_path / "zw"
    out.mkdir()
    for name in ("comparison.json", "fig_2.png", "table.csv"):
        (out / name).write_text("old")
    check_out(out)                                          # accepted: it is steerlab's
    (out / "notes.txt").write_text("mine")
    with pytest.raises(InputError, match="did not write"):  # a file of another kind: refused
        check_out(out)
    (out / "notes.txt").unlink()
    (out / "comparison.json").unlink()
    with pytest.raises(InputError, match="did not write"):  # no command's JSON: refused
        check_out(out)
