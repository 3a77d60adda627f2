"""A pytest-xdist scheduler with a lane for the tests that wait on the wall clock.

The runtime's tests (a ship server and an autopilot talking over loopback sockets in real time,
a headless browser, a Signal K server) spend most of their wall time waiting: on a worker that
also runs the compute-heavy tests they hold a core idle for about a minute of the suite. With
``-n auto`` the suite therefore starts one worker more than there are cores
(:func:`auto_workers`; only when the paths given to pytest may hold real-time tests, and not
with ``STEERLAB_TEST_LANES=0``: ``tests/conftest.py``), and :class:`LaneScheduling` gives

* the **wall-clock tests** (``is_waiting(nodeid)``) to the last worker, the *lane*, in
  collection order;
* every other test to the other workers, a few at a time, a short module's tests together
  (:data:`MODULE_TAIL`).

A worker whose own pool is empty takes tests from the other pool, so no worker idles while
tests are left (on a machine with many cores the compute workers finish first and share the
wall-clock tests). ``tests/conftest.py`` lowers the CPU priority of a worker running a compute
test (``os.nice``), so that the lane's processes get a core when they wake: the wall-clock tests
run as promptly as on an idle machine, and the compute tests use the cores in the meantime.

The protocol is pytest-xdist's ``Scheduling`` (``xdist/scheduler/protocol.py``); no xdist
import at module level, so the tests of this module run without it.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

#: fewest tests a worker holds: an xdist worker starts a test once it knows the next one
MIN_PENDING = 2
#: a worker's queue is topped up to this many tests when it falls to :data:`MIN_PENDING`
QUEUED = 5
#: ... and then by the rest of the last test's module when at most this many of its tests are
#: left: a module of up to ``MODULE_TAIL + 1`` tests runs on one worker, so its module-scoped
#: fixtures (a KVLCC2 trial set, a compiled in-memory driver: seconds each) are made once, not
#: once per worker that gets some of its tests
MODULE_TAIL = 8


def auto_workers(config: Any) -> int | None:
    """The number of workers for ``-n auto``: pytest-xdist's own count (one per core, or
    ``PYTEST_XDIST_AUTO_NUM_WORKERS``) plus one for the wall-clock lane; None (xdist decides)
    when the user set ``PYTEST_XDIST_AUTO_NUM_WORKERS``."""
    import os

    from xdist.plugin import pytest_xdist_auto_num_workers as xdist_count

    if os.environ.get("PYTEST_XDIST_AUTO_NUM_WORKERS"):
        return None
    return xdist_count(config) + 1


class LaneScheduling:
    """pytest-xdist scheduler: the wall-clock tests on the last worker, the rest on the others.

    Parameters
    ----------
    numnodes : int
        Workers expected to submit a collection.
    is_waiting : callable
        ``is_waiting(nodeid) -> bool``: True for a test that waits on the wall clock.
    log : callable, optional
        ``log(*args)``, pytest-xdist's scheduler log.
    """

    def __init__(self, numnodes: int, is_waiting: Callable[[str], bool], log: Callable[..., Any] | None = None):
        self.numnodes = numnodes
        self.is_waiting = is_waiting
        self.log = log or (lambda *args: None)
        self.node2collection: dict[Any, list[str]] = {}
        self.node2pending: dict[Any, list[int]] = {}
        self.collection: list[str] | None = None
        self.pools: dict[str, list[int]] = {"wait": [], "compute": []}
        self.lane: Any = None

    # ------------------------------------------------------------ state the session reads
    @property
    def nodes(self) -> list[Any]:
        return list(self.node2pending)

    @property
    def collection_is_completed(self) -> bool:
        return len(self.node2collection) >= self.numnodes

    @property
    def tests_finished(self) -> bool:
        if not self.collection_is_completed or any(self.pools.values()):
            return False
        return all(len(p) < MIN_PENDING for p in self.node2pending.values())

    @property
    def has_pending(self) -> bool:
        return any(self.pools.values()) or any(self.node2pending.values())

    # ------------------------------------------------------------------- nodes
    def add_node(self, node: Any) -> None:
        assert node not in self.node2pending
        self.node2pending[node] = []

    def add_node_collection(self, node: Any, collection: Sequence[str]) -> None:
        assert node in self.node2pending
        if self.collection is not None and list(collection) != self.collection:
            self.log(f"worker {node.gateway.id} collected other tests than the first worker: not used")
            return
        self.node2collection[node] = list(collection)

    def remove_node(self, node: Any) -> str | None:
        """Forget a worker; a crashed worker's unfinished tests go back to their pools and the
        test it was running is returned (the session reports it as the crash)."""
        pending = self.node2pending.pop(node)
        if node is self.lane:
            self.lane = None
        if not pending:
            return None
        assert self.collection is not None
        crashed = self.collection[pending.pop(0)]
        for index in pending:
            self.pools[self._pool_of(index)].append(index)
        for other in self.nodes:
            self.check_schedule(other)
        return crashed

    # ------------------------------------------------------------------- tests
    def schedule(self) -> None:
        """Split the collection into the two pools and give every worker its first tests."""
        assert self.collection_is_completed
        if self.collection is None:
            collections = list(self.node2collection.values())
            if any(c != collections[0] for c in collections[1:]):
                self.log("**Different tests collected, aborting run**")
                return
            self.collection = collections[0]
            for index in range(len(self.collection)):
                self.pools[self._pool_of(index)].append(index)
        if len(self.nodes) > 1 and self.lane is None:
            self.lane = max(self.nodes, key=lambda n: _worker_number(n))
        for node in self.nodes:
            self.check_schedule(node)

    def mark_test_complete(self, node: Any, item_index: int, duration: float = 0) -> None:
        self.node2pending[node].remove(item_index)
        self.check_schedule(node)

    def mark_test_pending(self, item: str) -> None:
        assert self.collection is not None
        index = self.collection.index(item)
        self.pools[self._pool_of(index)].insert(0, index)
        for node in self.nodes:
            self.check_schedule(node)

    def remove_pending_tests_from_node(self, node: Any, indices: Sequence[int]) -> None:
        raise NotImplementedError()

    def check_schedule(self, node: Any) -> None:
        """Top up ``node``'s queue from its own pool, else from the other; shut it down when
        both pools are empty. Queues stay short (:data:`QUEUED`), so that when the pools run
        dry no worker is left holding a long list of tests the others could have run."""
        if node.shutting_down:
            return
        own = "wait" if node is self.lane else "compute"
        pool = self.pools[own] or self.pools["compute" if own == "wait" else "wait"]
        if not pool:
            node.shutdown()
            return
        pending = self.node2pending[node]
        if len(pending) > MIN_PENDING:
            return
        send = pool[:QUEUED - len(pending)]
        send += self._rest_of_module(pool, len(send))
        del pool[:len(send)]
        pending.extend(send)
        node.send_runtest_some(send)

    def _rest_of_module(self, pool: list[int], taken: int) -> list[int]:
        """The tests of ``pool`` after the first ``taken`` that belong to the module of the last
        one taken, if there are at most :data:`MODULE_TAIL` of them (else none)."""
        assert self.collection is not None
        if taken == 0:
            return []
        module = _module(self.collection[pool[taken - 1]])
        end = taken
        while end < len(pool) and _module(self.collection[pool[end]]) == module:
            end += 1
            if end - taken > MODULE_TAIL:
                return []
        return pool[taken:end]

    def _pool_of(self, index: int) -> str:
        assert self.collection is not None
        return "wait" if self.is_waiting(self.collection[index]) else "compute"


def _module(nodeid: str) -> str:
    """``tests/test_a.py::test_x[1]`` -> ``tests/test_a.py``."""
    return nodeid.split("::", 1)[0]


def _worker_number(node: Any) -> int:
    """``gw3`` -> 3 (pytest-xdist's worker ids)."""
    digits = "".join(ch for ch in str(node.gateway.id) if ch.isdigit())
    return int(digits) if digits else 0
