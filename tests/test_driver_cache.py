"""Compiled drivers cached across processes (steerlab.jit.drivers): loaded, never stale,
safe under concurrent writers, rebuilt when corrupt; kernels named for a fresh process."""

from __future__ import annotations

import json
import os
from dataclasses import replace
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from steerlab.jit import kernel_refs
from steerlab.control.registry import get_controller
from steerlab.control.wave_filtered import wave_filtered
from steerlab.sensors.wrapper import sensed_spec

SRC = Path(__file__).resolve().parent.parent / "src"

SCRIPT = textwrap.dedent("""
    import json, sys
    from steerlab.guidance.reference_models import course_guide
    from steerlab.jit import drivers
    from steerlab.jit.loop_calls import loop_driver
    from steerlab.sim.engine import simulate
    from steerlab.sim.scenario import scenario_from_dict
    from steerlab.sim.setup import build
    s = build(scenario_from_dict({
        "name": "cache", "seed": 0, "dt": 0.1, "duration": 60.0,
        "ship": {"model": "nomoto1", "speed_kn": 10.0}, "controller": {"type": "pid"},
        "guidance": {"psi0_deg": 0.0, "changes": [{"t": 1.0, "psi_deg": 10.0}]}, "environment": {}}))
    r = simulate(s)
    d, _ = loop_driver(s.ship.rhs, s.controller.update, course_guide, s.x0.shape[0])
    print(json.dumps({"last": r.states[-1].tolist(), "cached": d._steerlab_cached,
                      "hits": sum(d.run.stats.cache_hits.values()),
                      "misses": sum(d.run.stats.cache_misses.values())}))
""")


def _run(cache: Path, src: Path = SRC, wait=True):
    env = {**os.environ, "STEERLAB_CACHE_DIR": str(cache), "PYTHONPATH": str(src)}
    env.pop("STEERLAB_DRIVER_CACHE", None)
    # NUMBA_CACHE_DIR (.ci/run-pins sets it for the whole suite) would move numba's files out of the test's folder
    env.pop("NUMBA_CACHE_DIR", None)
    p = subprocess.Popen([sys.executable, "-c", SCRIPT], env=env, stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True)
    return _result(p) if wait else p


def _result(p):
    out, err = p.communicate(timeout=600)
    assert p.returncode == 0, err
    return json.loads(out.strip().splitlines()[-1])


@pytest.fixture(scope="module")
def compiled_once(tmp_path_factory):
    """``(cache, result, concurrent)``: two processes started at once on an empty cache (both
    compile the loop and save it: the concurrent-writers case), then a fresh process on a copy of
    that cache; ``result`` is the run of a process that compiled, ``concurrent`` the three runs.
    Shared by the tests that start from that cache (each on its own copy of it): one cold
    compile for the test session, whichever pytest-xdist workers run these tests."""
    from conftest import once_per_session

    def make(folder: Path) -> dict:
        cache = folder / "cache"
        cache.mkdir()
        procs = [_run(cache, wait=False) for _ in range(2)]
        a, b = (_result(p) for p in procs)
        fresh = _run(_copy(cache, folder / "fresh"))
        return {"cache": str(cache), "first": a if a["misses"] == 1 else b, "runs": {"a": a, "b": b, "fresh": fresh}}

    made = once_per_session(tmp_path_factory, "driver-cache-compiled-once", make)
    return Path(made["cache"]), made["first"], made["runs"]


def _copy(cache: Path, to: Path) -> Path:
    shutil.copytree(cache, to)
    return to


def test_a_fresh_process_loads_the_compiled_loop_instead_of_compiling(compiled_once):
    _, first, runs = compiled_once
    assert first["cached"] and first["misses"] == 1 and first["hits"] == 0      # compiled, saved
    second = runs["fresh"]
    assert second["misses"] == 0 and second["hits"] == 1                         # loaded
    assert second["last"] == first["last"]                                        # same bits


