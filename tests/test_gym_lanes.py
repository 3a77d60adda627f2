"""The native vector environment on the batch engine's vectorised lanes (issue 13).

Ship i of ``SteeringVectorEnv`` (driver ``step_lanes``: groups of LANES ships, structure of
arrays, vectorised RK4 stages; seas of all resetting ships drawn in one call) must be
bit-identical to a single ``SteeringEnv`` (scalar plant step, one ship) seeded alike, for a
number of ships that is not a multiple of LANES, through an autoreset; the compiled
``step_lanes`` of the Esso must hold its four RK4 stages as vector arithmetic.
"""

import numba
import numpy as np
import pytest

gym = pytest.importorskip("gymnasium")

import steerlab.gym  # noqa: E402,F401  (registers the ids)
from steerlab.sim.lanes import LANES  # noqa: E402

KW = {"episode_s": 30.0}                      # 30 env steps per episode: the autoreset comes soon
N = 37                                        # 2 full groups of 16 and a partial one of 5


def _vec(env_id, n=N, **kw):
    return gym.make_vec(env_id, num_envs=n, vectorization_mode="vector_entry_point", **{**KW, **kw})


@pytest.mark.parametrize("env_id", ["steerlab/CourseKeeping-v0", "steerlab/TrackFollowing-v0"])
def test_vector_env_of_37_equals_37_single_envs_through_an_autoreset(env_id):
    assert N % LANES != 0
    venv = _vec(env_id)
    singles = [gym.make(env_id, **KW) for _ in range(N)]
    acts = np.random.default_rng(1).uniform(-1, 1, size=(34, N, 1)).astype(np.float32)
    vo, _ = venv.reset(seed=100)
    assert np.array_equal(vo, np.stack([e.reset(seed=100 + i)[0] for i, e in enumerate(singles)]))
    steered = 0
    for k in range(34):
        vo, vr, vte, vtr, _ = venv.step(acts[k])
        for i, e in enumerate(singles):
            if k == 30:                       # NEXT_STEP autoreset after the 30th step: a new sea
                o, _ = e.reset()
                assert np.array_equal(vo[i], o) and vr[i] == 0.0 and not vte[i] and not vtr[i]
                continue
            o, r, te, tr, _ = e.step(acts[k, i])
            assert np.array_equal(vo[i], o), (k, i, vo[i], o)
            assert vr[i] == r and vte[i] == te and vtr[i] == tr
            steered += 1
        if k == 29:
            assert vtr.all() and not vte.any()
    assert steered == 33 * N
    assert len({tuple(o) for o in vo}) == N   # 37 different seas and starts


def test_vector_env_same_seed_same_episodes_and_another_seed_another():
    venv = _vec("steerlab/CourseChange-v0", n=20)
    acts = np.random.default_rng(2).uniform(-1, 1, size=(40, 20, 1)).astype(np.float32)

    def episode(seed):
        out = [venv.reset(seed=seed)[0]]
        for k in range(40):                   # through the autoreset at step 31
            o, r, te, tr, _ = venv.step(acts[k])
            out.append(np.concatenate([o.ravel(), r, te, tr]))
        return np.concatenate([np.ravel(x) for x in out])

    a, b, c = episode(7), episode(7), episode(8)
    assert np.array_equal(a, b)
    assert not np.array_equal(a, c)


def test_reset_seas_equal_the_scenario_machinery():
    """The seas drawn for many lanes at once are the ones ``realise`` (``steerlab run``) gives."""
    from steerlab.environment.disturbance import Disturbance, build_disturbance, build_disturbances
    from steerlab.sim.setup import realise

    venv = _vec("steerlab/CourseKeeping-v0", n=5, environment={"waves": True, "current_speed": 0.4,
                                                                "current_dir_deg": 30.0, "constant_rudder_deg": 1.0})
    core = venv.unwrapped.core
    infos = core.reset_lanes([4, 1, 3], [11, 12, 13])
    for q, i in enumerate([4, 1, 3]):
        np.testing.assert_array_equal(core.W[i], realise(core.design, infos[q]["sea_seed"]).w)
    d = Disturbance(0.02, 5.0, True, 0.5, 1e-4, wind_speed=3.0, wind_dir=0.5, current_speed=0.5, current_dir=1.0)
    for dist in (d, Disturbance(0.02, 5.0, False, current_speed=0.2)):
        w = build_disturbances(dist, 200, 0.1, [3, 2**31 - 2, 3])
        for q, s in enumerate([3, 2**31 - 2, 3]):
            np.testing.assert_array_equal(w[q], build_disturbance(dist, 200, 0.1, s))
    assert not np.array_equal(w[0], build_disturbances(d, 200, 0.1, [4])[0])


@pytest.mark.skipif(not numba.config.LOOP_VECTORIZE, reason="numba's loop vectoriser is switched off")
def test_the_esso_step_lanes_has_four_vectorised_rk4_stages():
    from steerlab.sim.lanes import plant_lanes_report

    venv = _vec("steerlab/CourseKeeping-v0", n=3)
    core = venv.unwrapped.core
    with pytest.raises(RuntimeError, match="not been compiled"):
        plant_lanes_report(core.ship_spec.rhs, core.X.shape[1], lanes=5)
    venv.reset(seed=0)
    venv.step(np.zeros((3, 1), dtype=np.float32))
    report = plant_lanes_report(core.ship_spec.rhs, core.X.shape[1])
    assert report["vectorised_stages"] >= 4 and report["per_run_library_calls"] == []


def test_a_diverged_ship_in_the_vector_env_ends_only_its_episode():
    venv = _vec("steerlab/CourseKeeping-v0", n=18, ship="nomoto1", speed_kn=10.0,
                ship_options={"K": 0.1, "T": -0.05}, environment={"constant_rudder_deg": 1.0})
    venv.reset(seed=0)
    for k in range(30):
        o, r, te, tr, info = venv.step(np.zeros((18, 1), dtype=np.float32))
        if te.any():
            break
    assert te.all() and k < 29 and list(info["reason"]) == ["diverged"] * 18
    assert np.all(np.isfinite(o)) and np.all(np.isfinite(r))
    o, r, te, tr, _ = venv.step(np.zeros((18, 1), dtype=np.float32))      # autoreset: fresh ships
    assert not te.any() and np.all(r == 0.0) and np.all(np.abs(o[:, 1]) < 1e-9)
