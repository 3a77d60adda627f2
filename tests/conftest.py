"""Shared helpers for the core test suite.

Scenarios are built from plain dicts (the TOML shape) so every test goes through the same
validation as a user file. Compiled runs reuse two (ship, controller) combinations only,
esso+pid and esso+adrc, so each compiles once per test process.
"""

from __future__ import annotations

import copy
import os
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


def unnamed_law(update):
    """A controller kernel that calls ``update`` from a closure: the same orders, no importable
    name (its loops' sample entry is built in memory, new for every call of this function)."""
    import numba

    @numba.njit
    def closure_update(z, p, t, x, ref, h):
        return update(z, p, t, x, ref, h)
    return closure_update


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
REAL_PART_FILES = ("test_runtime_browser.py", "test_runtime_browser_rebinding.py", "test_runtime_browser_phone.py",
                   "test_signalk_plugin.py", "test_gym_sb3.py")
"""Tests of real parts (Debian's chromium, a real signalk-server, its NMEA 0183 parser, node;
Stable-Baselines3 with torch's CPU build).
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
        terminalreporter.write_line("real parts: browser, Signal K server, NMEA parser and SB3 tests ran (none skipped)")


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


# ---------------------------------------------------- the real-time tests, on one worker
REALTIME_MODULES = ("tests/test_runtime_*.py", "tests/test_signalk_plugin.py")
"""The tests of the real-time link (ship server and autopilot over loopback sockets, the browser
bridge, the Signal K server): they wait on the wall clock. They are marked ``realtime``
(``-m "not realtime"`` leaves them out) and ``xdist_group("realtime")``: under pytest-xdist's
``--dist loadgroup`` (``pyproject.toml``) they run one after another on one worker, never two
sets of real-time processes at once, while the other workers (one per core:
:func:`pytest_xdist_auto_num_workers`) run the rest."""


@pytest.hookimpl(hookwrapper=True, optionalhook=True)     # optional: a run without pytest-xdist
def pytest_xdist_auto_num_workers(config):
    """``-n auto``: one pytest-xdist worker per core (pytest-xdist's count, which honours
    ``PYTEST_XDIST_AUTO_NUM_WORKERS``) and one more when the real-time tests may run
    (:func:`may_select_realtime`): their worker mostly waits on the wall clock (on two cores it
    used about 105 s of CPU in 234 s), and the extra worker compiles and runs other tests on
    the core it leaves idle."""
    outcome = yield
    count = outcome.get_result()
    if not os.environ.get("PYTEST_XDIST_AUTO_NUM_WORKERS") and may_select_realtime(config.getoption("markexpr", "")):
        outcome.force_result(count + 1)


def may_select_realtime(markexpr: str) -> bool:
    """Whether the ``-m`` expression ``markexpr`` selects a test that carries the mark
    ``realtime`` and no other of the suite's marks (a real-time test): ``""``, ``"not slow"``
    yes; ``"not realtime"``, ``"conformance"`` no. An expression this cannot read counts as yes."""
    import re

    if not (markexpr or "").strip():
        return True
    words = re.sub(r"\b(?!(?:and|or|not)\b)[A-Za-z_][\w.]*\b",
                   lambda m: "True" if m.group(0) == "realtime" else "False", markexpr)
    if re.search(r"[^\w\s()]", words):
        return True
    try:
        return bool(eval(words, {"__builtins__": {}}, {}))      # only True/False, and/or/not, ()
    except SyntaxError:
        return True


def is_realtime(nodeid: str) -> bool:
    """True for a test of one of :data:`REALTIME_MODULES` (``nodeid`` relative to the repository)."""
    from fnmatch import fnmatch

    module = nodeid.split("::", 1)[0]
    return any(fnmatch(module, pattern) for pattern in REALTIME_MODULES)


def shared_result_group(item) -> str:
    """The ``xdist_group`` of a test that uses a fixture computed by :func:`once_per_session`
    (a fixture whose function calls it), named after that fixture; ``""`` for any other test.

    Such tests share one pytest-xdist worker: without the group, both workers could reach the
    fixture at once and one would wait on :func:`once_per_session`'s lock, a core idle for as
    long as the fixture takes (the random plants: about 170 s of one core on a cold cache,
    measured 2026-11-29), while with it the other worker runs other tests meanwhile."""
    infos = getattr(getattr(item, "_fixtureinfo", None), "name2fixturedefs", {})
    for name in getattr(item, "fixturenames", ()):
        for fixturedef in infos.get(name, ()):
            code = getattr(getattr(fixturedef, "func", None), "__code__", None)
            if code is not None and "once_per_session" in code.co_names:
                return f"{fixturedef.func.__module__}.{name}"
    return ""


EVALUATION_MARK = "conformance"
"""The marker of the conformance evaluation (issue 30's evidence: the 1 804-case catalogue
matrix and the 256 random plants, about 9 minutes of CPU from a cold cache, most of it
compiling one loop per ship and law). The default run leaves these tests out; ``-m conformance``
(or any ``-m`` expression naming the mark) runs them, and ``.ci/run`` runs them as its second
step (docs/ci.md). So the README's test command does not wait for the evaluation, and CI still
holds the catalogue to its targets."""


def _evaluation_selected(config) -> bool:
    return EVALUATION_MARK in (config.getoption("markexpr", "") or "")


@pytest.hookimpl(tryfirst=True)      # before pytest-xdist's worker reads the xdist_group marks
def pytest_collection_modifyitems(config, items):
    if not _evaluation_selected(config):
        left_out = [item for item in items if item.get_closest_marker(EVALUATION_MARK)]
        if left_out:
            config.hook.pytest_deselected(items=left_out)
            items[:] = [item for item in items if not item.get_closest_marker(EVALUATION_MARK)]
    for item in items:
        if is_realtime(item.nodeid):
            item.add_marker(pytest.mark.realtime)
            item.add_marker(pytest.mark.xdist_group("realtime"))
        elif not item.get_closest_marker("xdist_group") and (group := shared_result_group(item)):
            item.add_marker(pytest.mark.xdist_group(group))     # a group the test names itself wins


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

