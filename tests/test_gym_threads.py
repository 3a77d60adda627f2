"""The vector environment's threaded step on numba's threads (``step_parallel``, ``prange``) and the
process-wide threading layer the steerlab command asks for (:mod:`steerlab.jit.threading_layer`): fork-safe, a
forked child steps its own environments; steerlab's parallel calls from several Python threads
take turns; a user's explicit layer is kept. Each case runs in a fresh interpreter (the layer is
chosen once per process, and a wrong one aborts the process)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap

import pytest

pytest.importorskip("gymnasium")

PRELUDE = textwrap.dedent("""
    import json, sys
    import numpy as np
    import gymnasium as gym
    import numba
    import steerlab.gym

    def vec(n=37, threads=2):
        v = gym.make_vec("steerlab/CourseKeeping-v0", num_envs=n, vectorization_mode="vector_entry_point",
                         episode_s=6.0)
        v.unwrapped.core.threads_from, v.unwrapped.core.threads = 1, threads     # the threaded step at any N
        return v

    def episodes(v, steps=9, seed=5):                # through an autoreset (6 steps per episode)
        acts = np.random.default_rng(3).uniform(-1, 1, size=(steps, v.num_envs, 1))
        out = [v.reset(seed=seed)[0]] + [np.concatenate([v.step(a)[0].ravel(), v.unwrapped.core.rew]) for a in acts]
        return np.concatenate([np.ravel(x) for x in out])
""")

FORK = PRELUDE + textwrap.dedent("""
    import multiprocessing as mp

    def child(conn):
        conn.send(episodes(vec()).tolist())          # a new env in the child, its threaded step
        conn.close()

    ref = episodes(vec())                             # the parent's threaded step first: numba's threads run
    one = episodes(vec(threads=1))                    # the one-call step
    recv, send = mp.get_context("fork").Pipe(duplex=False)
    p = mp.get_context("fork").Process(target=child, args=(send,))
    p.start()
    got = recv.recv() if recv.poll(240) else None
    p.join(60)
    if p.is_alive():
        p.kill()
    print(json.dumps({"layer": numba.threading_layer(), "exitcode": p.exitcode,
                      "child_same": got == ref.tolist(), "one_call_same": bool(np.array_equal(one, ref))}))
""")

THREADS = PRELUDE + textwrap.dedent("""
    import threading

    envs = [vec(), vec()]
    ref = episodes(vec(threads=1), steps=60)
    out = [None, None]

    def run(k):
        out[k] = episodes(envs[k], steps=60)

    ts = [threading.Thread(target=run, args=(k,)) for k in range(2)]
    for t in ts:
        t.start()
    for t in ts:
        t.join()
    print(json.dumps({"layer": numba.threading_layer(), "same": [bool(np.array_equal(o, ref)) for o in out]}))
""")

LAYER = textwrap.dedent("""
    import json, sys
    import numba
    if len(sys.argv) > 2:
        numba.config.THREADING_LAYER = sys.argv[2]     # chosen in code before importing steerlab
    import steerlab
    if sys.argv[1] == "command":                       # what the steerlab command sets up
        from steerlab.jit import command
        command.settings()
    from steerlab.jit.threading_layer import num_threads, tbb_library, threads_pay
    num_threads()                                      # starts numba's threads, as steerlab does
    print(json.dumps({"layer": numba.threading_layer(), "config": numba.config.THREADING_LAYER,
                      "tbb": tbb_library() is not None, "pay": threads_pay()}))
""")


# a hang guard only: on a cold cache each script compiles the vector env's parallel drivers,
# which took more than 600 s on the loaded 2-core machine (numba 0.67, .ci/run-pins oldest)
def _run(script, *args, env_extra=None, timeout=1800):
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_THREADING_LAYER"}
    env.update(env_extra or {})
    p = subprocess.run([sys.executable, "-c", script, *args], env=env, capture_output=True, text=True,
                       timeout=timeout)
    assert p.returncode == 0, p.stderr[-3000:]
    return json.loads(p.stdout.strip().splitlines()[-1])


def test_a_child_forked_after_a_threaded_step_steps_its_own_env_and_exits():
    r = _run(FORK)
    assert r["layer"] in ("workqueue", "tbb")         # numba's fork-safe layers (not GNU OpenMP)
    assert r["exitcode"] == 0                         # no abort, no hang
    assert r["child_same"] and r["one_call_same"]     # same numbers in the child, and as one call


def test_threaded_steps_from_two_python_threads_take_turns_and_keep_their_numbers():
    r = _run(THREADS)
    assert r["layer"] in ("workqueue", "tbb")
    assert r["same"] == [True, True]


def test_the_command_asks_for_the_fork_safe_layer_unless_the_user_chose_one():
    r = _run(LAYER, "command")
    assert r["config"] == "forksafe"
    assert r["layer"] == ("tbb" if r["tbb"] else "workqueue")          # pip's TBB found and loaded when installed
    assert r["pay"] == r["tbb"]
    wq = _run(LAYER, "command", env_extra={"NUMBA_THREADING_LAYER": "workqueue"})
    assert (wq["layer"], wq["config"], wq["pay"]) == ("workqueue", "workqueue", False)
    omp = _run(LAYER, "command", "omp")                                 # set in code before import: kept
    assert (omp["layer"], omp["config"], omp["pay"]) == ("omp", "omp", True)
    assert _run(LAYER, "command", env_extra={"NUMBA_THREADING_LAYER": "omp"})["layer"] == "omp"   # set outside: kept


def test_import_steerlab_leaves_numbas_choice():
    """A user's program keeps numba's "default" layer: TBB where it loads (pip's found for it);
    where numba falls back to fork-unsafe OpenMP by itself, steerlab does not thread on it."""
    r = _run(LAYER, "library")
    assert r["config"] == "default"
    if r["tbb"]:
        assert (r["layer"], r["pay"]) == ("tbb", True)
    else:
        assert r["layer"] in ("omp", "workqueue") and r["pay"] is False


def test_the_threaded_step_runs_on_workqueue_too():
    """The fallback when TBB cannot be loaded: fork after a threaded step, two Python threads."""
    env = {"NUMBA_THREADING_LAYER": "workqueue"}
    r = _run(FORK, env_extra=env)
    assert r["layer"] == "workqueue" and r["exitcode"] == 0 and r["child_same"] and r["one_call_same"]
    r = _run(THREADS, env_extra=env)
    assert r["layer"] == "workqueue" and r["same"] == [True, True]


def test_the_vector_env_threads_only_where_threads_pay(monkeypatch):
    """One thread by default at every N (issue 34); asked for numba's threads (``threads=None``),
    from THREADS_FROM ships on, unless the layer is one where a threaded step is slower than one
    call (workqueue); an explicit ``threads`` is kept either way."""
    from steerlab.gym import episodes
    from steerlab.jit.threading_layer import num_threads

    core = episodes.Episodes(2, episode_s=4.0, vectorised=True)
    big = episodes.THREADS_FROM
    assert core.threads == 1 and core._threads(big) == 1 and core._threads(100 * big) == 1
    core.threads = None
    for pay, want in ((True, num_threads()), (False, 1)):
        monkeypatch.setattr(episodes, "threads_pay", lambda pay=pay: pay)
        assert core._threads(big - 1) == 1 and core._threads(big) == want
        core.threads = 3
        assert core._threads(big) == 3
        core.threads = None
