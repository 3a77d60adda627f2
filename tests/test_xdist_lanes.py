"""The suite's pytest-xdist scheduler (tests/xdist_lanes.py): the real-time tests run on a worker
of their own, every test runs once, no worker idles while tests are left, a crashed worker's
tests run elsewhere; and a compute test runs at the lower CPU priority."""

from __future__ import annotations

import os
from pathlib import Path
from types import SimpleNamespace

import pytest
import conftest
from conftest import COMPUTE_NICENESS, is_realtime, lanes_wanted, under_lanes
from xdist_lanes import MIN_PENDING, MODULE_TAIL, QUEUED, LaneScheduling


class FakeWorker:
    """What the scheduler uses of pytest-xdist's ``WorkerController``."""

    def __init__(self, number: int):
        self.gateway = SimpleNamespace(id=f"gw{number}")
        self.shutting_down = False
        self.received: list[int] = []

    def send_runtest_some(self, indices):
        assert not self.shutting_down
        self.received.extend(indices)

    def shutdown(self):
        self.shutting_down = True


def _session(collection, workers=3, is_waiting=None):
    sched = LaneScheduling(workers, is_waiting or (lambda nodeid: "wait" in nodeid))
    order = (2, 0, 1) if workers == 3 else range(workers)      # the lane is the highest number, not the last added
    nodes = [FakeWorker(n) for n in order]
    for node in nodes:
        sched.add_node(node)
    for node in nodes:
        sched.add_node_collection(node, collection)
    assert sched.collection_is_completed
    sched.schedule()
    return sched, nodes


def _run_all(sched, nodes, crash=None):
    """Workers finish their oldest test in turn until the scheduler has nothing pending;
    ``crash=(node, after)``: that worker dies after ``after`` tests. Returns the tests run,
    in order, per worker id, and the crashed test."""
    ran: dict[str, list[int]] = {n.gateway.id: [] for n in nodes}
    crashed = None
    steps = 0
    while sched.has_pending:
        steps += 1
        assert steps < 10_000
        for node in list(sched.nodes):
            pending = sched.node2pending[node]
            assert len(pending) <= QUEUED + MODULE_TAIL
            if not pending:
                continue
            if crash and node is crash[0] and len(ran[node.gateway.id]) == crash[1]:
                crashed = sched.remove_node(node)
                continue
            ran[node.gateway.id].append(pending[0])
            sched.mark_test_complete(node, pending[0], 0.01)
    assert sched.tests_finished
    return ran, crashed


COLLECTION = [f"tests/test_a.py::compute{i}" for i in range(40)] + \
             [f"tests/test_b.py::wait{i}" for i in range(6)] + [f"tests/test_c.py::compute{i}" for i in range(40, 60)]
WAIT = [i for i, nodeid in enumerate(COLLECTION) if "wait" in nodeid]


def test_wall_clock_tests_run_on_the_last_worker_first_and_every_test_runs_once():
    sched, nodes = _session(COLLECTION)
    ran, _ = _run_all(sched, nodes)
    assert ran["gw2"][:len(WAIT)] == WAIT                              # the lane, in collection order
    assert not set(WAIT) & set(ran["gw0"] + ran["gw1"])
    assert sorted(sum(ran.values(), [])) == list(range(len(COLLECTION)))
    assert all(len(ran[w]) > 10 for w in ran)                          # the lane helps once its tests are done
    assert all(node.shutting_down for node in nodes)


def test_no_worker_idles_while_tests_are_left():
    only_compute = _session([f"t.py::compute{i}" for i in range(30)])[0]
    ran, _ = _run_all(only_compute, only_compute.nodes)
    assert all(ran[w] for w in ran)                                    # the lane took compute tests
    only_waiting = _session([f"t.py::wait{i}" for i in range(30)])[0]
    ran, _ = _run_all(only_waiting, only_waiting.nodes)
    assert all(ran[w] for w in ran)                                    # the others took waiting tests


