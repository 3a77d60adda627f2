"""The figure worker (steerlab.figure_worker, report.figure_worker): a child forked early draws
the run's figures byte-identical to drawing them in order in one process; a child's failure is
raised in the parent; a cancelled, failed or vanished child leaves nothing behind."""

from __future__ import annotations

import os
import sys
import time

import pytest

from steerlab import figure_worker as fw
from steerlab.figure_worker import FigureWorker
from steerlab.report import FIGURE_NAMES, figure_worker, write_run_figures
from steerlab.sim.engine import simulate
from steerlab.sim.setup import build

@pytest.fixture
def forking(monkeypatch):
    """Fork even if an earlier test in this worker left a thread running (the guard of
    fork_allowed() is for commands; the children here run plain Python and matplotlib)."""
    if not (sys.platform.startswith("linux") and hasattr(os, "fork")):
        pytest.skip("the figure worker forks on Linux only")
    monkeypatch.setattr(fw, "fork_allowed", lambda: True)


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


def test_worker_figures_are_byte_identical_to_figures_drawn_in_order(result, tmp_path, forking):
    write_run_figures(tmp_path / "inline", result, "t")
    worker = figure_worker().start()
    assert len(worker._children) == 1                       # drawn in a child
    worker.submit(tmp_path / "child", result, "t")
    worker.wait()
    for name in FIGURE_NAMES:
        assert (tmp_path / "child" / name).read_bytes() == (tmp_path / "inline" / name).read_bytes(), name


def _fail(*args, **kw):
    raise ValueError("delta_max out of range")


def test_a_failing_child_is_raised_in_the_parent_with_its_message(tmp_path, forking):
    with pytest.raises(RuntimeError, match="ValueError: delta_max out of range"):
        with FigureWorker(_fail) as worker:
            worker.submit(tmp_path)


def test_inline_a_failing_draw_raises_its_own_exception(tmp_path, monkeypatch):
    monkeypatch.setenv("STEERLAB_FORK_JOBS", "0")
    with pytest.raises(ValueError, match="delta_max out of range"):
        with FigureWorker(_fail) as worker:
            worker.submit(tmp_path)


def test_the_child_warms_up_before_the_job_and_draws_in_its_own_process(tmp_path, forking):
    def warm():
        (tmp_path / "warm").write_text(str(os.getpid()))

    def draw(where, part, parts):
        (where / "drawn").write_text(str(os.getpid()))

    with FigureWorker(draw, warm=warm) as worker:
        pid = worker.pid
        worker.submit(tmp_path)
    assert int((tmp_path / "warm").read_text()) == pid == int((tmp_path / "drawn").read_text()) != os.getpid()
    assert _reaped(pid)


def test_a_command_that_fails_before_submitting_kills_the_children(tmp_path, forking):
    with pytest.raises(KeyError):
        with FigureWorker(lambda *a, **k: (tmp_path / "drawn").write_text("x"), parts=2) as worker:
            pids = [c[0] for c in worker._children]
            raise KeyError("bad scenario")
    assert len(pids) == 2 and all(_reaped(p) for p in pids) and not (tmp_path / "drawn").exists()


def test_a_vanished_child_means_the_parent_draws_itself(tmp_path, forking):
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


def test_split_shares_are_drawn_by_the_child_and_a_grandchild(tmp_path, forking):
    def draw(where, part, parts):
        (where / f"share{part}of{parts}").write_text(str(os.getpid()))

    with FigureWorker(draw, split=2) as worker:
        child = worker.pid
        worker.submit(tmp_path)
    a, b = (int((tmp_path / f"share{k}of2").read_text()) for k in (0, 1))
    assert a == child and b not in (child, os.getpid())
    assert sorted(p.name for p in tmp_path.iterdir()) == ["share0of2", "share1of2"]


def _fail_in_share_1(where, part, parts):
    if part == 1:
        raise ValueError("rudder.png: bad axis")
    (where / "share0").write_text("x")


def test_a_failing_grandchild_is_raised_in_the_parent_with_its_message(tmp_path, forking):
    with pytest.raises(RuntimeError, match=r"failed: ValueError: rudder.png: bad axis$"):
        with FigureWorker(_fail_in_share_1, split=2) as worker:
            worker.submit(tmp_path)


def test_submit_returns_while_the_child_is_still_warming_up(tmp_path, forking):
    """The job (larger than a pipe's buffer) is written by a thread: the child waits in its warm-up
    for a flag the parent sets after submit() returned (a blocking submit would leave the flag
    unset until the child gave up waiting)."""
    flag = tmp_path / "flag"

    def warm():
        for _ in range(3000):
            if flag.exists():
                (tmp_path / "saw").write_text("flag")
                return
            time.sleep(0.01)
        (tmp_path / "saw").write_text("gave up")

    def draw(where, blob, part, parts):
        (where / "drawn").write_text(str(len(blob)))

    with FigureWorker(draw, warm=warm) as worker:
        worker.submit(tmp_path, b"x" * (4 << 20))
        flag.write_text("set")
    assert (tmp_path / "saw").read_text() == "flag"
    assert (tmp_path / "drawn").read_text() == str(4 << 20)


def test_the_parent_gets_its_objects_back_from_the_permanent_generation(tmp_path, forking):
    """start() freezes the collector's objects for the fork (fewer page copies in the child) and
    unfreezes them in the parent: the parent's garbage collection is as before."""
    import gc

    before = gc.get_freeze_count()
    with FigureWorker(lambda where, part, parts: (where / "drawn").write_text(str(gc.get_freeze_count()))) as w:
        assert gc.get_freeze_count() == before
        w.submit(tmp_path)
    assert int((tmp_path / "drawn").read_text()) > 0          # the child kept them frozen
