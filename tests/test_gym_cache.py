"""The Gymnasium environments' compiled step and reset are compiled once ever (issues 13/14):
generated from :mod:`steerlab.jit.env_template` into the driver cache like the engines'
drivers (:mod:`steerlab.jit.drivers`), loaded by a fresh process instead of compiled, with the
same numbers; kernels that cannot be named get the same module built in memory."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("gymnasium")

from test_docs_components import ESSO_GYM  # noqa: E402  (the group that fills the suite's cache with the Esso's)

SRC = Path(__file__).resolve().parent.parent / "src"

ENTRIES = ("step", "step_serial", "reset", "step_parallel", "reset_parallel")
SCRIPT = textwrap.dedent(f"""ENTRIES = {ENTRIES!r}""") + textwrap.dedent("""
    import json, sys
    import numpy as np
    from numba.core import event
    with event.install_recorder("numba:compile") as before:  # a steerlab command first, if any
        if sys.argv[1:]:
            from steerlab.cli import main
            assert main(sys.argv[1:]) == 0
    with event.install_recorder("numba:compile") as rec:     # every numba compile from here on
        import gymnasium as gym
        import steerlab.gym
        from steerlab.gym.plant_batch import env_kernels
        venv = gym.make_vec("steerlab/CourseKeeping-v0", num_envs=37, vectorization_mode="vector_entry_point",
                            episode_s=5.0)
        single = gym.make("steerlab/CourseKeeping-v0", episode_s=5.0)
        acts = np.random.default_rng(1).uniform(-1, 1, size=(7, 37, 1))
        vec = [venv.reset(seed=3)[0].tolist()] + [venv.step(a)[0].tolist() for a in acts]   # through an autoreset
        one = [single.reset(seed=3)[0].tolist()] + [single.step(a[0])[0].tolist() for a in acts[:5]]
        par = gym.make_vec("steerlab/CourseKeeping-v0", num_envs=37, vectorization_mode="vector_entry_point",
                           episode_s=5.0)
        par.unwrapped.core.threads_from, par.unwrapped.core.threads = 1, 2      # the threaded step and reset
        pvec = [par.reset(seed=3)[0].tolist()] + [par.step(a)[0].tolist() for a in acts]
    core = venv.unwrapped.core
    m = env_kernels(core.ship_spec.rhs, core.guide, core.X.shape[1])
    stats = {n: [sum(getattr(m, n).stats.cache_hits.values()), sum(getattr(m, n).stats.cache_misses.values())]
             for n in ENTRIES}
    print(json.dumps({"cached": m._steerlab_cached, "stats": stats, "compiles_before": len(before.buffer),
                      "compiles": len(rec.buffer), "vec": vec, "one": one, "pvec": pvec}))