def test_queues_stay_short_so_the_tail_is_balanced():
    sched, nodes = _session(COLLECTION)
    assert all(MIN_PENDING <= len(sched.node2pending[n]) <= QUEUED + MODULE_TAIL for n in nodes)
    _run_all(sched, nodes)                                   # asserts <= QUEUED + MODULE_TAIL at every step


def test_a_short_module_runs_on_one_worker_a_long_one_is_shared():
    """Module-scoped fixtures are made once per worker: a module of up to MODULE_TAIL + 1 tests
    goes to one worker wherever a top-up starts in it; a longer one is shared out."""
    sizes = [3, MODULE_TAIL + 1, 2, 7, MODULE_TAIL + 1, 1, 40, 4]
    collection = [f"tests/test_m{m}.py::t{i}" for m, n in enumerate(sizes) for i in range(n)]
    sched, nodes = _session(collection, workers=2)
    ran, _ = _run_all(sched, nodes)
    worker_of = {i: w for w, tests in ran.items() for i in tests}
    shared = {m: len({worker_of[i] for i, nodeid in enumerate(collection) if nodeid.startswith(f"tests/test_m{m}.py")})
              for m in range(len(sizes))}
    assert shared == {0: 1, 1: 1, 2: 1, 3: 1, 4: 1, 5: 1, 6: 2, 7: 1}


def test_a_crashed_worker_is_reported_and_its_other_tests_run_elsewhere():
    sched, nodes = _session(COLLECTION)
    lane = next(n for n in nodes if n.gateway.id == "gw2")
    ran, crashed = _run_all(sched, nodes, crash=(lane, 2))
    assert crashed == COLLECTION[WAIT[2]]
    done = sum(ran.values(), [])
    assert sorted(done + [WAIT[2]]) == list(range(len(COLLECTION)))   # the rest ran, once each
    assert set(WAIT[3:]) <= set(ran["gw0"] + ran["gw1"])


def test_workers_that_collected_other_tests_are_not_used():
    sched = LaneScheduling(2, lambda nodeid: False)
    a, b = FakeWorker(0), FakeWorker(1)
    for n in (a, b):
        sched.add_node(n)
    sched.add_node_collection(a, ["t.py::x", "t.py::y"])
    sched.add_node_collection(b, ["t.py::x", "t.py::z"])
    sched.schedule()
    assert a.received == b.received == [] and sched.collection is None


@pytest.mark.parametrize("nodeid, realtime", [
    ("tests/test_runtime_e2e.py::test_hold_course_and_change_20_deg", True),
    ("tests/test_signalk_plugin.py::test_plugin_unit_tests_pass_under_node", True),
    ("tests/test_runtime_access.py::test_x[1]", True),
    ("tests/test_gym_cache.py::test_runtime_like_name", False),
    ("tests/test_cli.py::test_run_writes_all_outputs", False),
])
def test_realtime_modules(nodeid, realtime):
    assert is_realtime(nodeid) is realtime


def test_a_compute_test_runs_at_the_lower_cpu_priority_under_xdist(request):
    if not under_lanes(request.config):
        pytest.skip("runs under pytest-xdist's load distribution (the suite's default -n auto)")
    assert os.getpriority(os.PRIO_PROCESS, 0) >= COMPUTE_NICENESS


@pytest.mark.parametrize("args, wanted", [
    ([], True),                                                   # the whole suite (testpaths)
    (["tests"], True),
    (["tests/test_asa.py"], False),                               # no real-time test selected
    (["tests/test_asa.py", "tests/test_runtime_e2e.py::test_hold_course_and_change_20_deg"], True),
    (["tests/test_signalk_plugin.py"], True),
])
def test_the_lane_only_when_real_time_tests_may_run(args, wanted, monkeypatch):
    repo = Path(__file__).resolve().parent.parent
    config = SimpleNamespace(args=args, rootpath=repo, invocation_params=SimpleNamespace(dir=repo),
                             getini={"testpaths": ["tests"]}.get)
    monkeypatch.setattr(conftest, "LANES", True)                   # whatever this run's setting
    assert lanes_wanted(config) is wanted
    monkeypatch.setattr(conftest, "LANES", False)                  # STEERLAB_TEST_LANES=0
    assert lanes_wanted(config) is False
