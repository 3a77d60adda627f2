"""Shared helpers for the core test suite.

Scenarios are built from plain dicts (the TOML shape) so every test goes through the same
validation as a user file. Compiled runs reuse two (ship, controller) combinations only,
esso+pid and esso+adrc, so each compiles once per test process.
"""

from __future__ import annotations

import copy
import os
import time
from pathlib import Path

import pytest

# numpy's OpenBLAS on one thread, as in the steerlab command (steerlab.jit.blas_threads): the commands
# the tests run in this process fork (figure children, pools), and OpenBLAS restarts its
# busy-waiting threads after every fork (7-8 % of the CPU of the command tests, measured
# alternately under pytest-xdist). Set before numpy is first imported (the line below); a value
# the user set is kept; subprocesses inherit it.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

from steerlab.sim.scenario import scenario_from_dict  # noqa: E402

# Subprocess tests (``python -m steerlab ...``) must import this checkout's ``src`` (pytest's
# ``pythonpath`` only reaches this process), whichever checkout an editable install points to.
_SRC = str(Path(__file__).resolve().parent.parent / "src")
os.environ["PYTHONPATH"] = os.pathsep.join(p for p in (_SRC, os.environ.get("PYTHONPATH")) if p)
# figures without a display, in this process (commands run in-process) and in subprocesses
os.environ.setdefault("MPLBACKEND", "Agg")

BASE = {
    "name": "test",
    "seed": 0,
    "dt": 0.1,
    "duration": 300.0,
    "ship": {"model": "esso", "speed_kn": 16.0},
    "controller": {"type": "pid", "gains": "paper"},   # the vehicle of many tests: Zwierzewicz et al. (2021) gains
    "guidance": {"psi0_deg": 0.0, "changes": []},
    "environment": {},
}


def _merge(base: dict, over: dict) -> dict:
    out = copy.deepcopy(base)
    for k, v in over.items():
        if isinstance(v, dict) and isinstance(out.get(k), dict) and k != "controller":
            out[k] = _merge(out[k], v)
        else:
            out[k] = copy.deepcopy(v)
    return out


def import_tool(name: str):
    """A module of the repository's ``tools/`` folder (not a package), e.g. ``docs_hooks``."""
    import importlib
    import sys

    tools = str(Path(__file__).resolve().parent.parent / "tools")
    sys.path.insert(0, tools)
    try:
        return importlib.import_module(name)
    finally:
        sys.path.remove(tools)


def batch_parity_and_vectorisation(setup):
    """Three PID runs of ``setup`` (the middle one with Kp doubled) as a batch and one by one:
    ``(single final states, batch final states, vectorisation report)``."""
    import numpy as np

    from steerlab.control.pid import C_KP
    from steerlab.sim.batch import simulate_batch, vary_controller
    from steerlab.sim.engine import simulate_compiled
    from steerlab.sim.lanes import vectorisation_report

    pcs = np.tile(setup.pc, (3, 1))
    pcs[1, C_KP] *= 2.0
    runs = vary_controller(setup, pcs)
    batch = simulate_batch(runs)
    single = np.array([simulate_compiled(s).states[-1] for s in runs])
    return single, batch.final_states, vectorisation_report(setup.ship.rhs, setup.controller.update, setup.x0.size)


def unnamed_ship(rhs):
    """A ship kernel that calls ``rhs`` from a closure: the same numbers, but no importable name
    (:func:`steerlab.jit.kernel_refs.kernel_ref` gives None), so drivers are built in memory."""
    import numba

    @numba.njit
    def closure_rhs(t, x, delta, w, ps, dx):
        rhs(t, x, delta, w, ps, dx)
    return closure_rhs


def make_scenario_dict(**over) -> dict:
    """The base dict with top-level / nested overrides (``controller`` is replaced whole)."""
    return _merge(BASE, over)


def make_scenario(**over):
    return scenario_from_dict(make_scenario_dict(**over))


@pytest.fixture(scope="session")
def control():
    """python-control, imported by the tests that use it rather than at collection (every
    pytest-xdist worker collects every test module; the import costs about 0.5-2 s each time)."""
    return pytest.importorskip("control")


@pytest.fixture
def scenario():
    """Factory: ``scenario(duration=..., controller={...}, guidance={...})`` -> Scenario."""
    return make_scenario


# ---------------------------------------------------------------- real parts must run in CI
REAL_PART_FILES = ("test_runtime_browser.py", "test_runtime_browser_rebinding.py", "test_signalk_plugin.py")
"""Tests of real parts (Debian's chromium, a real signalk-server, its NMEA 0183 parser, node).
Locally they skip with a reason where a part is missing; with ``STEERLAB_REQUIRE_REAL_PARTS=1``
(set by ``.ci/run``, which installs the parts) a skip of any of them fails the run."""


