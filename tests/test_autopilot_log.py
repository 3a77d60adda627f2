"""The autopilot's CSV log (``--log``, steerlab.runtime.autopilot.open_log): a restart continues
it, never truncates it; another program's file of that name is refused and left as it was."""

from __future__ import annotations

import csv

import pytest

from steerlab.errors import InputError
from steerlab.runtime.autopilot import LOG_COLUMNS, open_log


def _rows(path):
    with open(path, newline="", encoding="utf-8") as f:
        return list(csv.DictReader(f))


def test_a_restart_appends_to_the_log_with_one_header(tmp_path):
    path = tmp_path / "autopilot-log.csv"
    for run in (1, 2):                       # two runs of the autopilot, one after the other
        f, w = open_log(path)
        for t in (0.0, 1.0):
            w.writerow({"t": t, "wall": 1000.0 * run + t, "mode": "auto"})
        f.close()
    text = path.read_text(encoding="utf-8")
    assert text.count(",".join(LOG_COLUMNS)) == 1
    assert [(r["t"], r["wall"]) for r in _rows(path)] == [("0.0", "1000.0"), ("1.0", "1001.0"),
                                                          ("0.0", "2000.0"), ("1.0", "2001.0")]


def test_a_row_cut_short_by_a_kill_is_ended_before_the_next_run(tmp_path):
    path = tmp_path / "log.csv"
    f, w = open_log(path)
    w.writerow({"t": 0.0, "wall": 5.0})
    f.close()
    with open(path, "a", encoding="utf-8") as g:
        g.write("1.0,6.")                    # the process killed in the middle of a row
    f, w = open_log(path)
    w.writerow({"t": 0.0, "wall": 9.0})
    f.close()
    rows = _rows(path)
    assert rows[-1]["t"] == "0.0" and rows[-1]["wall"] == "9.0" and len(rows) == 3


def test_another_programs_file_is_refused_and_left_as_it_was(tmp_path):
    path = tmp_path / "autopilot-log.csv"
    path.write_text("date,position\n2026-11-30,54N 18E\n", encoding="utf-8")
    with pytest.raises(InputError) as e:
        open_log(path)
    assert str(e.value).startswith("--log: ") and "is not an autopilot log" in str(e.value)
    assert path.read_text(encoding="utf-8") == "date,position\n2026-11-30,54N 18E\n"
