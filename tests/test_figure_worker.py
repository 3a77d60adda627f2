"""The figure worker (steerlab.figure_worker, report.figure_worker): a child forked early draws
the run's figures byte-identical to drawing them in order in one process; a child's failure is
raised in the parent; a cancelled, failed or vanished child leaves nothing behind."""

from __future__ import annotations

import os

import pytest

from steerlab.figure_worker import FigureWorker, fork_allowed
from steerlab.report import FIGURE_NAMES, figure_worker, write_run_figures
from steerlab.sim.engine import simulate
from steerlab.sim.setup import build

needs_fork = pytest.mark.skipif(not fork_allowed(), reason="fork is not used on this platform or "
                                                           "in a threaded process")


@pytest.fixture(scope="module")
def result():
    from conftest import make_scenario

    return simulate(build(make_scenario(duration=120.0, guidance={"changes": [{"t": 10.0, "psi_deg": 20.0}]})))


def _reaped(pid: int) -> bool:
    try:
        os.waitpid(pid, os.WNOHANG)
    except ChildProcessError:
        return True
    return False


def test_worker_figures_are_byte_identical_to_figures_drawn_in_order(result, tmp_path):
    write_run_figures(tmp_path / "inline", result, "t")
    worker = figure_worker().start()
    assert len(worker._children) == (1 if fork_allowed() else 0)   # a child where fork is used
    worker.submit(tmp_path / "child", result, "t")
    worker.wait()
    for name in FIGURE_NAMES:
        assert (tmp_path / "child" / name).read_bytes() == (tmp_path / "inline" / name).read_bytes(), name


def _fail(*args, **kw):
    raise ValueError("delta_max out of range")


def test_a_failing_child_is_raised_in_the_parent_with_its_message(tmp_path):
    forked = fork_allowed()
    with pytest.raises(RuntimeError if forked else ValueError,
                       match=("ValueError: " if forked else "") + "delta_max out of range"):
        with FigureWorker(_fail) as worker:
            worker.submit(tmp_path)


@needs_fork
def test_the_child_warms_up_before_the_job_and_draws_in_its_own_process(tmp_path):
    def warm():
        (tmp_path / "warm").write_text(str(os.getpid()))

    def draw(where, part, parts):
        (where / "drawn").write_text(str(os.getpid()))

    with FigureWorker(draw, warm=warm) as worker:
        pid = worker.pid
        worker.submit(tmp_path)
    assert int((tmp_path / "warm").read_text()) == pid == int((tmp_path / "drawn").read_text()) != os.getpid()
    assert _reaped(pid)


@needs_fork
def test_a_command_that_fails_before_submitting_kills_the_children(tmp_path):
    with pytest.raises(KeyError):
        with FigureWorker(lambda *a, **k: (tmp_path / "drawn").write_text("x"), parts=2) as worker:
            pids = [c[0] for c in worker._children]
            raise KeyError("bad scenario")
    assert len(pids) == 2 and all(_reaped(p) for p in pids) and not (tmp_path / "drawn").exists()


@needs_fork
def test_a_vanished_child_means_the_parent_draws_itself(tmp_path):
    worker = FigureWorker(lambda where, part, parts: (where / "drawn").write_text(str(os.getpid()))).start()
    os.kill(worker.pid, 9)              # e.g. killed by the OOM killer while warming up
    os.waitpid(worker.pid, 0)
    worker.submit(tmp_path)             # the pipe is broken: the parent takes the job back
    worker.wait()
    assert int((tmp_path / "drawn").read_text()) == os.getpid()


def test_switched_off_the_parent_draws_in_wait(tmp_path, monkeypatch):
    monkeypatch.setenv("STEERLAB_FORK_JOBS", "0")
    worker = FigureWorker(lambda where, part, parts: (where / f"drawn{part}").write_text(str(os.getpid())),
                          parts=2).start()
    assert worker.pid is None
    worker.submit(tmp_path)
    assert not (tmp_path / "drawn0").exists()               # nothing before wait()
    worker.wait()
    assert int((tmp_path / "drawn0").read_text()) == int((tmp_path / "drawn1").read_text()) == os.getpid()