def _real_part_skips(terminalreporter) -> list:
    out = []
    for rep in terminalreporter.stats.get("skipped", []):
        where = str(getattr(rep, "nodeid", "") or getattr(rep, "fspath", ""))
        if any(name in where for name in REAL_PART_FILES) or any(
                name in str(rep.longrepr) for name in REAL_PART_FILES):
            out.append(f"{where}: {rep.longrepr[-1] if isinstance(rep.longrepr, tuple) else rep.longrepr}")
    return out


def pytest_terminal_summary(terminalreporter, exitstatus, config):
    if os.environ.get("STEERLAB_REQUIRE_REAL_PARTS") != "1":
        return
    skips = _real_part_skips(terminalreporter)
    if skips:
        terminalreporter.write_line("real-part tests skipped although STEERLAB_REQUIRE_REAL_PARTS=1:", red=True)
        for s in skips:
            terminalreporter.write_line(f"  {s}", red=True)
        config._steerlab_real_parts_skipped = True
    else:
        terminalreporter.write_line("real parts: browser, Signal K server and NMEA parser tests ran (none skipped)")


def pytest_sessionfinish(session, exitstatus):
    if os.environ.get("STEERLAB_REQUIRE_REAL_PARTS") != "1" or hasattr(session.config, "workerinput"):
        return
    reporter = session.config.pluginmanager.get_plugin("terminalreporter")
    if reporter is not None and _real_part_skips(reporter) and session.exitstatus == 0:
        session.exitstatus = 1


# ------------------------------------------------------- Ctrl-C reaches the processes tests start
def pytest_configure(config):
    """Tests stop a steerlab process as a user does, with Ctrl-C (SIGINT, exit 130). A shell that
    starts pytest as a background job (``pytest &`` in a script) makes it ignore SIGINT, and an
    ignored signal stays ignored in every process started from it, so that Ctrl-C would do
    nothing there (Python keeps an inherited ignore). Here SIGINT gets Python's own handler
    back; the processes the tests start then begin with SIGINT at its default."""
    import signal

    if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
        signal.signal(signal.SIGINT, signal.default_int_handler)


# ------------------------------------------- a worker of their own for the wall-clock tests
REALTIME_MODULES = ("tests/test_runtime_*.py", "tests/test_signalk_plugin.py")
"""The tests of the real-time link (ship server and autopilot over loopback sockets, the browser
bridge, the Signal K server): they wait on the wall clock. They are marked ``realtime``
(``-m "not realtime"`` leaves them out) and, under ``-n auto``, run on a worker of their own
beside one per core (``tests/xdist_lanes.py``)."""

#: ``STEERLAB_TEST_LANES=0``: pytest-xdist's own ``-n auto`` and ``load`` scheduling instead
#: (one worker per core, every test anywhere; ``benchmarks/bench_test_lanes.py`` compares them)
LANES = os.environ.get("STEERLAB_TEST_LANES", "1") != "0"

#: the CPU niceness of a pytest-xdist worker while it runs a compute test (not ``realtime``):
#: when a real-time test's processes wake they get a core at once
COMPUTE_NICENESS = 10


def is_realtime(nodeid: str) -> bool:
    """True for a test of one of :data:`REALTIME_MODULES` (``nodeid`` relative to the repository)."""
    from fnmatch import fnmatch

    module = nodeid.split("::", 1)[0]
    return any(fnmatch(module, pattern) for pattern in REALTIME_MODULES)


def lanes_wanted(config) -> bool:
    """Whether this run gets the real-time lane: ``STEERLAB_TEST_LANES`` is not ``0`` and the
    paths given to pytest may hold real-time tests (none given: the ``testpaths``; a folder; one
    of :data:`REALTIME_MODULES`). ``pytest tests/test_asa.py`` keeps one worker per core."""
    if not LANES:
        return False
    root = Path(str(config.rootpath)).resolve()
    for arg in config.args or config.getini("testpaths") or ["."]:
        path = Path(arg.split("::", 1)[0])
        if not path.is_absolute():
            path = Path(str(config.invocation_params.dir)) / path
        if path.is_dir():
            return True
        try:
            if is_realtime(path.resolve().relative_to(root).as_posix()):
                return True
        except ValueError:
            continue
    return False


def pytest_collection_modifyitems(config, items):
    for item in items:
        if is_realtime(item.nodeid):
            item.add_marker(pytest.mark.realtime)


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_auto_num_workers(config):
    from xdist_lanes import auto_workers

    return auto_workers(config) if lanes_wanted(config) else None


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_make_scheduler(config, log):
    if config.getvalue("dist") != "load" or not lanes_wanted(config):
        return None                   # the user chose another distribution, or no lane is needed
    from xdist.workermanage import parse_tx_spec_config
    from xdist_lanes import LaneScheduling

    return LaneScheduling(len(parse_tx_spec_config(config)), is_realtime, log.lanesched)


@pytest.hookimpl(optionalhook=True)
def pytest_configure_node(node):
    """Tells each pytest-xdist worker whether the lanes scheduler runs (the workers' own
    options do not say which distribution the controller uses)."""
    node.workerinput["steerlab_lanes"] = node.config.getvalue("dist") == "load" and lanes_wanted(node.config)


