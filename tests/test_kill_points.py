"""kill -9 at seeded random points of ``run``, ``montecarlo`` and ``tune``: ``--out`` is always
the complete old or the complete new result, and nothing is left after the next run
(tests/kill_harness.py; the 50-point table: benchmarks/kill_points.py)."""

from __future__ import annotations

import os

import pytest

from kill_harness import Case, check, delays

POINTS = 6            #: kill points per command in CI


@pytest.mark.slow
@pytest.mark.skipif(os.name != "posix", reason="SIGKILL and atomic directory renames: POSIX")
@pytest.mark.parametrize("command", ["run", "montecarlo", "tune"])
def test_kill_9_leaves_the_old_or_the_new_result(tmp_path, command):
    case = Case(command, tmp_path)
    case.prepare()
    results = [case.kill_at(d) for d in delays(POINTS, case.run_s, seed=sum(map(ord, command)))]
    problems = [(r["delay_s"], p) for r in results for p in check(r)]
    assert not problems, problems
    seen = {r["after"] for r in results}
    assert seen <= {"old", "new"}
    assert any(not r["finished"] for r in results), "every run finished before its kill: nothing tested"
