"""Figures drawn in forked children (steerlab.forked_jobs, report.run_figure_jobs): the same
bytes as drawn in order in one process, a child's failure raised in the parent, no child left."""

from __future__ import annotations

import os

import pytest

from steerlab.forked_jobs import ForkedJobs, fork_allowed
from steerlab.report import FIGURE_NAMES, run_figure_jobs, write_run_figures
from steerlab.sim.engine import simulate
from steerlab.sim.setup import build


@pytest.fixture(scope="module")
def result(request):
    from conftest import make_scenario

    return simulate(build(make_scenario(duration=120.0, guidance={"changes": [{"t": 10.0, "psi_deg": 20.0}]})))


def test_forked_figures_are_byte_identical_to_figures_drawn_in_order(result, tmp_path):
    write_run_figures(tmp_path / "inline", result, "t")
    with run_figure_jobs(tmp_path / "forked", result, "t") as jobs:
        assert bool(jobs._children) == fork_allowed()       # drawn in children where fork is used
    assert [p.name for p in jobs.paths] == list(FIGURE_NAMES)
    for name in FIGURE_NAMES:
        assert (tmp_path / "forked" / name).read_bytes() == (tmp_path / "inline" / name).read_bytes(), name


def _fail():
    raise ValueError("delta_max out of range")


def test_a_failing_job_is_raised_in_the_parent_with_its_message(tmp_path):
    marker = tmp_path / "ran"
    forked = fork_allowed()      # False in a process with other threads (e.g. after a runtime test)
    with pytest.raises(RuntimeError if forked else ValueError,
                       match=("ValueError: " if forked else "") + "delta_max out of range"):
        with ForkedJobs([[lambda: marker.write_text("x")], [_fail]]):
            pass
    assert marker.read_text() == "x"               # the other group still ran


def test_children_are_forked_and_all_reaped(tmp_path):
    if not fork_allowed():
        pytest.skip("fork is not used on this platform or in a threaded process")
    pids = tmp_path / "pids"
    pids.mkdir()
    jobs = ForkedJobs([[lambda: (pids / str(os.getpid())).write_text("")] for _ in range(3)]).start()
    jobs.wait()
    seen = {int(p.name) for p in pids.iterdir()}
    assert len(seen) == 3 and os.getpid() not in seen      # each group in its own child
    for pid in seen:
        with pytest.raises(ChildProcessError):
            os.waitpid(pid, os.WNOHANG)                     # already reaped: no zombie left


def test_switched_off_the_jobs_run_in_this_process(tmp_path, monkeypatch):
    monkeypatch.setenv("STEERLAB_FORK_JOBS", "0")
    ran = []
    jobs = ForkedJobs([[lambda: ran.append(os.getpid())], [lambda: ran.append(os.getpid())]]).start()
    assert ran == []                                        # nothing before wait()
    jobs.wait()
    assert ran == [os.getpid(), os.getpid()]


def test_a_failure_in_the_parent_kills_the_children(tmp_path):
    if not fork_allowed():
        pytest.skip("fork is not used on this platform or in a threaded process")
    import time

    started = tmp_path / "started"
    with pytest.raises(KeyError):
        with ForkedJobs([[lambda: (started.write_text(""), time.sleep(60))]]) as jobs:
            children = [pid for pid, _ in jobs._children]
            raise KeyError("parent failed")
    for pid in children:
        with pytest.raises(ChildProcessError):
            os.waitpid(pid, os.WNOHANG)