def under_lanes(config) -> bool:
    """True in a pytest-xdist worker of a run scheduled by ``tests/xdist_lanes.py``."""
    return bool(getattr(config, "workerinput", {}).get("steerlab_lanes"))


@pytest.hookimpl(tryfirst=True)
def pytest_runtest_setup(item):
    """Under the lanes scheduler, a worker runs compute tests at a lower CPU priority
    (:data:`COMPUTE_NICENESS`) than the real-time tests (see :data:`REALTIME_MODULES`). The
    priority only goes down: a worker that has run a compute test stays at it."""
    if not under_lanes(item.config) or not hasattr(os, "nice") or item.get_closest_marker("realtime"):
        return
    now = os.getpriority(os.PRIO_PROCESS, 0)
    if now < COMPUTE_NICENESS:
        os.nice(COMPUTE_NICENESS - now)


# ---------------------------------------------------------------- test times, as they finish
def pytest_runtest_logreport(report):
    """With ``STEERLAB_TEST_TIMES=FILE``, append ``seconds phase nodeid`` for every test phase
    as it finishes (all workers append to the same file): where the suite's time goes, readable
    while it runs (``sort -rn FILE | head``)."""
    path = os.environ.get("STEERLAB_TEST_TIMES")
    # under pytest-xdist the controller gets every worker's reports: write there only
    if path and report.duration >= 0.05 and not os.environ.get("PYTEST_XDIST_WORKER"):
        with open(path, "a", encoding="utf-8") as f:
            f.write(f"{report.duration:.2f} {report.when} {report.nodeid}\n")


def _cpu_seconds() -> float:
    """User + system CPU of this process and of its waited-for children [s]."""
    import resource

    own, kids = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + kids.ru_utime + kids.ru_stime


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item, nextitem):
    """With ``STEERLAB_TEST_CPU=FILE``, append ``cpu_s wall_s nodeid`` for every test (setup,
    call and teardown together; CPU of the worker and the subprocesses it waited for): which
    tests use the cores and which wait (sockets, sleeps, other processes' locks)."""
    path = os.environ.get("STEERLAB_TEST_CPU")
    if not path or os.name != "posix":
        yield
        return
    c0, t0 = _cpu_seconds(), time.perf_counter()
    yield
    cpu, wall = _cpu_seconds() - c0, time.perf_counter() - t0
    if wall >= 0.05:
        with open(path, "a", encoding="utf-8") as f:
            f.write(f"{cpu:.2f} {wall:.2f} {item.nodeid}\n")


# ------------------------------------------------------------- compiles, test by test
class _CompileLog:
    """numba ``numba:compile`` listener for ``STEERLAB_TEST_COMPILES=FILE``: appends ``seconds
    worker nodeid function`` for every function numba compiles (not a disk-cache load) while a
    test runs, so that a suite's compile time can be traced to its tests and combinations
    compiled by both workers can be found (``sort -k4 FILE``)."""

    def __init__(self, path: str):
        import numba.core.event as ev

        class Listener(ev.Listener):
            def on_start(inner, event):
                inner.t0 = time.perf_counter()

            def on_end(inner, event):
                disp = event.data.get("dispatcher")
                name = getattr(getattr(disp, "py_func", None), "__qualname__", "?")
                module = getattr(getattr(disp, "py_func", None), "__module__", "?")
                with open(path, "a", encoding="utf-8") as f:
                    f.write(f"{time.perf_counter() - inner.t0:.2f} {os.environ.get('PYTEST_XDIST_WORKER', '-')} "
                            f"{os.environ.get('PYTEST_CURRENT_TEST', '-').split(' ')[0]} {module}.{name}\n")

        self.listener = Listener()
        ev.register("numba:compile", self.listener)


if os.environ.get("STEERLAB_TEST_COMPILES"):
    _COMPILE_LOG = _CompileLog(os.environ["STEERLAB_TEST_COMPILES"])


# ------------------------------------------------- one expensive result for every worker
def once_per_session(tmp_path_factory, name: str, make):
    """``make(folder)``'s result (JSON-able), computed once per test session even when the
    tests that need it run in different pytest-xdist workers: the first worker to ask computes
    it in ``folder`` under the session's shared temporary root, holding a lock the others wait
    on, and keeps it in ``folder/result.json``, which the others read. Without ``fcntl`` (not
    POSIX), each worker computes it in a folder of its own."""
    import json

    try:
        import fcntl
    except ImportError:
        fcntl = None
    root = tmp_path_factory.getbasetemp()
    if os.environ.get("PYTEST_XDIST_WORKER") and fcntl is not None:
        root = root.parent                        # the folder every worker's basetemp is in
    folder = root / name
    with open(root / f"{name}.lock", "a") as lock:
        if fcntl is not None:
            fcntl.flock(lock, fcntl.LOCK_EX)     # released when the file closes
        result = folder / "result.json"
        if not result.exists():
            folder.mkdir(exist_ok=True)
            result.write_text(json.dumps(make(folder)))
        return json.loads(result.read_text())

