"""All-or-nothing ``--out``: the whole folder swapped, leftovers of dead runs repaired, and a bad
``--out`` refused before any work (docs/reliability-outputs.md)."""

from __future__ import annotations

import os
import re
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


def _snapshot(d):
    """Every entry under ``d`` with its bytes: what "nothing changed" compares."""
    return sorted((str(p.relative_to(d)), p.read_bytes() if p.is_file() else b"<dir>") for p in d.rglob("*"))


@pytest.mark.parametrize("names", [
    ["thesis.tex"],
    ["result.json", "measurements.csv", "notes.html"],              # the case: looks like an output
    ["metrics.json", "timeseries.csv", "report.html", "fig_heading.png"],
    ["comparison.json", "fig_2.png", "table.csv"],                  # an output of a version before the marker
])
def test_a_folder_steerlab_did_not_mark_is_refused_and_unchanged(tmp_path, capsys, names):
    out = tmp_path / "o"
    out.mkdir()
    for name in names:
        (out / name).write_text(f"the user's {name}")
    (out / "sub").mkdir()
    (out / "sub" / "keep.txt").write_text("nested")
    before = _snapshot(out)
    assert main(["run", "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--out" in err[0] and str(out) in err[0], err
    assert "remove it or choose another folder" in err[0]
    assert _snapshot(out) == before                          # listed before and after: nothing changed
    assert _files(tmp_path) == ["o"]                          # no stage either


def test_the_marker_names_the_command_and_the_listing(tmp_path):
    import json

    from steerlab.outputs import listing_digest

    out = tmp_path / "o"
    with staged_output(out) as stage:
        (stage / "a.txt").write_text("12345")
        (stage / "figs").mkdir()
        (stage / "figs" / "f.png").write_text("xy")
    doc = json.loads((out / MARKER).read_text())
    assert doc["listing"] == {"a.txt": 5, "figs": -1, "figs/f.png": 2}
    assert doc["listing_sha256"] == listing_digest(doc["listing"])
    assert doc["command"].startswith("steerlab")


@pytest.mark.parametrize("tamper, words", [
    (lambda o: (o / "notes.html").write_text("mine"), "changed since ('notes.html')"),        # a file added
    (lambda o: (o / "a.txt").write_text("edited by hand"), "changed since ('a.txt')"),        # a file edited
    (lambda o: (o / MARKER).write_text("written by steerlab\n"), "without steerlab's listing"),  # old marker
    (lambda o: (o / MARKER).write_text((o / MARKER).read_text().replace('"a.txt": 1', '"a.txt": 2')),
     "does not match its digest"),
])
def test_a_marked_folder_changed_since_is_refused(tmp_path, tamper, words):
    out = tmp_path / "o"
    with staged_output(out) as stage:
        (stage / "a.txt").write_text("1")
    tamper(out)
    before = _snapshot(out)
    with pytest.raises(InputError, match=re.escape(words)) as exc:
        check_out(out)
    assert exc.value.field == "--out" and "remove it or choose another folder" in str(exc.value)
    assert _snapshot(out) == before


def test_a_marked_folder_with_files_removed_is_still_replaced(tmp_path):
    out = tmp_path / "o"
    with staged_output(out) as stage:
        (stage / "a.txt").write_text("1")
        (stage / "b.txt").write_text("2")
    (out / "b.txt").unlink()                                  # nothing of the user's to lose
    with staged_output(out) as stage:
        (stage / "c.txt").write_text("3")
    assert _files(out) == [MARKER, "c.txt"]