""")
#: ``steerlab cache warm`` of the fewest combinations, with the Gymnasium environments
WARM_GYM = ["cache", "warm", "--ships", "esso", "--controllers", "pid", "--gym", "--quiet"]


def _run(cache: Path, *command: str) -> dict:
    """SCRIPT in a new process on the driver cache ``cache``, after ``steerlab COMMAND`` (through
    the entry point of ``python -m steerlab``, :func:`steerlab.cli.main`) in the same process."""
    env = {**os.environ, "STEERLAB_CACHE_DIR": str(cache), "PYTHONPATH": str(SRC)}
    env.pop("STEERLAB_DRIVER_CACHE", None)
    p = subprocess.run([sys.executable, "-c", SCRIPT, *command], env=env, capture_output=True, text=True,
                       timeout=900)
    assert p.returncode == 0, p.stderr
    return json.loads(p.stdout.strip().splitlines()[-1])


def _is_esso_course_keeping_env(module: Path) -> bool:
    """Is ``module`` (a generated ``d_<hash>.py``) the Esso course-keeping environment's step and
    reset (the module the environments of SCRIPT use)? A generated module starts as its
    template does (:data:`steerlab.gym.plant_batch.TEMPLATE`)."""
    from steerlab.gym.plant_batch import TEMPLATE

    head = TEMPLATE.read_text(encoding="utf-8").split("\n", 1)[0]
    text = module.read_text(encoding="utf-8", errors="replace")
    return (text.startswith(head) and "steerlab.ships.esso_3dof:esso_rhs" in text
            and "steerlab.guidance.reference_models:course_guide" in text)


def _seed_without_the_env_module(cache: Path) -> int:
    """Fill the empty driver cache ``cache`` with hard links (or copies) of this steerlab's
    drivers in the suite's own cache (which ``.ci/warm-cache`` fills), leaving out the Esso
    course-keeping environment module and its machine code: the first process then compiles
    that module and nothing else the test does not need (the Esso + PID loops, the route
    task's module, ...). Returns how many modules were left out (0 if the suite's cache had
    none: then it is compiled anyway)."""
    from steerlab.jit import drivers

    source = drivers.drivers_dir()
    if not source.is_dir():
        return 0
    left_out = {p.stem for p in source.glob("d_*.py") if _is_esso_course_keeping_env(p)}

    def ignore(folder, names):
        return [n for n in names if n.split(".")[0] in left_out or ".tmp" in n]

    def link_or_copy(src, dst):
        try:
            os.link(src, dst)
        except OSError:
            shutil.copy2(src, dst)

    shutil.copytree(source, cache / "drivers" / source.name, ignore=ignore, copy_function=link_or_copy)
    return len(left_out)


@pytest.fixture(scope="module")
def warmed(tmp_path_factory) -> dict:
    """One cold compile of the environments' module for the two tests that need one: on a
    driver cache without it (:func:`_seed_without_the_env_module`), a process runs ``steerlab
    cache warm --gym`` and then the environments (``first``); then a fresh process runs them on
    that cache (``fresh``). Made once per test session (shared by the pytest-xdist workers).

    Its tests run in the group (:data:`ESSO_GYM`) of the two tests that compile the Esso's loops
    and environments into the suite's cache, after them (file order): the seed then holds all
    but the module under test, which is all the first process compiles (on a cold suite cache it
    compiled the Esso's loops and its other environment too: 39 s of CPU, 18 s after it)."""
    from conftest import once_per_session

    def make(cache: Path) -> dict:
        _seed_without_the_env_module(cache)
        return {"first": _run(cache, *WARM_GYM), "fresh": _run(cache)}

    return once_per_session(tmp_path_factory, "gym-cache-warmed", make)


@pytest.mark.xdist_group(ESSO_GYM)
def test_a_fresh_process_loads_the_env_step_and_reset_and_compiles_nothing(warmed):
    first, second = warmed["first"], warmed["fresh"]
    assert first["cached"] and first["compiles_before"] > 0
    assert first["stats"] == {n: [0, 1] for n in ENTRIES}                                # compiled, saved
    assert second["stats"] == {n: [1, 0] for n in ENTRIES}                               # loaded
    assert second["compiles"] == 0                    # nothing else compiled either (plants, guidance, seas)
    assert second["vec"] == first["vec"] and second["one"] == first["one"]               # same bits
    assert [v[0] for v in first["vec"][:6]] == first["one"]                              # ship 0 = single env
    assert first["pvec"] == first["vec"]                                                 # threaded: same bits


def test_kernels_that_cannot_be_named_step_and_reset_from_an_in_memory_module():
    """A ship kernel made in a closure (no importable name) gets the environment's step and reset
    compiled in the process, with the same numbers as the named kernel's cached module (from
    the cache the rest of the suite uses, which ``.ci/warm-cache`` fills)."""
    from conftest import unnamed_ship

    from steerlab.jit import kernel_refs
    from steerlab.gym.episodes import Episodes
    from steerlab.gym.plant_batch import env_kernels

    a = Episodes(20, episode_s=4.0, vectorised=True)
    b = Episodes(20, episode_s=4.0, vectorised=True)
    rhs = unnamed_ship(a.ship_spec.rhs)
    assert kernel_refs.kernel_ref(rhs) is None
    named = env_kernels(a.ship_spec.rhs, a.guide, a.X.shape[1])
    mem = env_kernels(rhs, b.guide, b.X.shape[1])
    assert named._steerlab_cached and mem._steerlab_cached is False
    b._vstep, b._reset = mem.step, mem.reset
    acts = np.random.default_rng(2).uniform(-1, 1, size=(6, 20))
    for e in (a, b):
        e.reset_lanes(np.arange(20), seeds=list(range(20)))
    np.testing.assert_array_equal(a.obs, b.obs)
    flags = [tuple(np.zeros(20, dtype=bool) for _ in range(3)) for _ in (a, b)]
    for k in range(6):                                # through an autoreset (4 steps per episode)
        for e, (redo, term, trunc) in zip((a, b), flags):
            e.step_autoreset(acts[k], redo, term, trunc)
        np.testing.assert_array_equal(a.obs, b.obs)
        np.testing.assert_array_equal(a.rew, b.rew)
        assert (flags[0][0] == flags[1][0]).all()
        assert flags[0][0].all() == (k == 3)          # all episodes end at the 4th step, reset at the 5th


@pytest.mark.xdist_group(ESSO_GYM)
def test_cache_warm_gym_leaves_the_default_envs_step_and_reset_on_disk(warmed):
    first, after = warmed["first"], warmed["fresh"]
    assert first["compiles"] == 0                     # after the warm: no compile, so the warm wrote all
    assert after["stats"] == {n: [1, 0] for n in ENTRIES} and after["compiles"] == 0
