"""Where the test suite's time goes: a pytest plugin, loaded on demand (not by ``tests/conftest.py``).

Usage, from the repository root (``-p`` loads it in the controller and in every pytest-xdist
worker; each log is switched on by its variable)::

    PYTHONPATH=benchmarks STEERLAB_TEST_TIMES=times.txt python3 -m pytest -q -p suite_profile
    sort -rn times.txt | head                      # the slowest test phases, readable while it runs

* ``STEERLAB_TEST_TIMES=FILE``: ``seconds phase nodeid`` for every test phase (setup, call,
  teardown) of at least 0.05 s, as it finishes (written by the controller only).
* ``STEERLAB_TEST_CPU=FILE``: ``cpu_s wall_s nodeid children_cpu_s`` for every test (setup, call
  and teardown together; CPU of the worker and the subprocesses it waited for, ``getrusage``,
  and of those subprocesses alone): which tests use the cores, which wait (sockets, sleeps,
  other processes' locks) and which spend their CPU in the commands they start. POSIX only.
* ``STEERLAB_TEST_COMPILES=FILE``: ``seconds worker nodeid function depth`` for every function
  numba compiles (not a disk-cache load) while a test runs (``depth`` 0: a compile no other
  compile started, whose seconds include those it started; sum depth 0 for the total), so that a suite's compile time can be
  traced to its tests and combinations compiled by both workers found (``sort -k4 FILE``);
  what ``.ci/warm-cache`` should warm.
* ``STEERLAB_TEST_TIMELINE=FILE``: ``start end worker nodeid`` (Unix times [s]) for every test
  of at least 0.05 s: which worker ran what when, and what ran alone at the end of the run.

The timings are for finding work to cut; no test decides anything by them.
"""

from __future__ import annotations

import os
import time

import pytest


def pytest_runtest_logreport(report):
    path = os.environ.get("STEERLAB_TEST_TIMES")
    # under pytest-xdist the controller gets every worker's reports: write there only
    if path and report.duration >= 0.05 and not os.environ.get("PYTEST_XDIST_WORKER"):
        with open(path, "a", encoding="utf-8") as f:
            f.write(f"{report.duration:.2f} {report.when} {report.nodeid}\n")


def _cpu_seconds() -> tuple[float, float]:
    """User + system CPU of this process and of its waited-for children, and of those children
    alone [s]."""
    import resource

    own, kids = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    children = kids.ru_utime + kids.ru_stime
    return own.ru_utime + own.ru_stime + children, children


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item, nextitem):
    path = os.environ.get("STEERLAB_TEST_CPU")
    timeline = os.environ.get("STEERLAB_TEST_TIMELINE")
    if not (path or timeline) or os.name != "posix":
        yield
        return
    (c0, k0), t0, start = _cpu_seconds(), time.perf_counter(), time.time()
    yield
    (c1, k1), wall = _cpu_seconds(), time.perf_counter() - t0
    if wall >= 0.05 and path:
        with open(path, "a", encoding="utf-8") as f:
            f.write(f"{c1 - c0:.2f} {wall:.2f} {item.nodeid} {k1 - k0:.2f}\n")
    if wall >= 0.05 and timeline:
        with open(timeline, "a", encoding="utf-8") as f:
            f.write(f"{start:.2f} {start + wall:.2f} {os.environ.get('PYTEST_XDIST_WORKER', '-')} {item.nodeid}\n")


def _listen_to_compiles(path: str) -> None:
    """Registers a numba ``numba:compile`` listener appending to ``path``."""
    import numba.core.event as ev

    class Listener(ev.Listener):
        starts: list = []

        def on_start(self, event):
            self.starts.append(time.perf_counter())

        def on_end(self, event):
            disp = event.data.get("dispatcher")
            func = getattr(disp, "py_func", None)
            name = f"{getattr(func, '__module__', '?')}.{getattr(func, '__qualname__', '?')}"
            seconds = time.perf_counter() - self.starts.pop()
            with open(path, "a", encoding="utf-8") as f:
                f.write(f"{seconds:.2f} {os.environ.get('PYTEST_XDIST_WORKER', '-')} "
                        f"{os.environ.get('PYTEST_CURRENT_TEST', '-').split(' ')[0]} {name} {len(self.starts)}\n")

    ev.register("numba:compile", Listener())


def pytest_configure(config):
    if os.environ.get("STEERLAB_TEST_COMPILES"):
        _listen_to_compiles(os.environ["STEERLAB_TEST_COMPILES"])