def test_two_processes_compiling_the_same_combination_at_once_both_succeed(compiled_once):
    _, _, runs = compiled_once
    a, b = runs["a"], runs["b"]
    assert a["cached"] and b["cached"] and a["last"] == b["last"]                 # both succeeded, same bits
    assert runs["fresh"]["hits"] == 1 and runs["fresh"]["last"] == a["last"]      # what they saved loads


def test_truncated_cache_files_are_detected_and_rebuilt(compiled_once, tmp_path):
    cache, ref, _ = compiled_once
    cache = _copy(cache, tmp_path / "cache")
    files = [f for f in cache.rglob("*") if f.suffix in (".nbi", ".nbc", ".py")]
    assert any(f.suffix == ".nbc" for f in files)
    for f in files:                                   # truncate every entry, the module too
        data = f.read_bytes()
        f.write_bytes(data[: len(data) // 3])
    again = _run(cache)
    assert again["last"] == ref["last"] and again["misses"] == 1                 # rebuilt, no crash
    assert _run(cache)["hits"] == 1                                              # and cached again


@pytest.mark.slow
def test_a_changed_steerlab_never_serves_stale_code(compiled_once, tmp_path):
    """A real source change in a copy of the package (the Nomoto 1 ship's equation) gives the
    new numbers in the next fresh process, with the same cache directory (one where the loop
    of the unchanged source is cached, and served to the copy)."""
    src = tmp_path / "src"
    shutil.copytree(SRC / "steerlab", src / "steerlab",
                    ignore=shutil.ignore_patterns("__pycache__"))
    cache, ref, _ = compiled_once
    cache = _copy(cache, tmp_path / "cache")
    before = _run(cache, src)
    assert before["hits"] == 1 and before["last"] == ref["last"]
    model = src / "steerlab" / "ships" / "nomoto1.py"
    text = model.read_text()
    term = "(p[P_K] * (delta + w[W_RUDDER]) - r)"
    assert term in text, "test needs the Nomoto 1 equation as written"
    new = text.replace(term, "(2.0 * p[P_K] * (delta + w[W_RUDDER]) - r)")   # twice the rudder gain
    model.write_text(new)
    after = _run(cache, src)
    assert after["misses"] == 1 and after["last"] != before["last"]


def test_wrapped_kernels_have_references_that_resolve_to_themselves():
    pid = get_controller("pid")
    for spec in (wave_filtered(pid), sensed_spec(pid), sensed_spec(wave_filtered(pid))):
        ref = kernel_refs.kernel_ref(spec.update)
        assert ref is not None and ref[0] == "bound"
        assert kernel_refs.resolve(eval(repr(ref))) is spec.update        # repr is the source form
    assert kernel_refs.resolve(kernel_refs.kernel_ref(pid.update)) is pid.update


def test_kernels_that_cannot_be_named_run_from_an_in_memory_driver(tmp_path, monkeypatch):
    """A ship kernel made in a closure (no importable name) still runs, compiled in the process,
    and gives the same numbers as the named kernel through the cached driver."""
    from conftest import make_scenario, unnamed_ship

    from steerlab.guidance.reference_models import course_guide
    from steerlab.jit.loop_calls import loop_driver
    from steerlab.sim.engine import simulate
    from steerlab.sim.setup import build

    monkeypatch.setenv("STEERLAB_CACHE_DIR", str(tmp_path))
    setup = build(make_scenario(duration=30.0, ship={"model": "nomoto1", "speed_kn": 10.0}))
    rhs = unnamed_ship(setup.ship.rhs)
    assert kernel_refs.kernel_ref(rhs) is None
    d, _ = loop_driver(rhs, setup.controller.update, course_guide, setup.x0.shape[0])
    assert d._steerlab_cached is False
    a = simulate(setup)
    b = simulate(replace(setup, ship=replace(setup.ship, rhs=rhs)))
    np.testing.assert_array_equal(a.states, b.states)


def test_a_ships_one_loop_runs_every_law_and_a_law_compiles_once_for_every_ship():
    """The single run's loop is the ship's: a second law on the ship compiles only that law's
    entry (no loop, no plant), the first law on a second ship only that ship's loop (its entry
    is already compiled), and every run's numbers are those of the readable engine."""
    from conftest import make_scenario, unnamed_law, unnamed_ship
    from numba.core import event

    from steerlab.jit import loop_calls
    from steerlab.sim.engine import simulate, simulate_readable
    from steerlab.sim.setup import build

    if not loop_calls.by_address():
        pytest.skip("this numba is outside the tested versions: every loop inlines its law")
    compiled = []
    ships, laws = {}, {}
    for ship, law in (("a", "pid"), ("a", "sliding_mode"), ("b", "pid")):
        setup = build(make_scenario(duration=20.0, ship={"model": "nomoto1", "speed_kn": 10.0},
                                    controller={"type": law}))
        # new kernels, never compiled before in this process nor on disk: their code is built in memory
        rhs = ships.setdefault(ship, unnamed_ship(setup.ship.rhs))
        update = laws.setdefault(law, unnamed_law(setup.controller.update))
        setup = replace(setup, ship=replace(setup.ship, rhs=rhs), controller=replace(setup.controller, update=update))
        with event.install_recorder("numba:compile") as rec:
            result = simulate(setup)
        compiled.append({e.data["dispatcher"].py_func.__name__ for _, e in rec.buffer if e.is_start})
        np.testing.assert_array_equal(result.states, simulate_readable(setup).states)
    loop = {"run", "loop", "rk4", "plant_rhs"}
    assert loop <= compiled[0]                                     # ship a's loop
    assert not loop & compiled[1] and "sample_entry" in compiled[1]     # only the second law's entry
    assert loop <= compiled[2] and "sample_entry" not in compiled[2]    # ship b's loop; pid's entry is there


UNPICKLE = textwrap.dedent("""
    import json, pickle, sys
    from steerlab.jit.kernel_refs import kernel_ref
    from steerlab.jit.drivers import driver
    import kmod
    rhs, upd = pickle.loads(open(sys.argv[1], "rb").read())
    mod = driver(rhs, upd, None, 7)
    print(json.dumps({"copy": rhs is not kmod.rhs, "ref": kernel_ref(rhs), "cached": mod._steerlab_cached}))
""")
KMOD = textwrap.dedent("""
    import numba

    @numba.njit
    def rhs(t, x, delta, w, p, dx):
        dx[:] = 0.0
        dx[2] = x[5]
        dx[5] = (p[1] * delta - x[5]) / p[0]{extra}
""")


def test_a_kernel_unpickled_in_another_process_keeps_its_name_unless_its_code_changed(tmp_path):
    """numba pickles a dispatcher by its function's code, so another process (a spawned child, a
    Dask worker) unpickles a new dispatcher, not the module's: still named (its driver from the
    disk cache, not compiled in every such process) when its code is the module's, and not named
    (compiled in memory) when the module's code has changed since it was pickled."""
    import pickle

    from steerlab.control.pid import pid_update

    (tmp_path / "kmod.py").write_text(KMOD.format(extra=""))
    sys.path.insert(0, str(tmp_path))
    try:
        import kmod

        (tmp_path / "k.pkl").write_bytes(pickle.dumps((kmod.rhs, pid_update)))
    finally:
        sys.path.remove(str(tmp_path))
        sys.modules.pop("kmod", None)
    env = {**os.environ, "STEERLAB_CACHE_DIR": str(tmp_path / "cache"),
           "PYTHONPATH": os.pathsep.join([str(tmp_path), str(SRC)])}
    env.pop("STEERLAB_DRIVER_CACHE", None)

    def child() -> dict:
        p = subprocess.run([sys.executable, "-c", UNPICKLE, str(tmp_path / "k.pkl")], env=env,
                           capture_output=True, text=True, timeout=300)
        assert p.returncode == 0, p.stderr
        return json.loads(p.stdout.strip().splitlines()[-1])

    same = child()
    assert same == {"copy": True, "ref": ["ref", "kmod:rhs"], "cached": True}
    (tmp_path / "kmod.py").write_text(KMOD.format(extra=" + 0.0"))
    changed = child()
    assert changed == {"copy": True, "ref": None, "cached": False}
