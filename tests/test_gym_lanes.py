"""The native vector environment on the batch engine's vectorised lanes (issue 13).

Ship i of ``SteeringVectorEnv`` (driver ``step_lanes``: groups of LANES ships, structure of
arrays, vectorised RK4 stages; every draw of every ship from its own Philox key, in compiled code) must be
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


def _vec(env_id, n=N, threads=None, **kw):
    """A native vector env; ``threads`` (an int) spreads its every step over that many threads
    whatever N (the split the env uses from ``THREADS_FROM`` ships on)."""
    venv = gym.make_vec(env_id, num_envs=n, vectorization_mode="vector_entry_point", **{**KW, **kw})
    if threads is not None:
        venv.unwrapped.core.threads_from, venv.unwrapped.core.threads = 1, threads
    return venv


@pytest.mark.parametrize("threads", [None, 2, 3])     # 37 ships: one call; ranges [0, 16) [16, 37); 3 ranges
@pytest.mark.parametrize("env_id", ["steerlab/CourseKeeping-v0", "steerlab/TrackFollowing-v0"])
def test_vector_env_of_37_equals_37_single_envs_through_an_autoreset(env_id, threads):
    assert N % LANES != 0
    venv = _vec(env_id, threads=threads)
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


def _episodes(venv, seed, acts):
    """Observations, rewards and end flags of ``len(acts)`` steps from ``reset(seed=seed)``, flat."""
    out = [venv.reset(seed=seed)[0]]
    for a in acts:
        o, r, te, tr, _ = venv.step(a)
        out.append(np.concatenate([o.ravel(), r, te, tr]))
    return np.concatenate([np.ravel(x) for x in out])


def test_vector_env_same_seed_same_episodes_and_another_seed_another():
    venv = _vec("steerlab/CourseChange-v0", n=20)
    acts = np.random.default_rng(2).uniform(-1, 1, size=(40, 20, 1)).astype(np.float32)   # autoreset at 31
    a, b, c = _episodes(venv, 7, acts), _episodes(venv, 7, acts), _episodes(venv, 8, acts)
    assert np.array_equal(a, b)
    assert not np.array_equal(a, c)


@pytest.mark.parametrize("environment", [None, {"waves": True, "wind_speed": 5.0, "gusts": {"speed_std": 1.0}}])
def test_threaded_steps_give_the_one_call_numbers_whatever_the_thread_count(environment):
    """The step spread over 1, 2 or 3 ranges of whole groups (on numba's threads, or on one)
    gives, bit for bit, the episodes of the one-call step, through autoresets, and the same seed the same episodes; also
    with a sea realised lane by lane (gusts: the caller resets those lanes)."""
    n = 2 * LANES + 3
    kw = {"environment": environment} if environment else {}
    acts = np.random.default_rng(4).uniform(-1, 1, size=(65, n, 1)).astype(np.float32)   # 2 autoresets
    one_call = _vec("steerlab/CourseChange-v0", n=n, **kw)
    assert one_call.unwrapped.core.threads_from > n
    ref = _episodes(one_call, 9, acts)
    for threads in (1, 2, 3):             # 2, 3: ranges of the prange (step_parallel, reset_parallel)
        venv = _vec("steerlab/CourseChange-v0", n=n, threads=threads, **kw)
        assert np.array_equal(_episodes(venv, 9, acts), ref), threads
        assert np.array_equal(_episodes(venv, 9, acts), ref), threads
    cores = numba.get_num_threads()
    try:
        numba.set_num_threads(1)          # 2 ranges on one of numba's threads
        assert np.array_equal(_episodes(_vec("steerlab/CourseChange-v0", n=n, threads=2, **kw), 9, acts), ref)
    finally:
        numba.set_num_threads(cores)
    assert not np.array_equal(_episodes(venv, 10, acts), ref)
    lanes = [3, 30] + list(range(5, 25)) + [3]               # a lane twice: reset twice, in order, one call
    for env in (one_call, venv):
        env.reset(seed=9)
        env.unwrapped.core.reset_lanes(lanes)
    a, b = one_call.unwrapped.core, venv.unwrapped.core
    assert np.array_equal(a.X, b.X) and np.array_equal(a.EP, b.EP) and np.array_equal(a.obs, b.obs)


def test_range_cuts_cover_the_lanes_once_in_whole_groups():
    from steerlab.sim.lanes import range_cuts

    for n, lanes, ranges, expect in ((37, LANES, 2, 2), (37, LANES, 3, 3), (37, LANES, 4, 3), (1024, LANES, 2, 2),
                                     (1024, LANES, 12, 12), (10, LANES, 4, 1), (40, LANES, 1, 1), (5, 1, 8, 5)):
        cuts = range_cuts(n, lanes, ranges)
        assert cuts.dtype == np.int64 and cuts.shape == (expect + 1,), (n, ranges)
        assert cuts[0] == 0 and cuts[-1] == n and (np.diff(cuts) > 0).all()     # contiguous, none empty
        assert (cuts[:-1] % lanes == 0).all()                                   # whole groups
        sizes = np.diff(-(-cuts // lanes))                                      # groups per range
        assert sizes.max() - sizes.min() <= 1                                   # as equal as groups allow


def test_plain_seas_are_the_scenario_wave_model_driven_by_each_lanes_philox_normals():
    """A plain sea's rows, written lazily env step by env step, equal the scenario machinery's
    sea (seed-free channels of ``realise``, eq-39 filter of the held samples as
    ``build_disturbances`` does it in one pass) driven by the lane's own Philox normals."""
    from steerlab.environment.disturbance import N_CHANNELS, W_RUDDER, _fill
    from steerlab.environment.iir_filter import _padded
    from steerlab.environment.waves import band_pass_eq39
    from steerlab.jit.philox import seed_key
    from steerlab.sim.setup import realise

    venv = _vec("steerlab/CourseKeeping-v0", n=5, environment={"waves": True, "current_speed": 0.4,
                                                                "current_dir_deg": 30.0, "constant_rudder_deg": 1.0})
    core = venv.unwrapped.core
    assert core.lazy
    venv.reset(seed=11)
    venv.step(np.zeros((5, 1), dtype=np.float32))
    venv.step(np.zeros((5, 1), dtype=np.float32))
    infos = core.reset_lanes([4, 1, 2], [11, 12, 11])   # lanes 4 and 2 keyed 11 again, episode 0; lane 1 12
    assert [d["episode"] for d in infos] == [0, 0, 0]
    sc = core.scenario
    n_read = sc.n_steps                               # rows 0 .. n_steps - 1 are read by the plant steps
    assert core.W.shape == (5, core.nc, N_CHANNELS)   # a lane holds only its env step's rows
    read = np.full((5, n_read, core.W.shape[2]), np.nan)
    for _ in range(int(KW["episode_s"])):              # every row the plants read, in 30 env steps
        k0 = core.K.copy()
        venv.step(np.full((5, 1), 0.3, dtype=np.float32))
        for i in (4, 1, 2):
            read[i, k0[i]:k0[i] + core.nc] = core.W[i]
    assert (core.J[[4, 1, 2]] == 30).all()
    ref = realise(core.design, 123).w
    b, a = _padded(*band_pass_eq39(sc.dt))
    dist = core.design.dist
    scale = float(np.sqrt(dist.wave_power / dist.wave_sample_time))   # held_white_noise's scaling
    for i, seed in ((4, 11), (1, 12)):
        k0, k1 = seed_key(seed)
        z = _ziggurat_normals(k0, k1, 0, core.S.shape[1])
        np.testing.assert_array_equal(core.S[i], z * scale)
        one_pass = np.empty((1,) + ref.shape)
        _fill(one_pass, np.array([0]), core._base, core.S[i:i + 1], core._hold, b, a, W_RUDDER)
        np.testing.assert_array_equal(read[i], one_pass[0, :n_read])
        others = [c for c in range(ref.shape[1]) if c != W_RUDDER]
        np.testing.assert_array_equal(read[i][:, others], ref[:n_read, others])   # seed-free channels
    np.testing.assert_array_equal(read[4], read[2])                              # same seed, same sea
    assert not np.array_equal(read[1], read[2])


def _ziggurat_normals(k0, k1, episode, n):
    """Reference: the documented ziggurat in plain Python on numpy's Philox words (counter
    (b, episode, 1, 0), b = 0, 1, ...)."""
    import math

    from steerlab.jit.philox import _FI, _KI, _WI, ZIG_R

    c = (episode << 64) + (1 << 128) - 1                  # numpy increments the counter before a block
    bg = np.random.Philox(key=np.array([k0, k1], dtype=np.uint64),
                          counter=np.array([(c >> (64 * q)) & (2 ** 64 - 1) for q in range(4)], dtype=np.uint64))
    words = iter(int(v) for v in bg.random_raw(4 * n + 64))
    uni = lambda: (next(words) >> 11) * 2.0 ** -53        # noqa: E731
    out = []
    while len(out) < n:
        w = next(words)
        i, neg, a = w & 255, (w >> 8) & 1, (w >> 9) & (2 ** 52 - 1)
        x = -(a * _WI[i]) if neg else a * _WI[i]
        if a < int(_KI[i]):
            out.append(x)
        elif i == 0:
            while True:
                xx = -math.log1p(-uni()) / ZIG_R
                if -2.0 * math.log1p(-uni()) > xx * xx:
                    break
            out.append(-(ZIG_R + xx) if neg else ZIG_R + xx)
        elif (_FI[i - 1] - _FI[i]) * uni() + _FI[i] < math.exp(-0.5 * x * x):
            out.append(x)
    return np.array(out)


def test_the_lane_normals_are_standard_normal():
    from steerlab.jit.philox import normals

    import math

    z = np.empty(2_000_000)
    normals(np.uint64(3), np.uint64(0), np.uint64(0), 1, z, 1.0)
    assert abs(z.mean()) < 0.003 and abs(z.var() - 1.0) < 0.005          # 4 and 5 standard errors
    assert abs(np.mean(z ** 4) - 3.0) < 0.035                             # 5 standard errors
    for q in (-1.0, 0.5, 2.0):
        assert abs(np.mean(z < q) - 0.5 * math.erfc(-q / math.sqrt(2.0))) < 0.0015
    # the base layer's tail beyond r = 3.654 (drawn by its own rule): P = erfc(r / sqrt 2) = 2.58e-4
    assert abs(np.mean(np.abs(z) > 3.6541528853610088) - 2.58e-4) < 0.6e-4
    y = np.empty(2_000_000)
    normals(np.uint64(4), np.uint64(0), np.uint64(0), 1, y, 1.0)          # the next key: independent
    assert abs(np.corrcoef(z, y)[0, 1]) < 0.004


def test_seas_with_optional_blocks_are_realised_by_the_scenario_machinery():
    from steerlab.sim.setup import realise

    venv = _vec("steerlab/CourseKeeping-v0", n=3, environment={"waves": True, "wind_speed": 5.0,
                                                                "gusts": {"speed_std": 1.0}})
    core = venv.unwrapped.core
    assert not core.lazy
    infos = core.reset_lanes([2, 0], [11, 12])
    for q, i in enumerate([2, 0]):
        np.testing.assert_array_equal(core.W[i], realise(core.design, infos[q]["sea_seed"]).w)
    venv.reset(seed=5)
    for _ in range(int(KW["episode_s"]) + 1):              # through an autoreset done lane by lane
        o, r, te, tr, _ = venv.step(np.zeros((3, 1), dtype=np.float32))
    assert np.all(r == 0.0) and not te.any() and not tr.any()


def test_build_disturbances_equals_build_disturbance_per_seed():
    from steerlab.environment.disturbance import Disturbance, build_disturbance, build_disturbances

    d = Disturbance(0.02, 5.0, True, 0.5, 1e-4, wind_speed=3.0, wind_dir=0.5, current_speed=0.5, current_dir=1.0)
    for dist in (d, Disturbance(0.02, 5.0, False, current_speed=0.2)):
        w = build_disturbances(dist, 200, 0.1, [3, 2**31 - 2, 3])
        for q, s in enumerate([3, 2**31 - 2, 3]):
            np.testing.assert_array_equal(w[q], build_disturbance(dist, 200, 0.1, s))
    assert not np.array_equal(w[0], build_disturbances(d, 200, 0.1, [4])[0])


def test_philox_blocks_equal_numpys_philox():
    from steerlab.jit.philox import philox4x64

    out = np.empty(4, dtype=np.uint64)
    for key, ctr in (((0, 0), (1, 0, 0, 0)), ((123, 2**64 - 1), (5, 7, 1, 0)), ((2**63 + 11, 9), (0, 3, 0, 2**64 - 1))):
        philox4x64(*[np.uint64(v) for v in ctr + key], out)
        c = (sum(v << (64 * q) for q, v in enumerate(ctr)) - 1) % 2 ** 256
        bg = np.random.Philox(key=np.array(key, dtype=np.uint64),
                              counter=np.array([(c >> (64 * q)) & (2 ** 64 - 1) for q in range(4)], dtype=np.uint64))
        np.testing.assert_array_equal(out, bg.random_raw(4))


def test_seeds_are_checked_and_unseeded_resets_differ():
    from steerlab.errors import InputError

    venv = _vec("steerlab/CourseKeeping-v0", n=2)
    with pytest.raises(RuntimeError, match="reset"):
        venv.step(np.zeros((2, 1), dtype=np.float32))
    for bad in (-1, 2 ** 128, 1.5, [1], [3, -3]):
        with pytest.raises(InputError) as ei:
            venv.reset(seed=bad)
        assert ei.value.field == "seed"
    assert not venv.unwrapped.core.keyed.any()             # a refused seed list changed no ship
    a, _ = venv.reset()                                    # keyed from the OS's entropy
    b, _ = _vec("steerlab/CourseKeeping-v0", n=2).reset()
    assert not np.array_equal(a, b)


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


@pytest.mark.parametrize("threads", [None, 2])          # 2: ranges [0, 16) and [16, 18), the bad lane in the 2nd
def test_an_action_outside_the_space_is_refused_by_the_vector_env_and_changes_nothing(threads):
    from steerlab.errors import InputError

    venv = _vec("steerlab/CourseKeeping-v0", n=18, threads=threads)
    core = venv.unwrapped.core
    venv.reset(seed=3)
    venv.step(np.zeros((18, 1), dtype=np.float32))
    before = [a.copy() for a in (core.X, core.K, core.J, core.W, core.obs, core.rew)]
    for bad in (1.5, -1.01, np.nan, np.inf):
        acts = np.zeros((18, 1), dtype=np.float32)
        acts[17, 0] = bad                                     # in the partial group of 2
        with pytest.raises(InputError) as ei:
            venv.step(acts)
        assert ei.value.field == "action" and "[-1, 1]" in str(ei.value)
        assert repr(float(np.float32(bad))) in str(ei.value)
        assert all(np.array_equal(a, b, equal_nan=True) for a, b in
                   zip(before, (core.X, core.K, core.J, core.W, core.obs, core.rew)))
    acts = np.zeros((18, 1), dtype=np.float32)
    acts[3, 0], acts[17, 0] = 1.5, -2.0                       # one bad action in each range: the first named
    with pytest.raises(InputError) as ei:
        venv.step(acts)
    assert "1.5" in str(ei.value) and "-2" not in str(ei.value)
    assert all(np.array_equal(a, b) for a, b in zip(before, (core.X, core.K, core.J, core.W, core.obs, core.rew)))
    o, *_ = venv.step(np.ones((18, 1), dtype=np.float32))     # the boundary itself is allowed
    assert np.all(np.isfinite(o))


def test_bench_env_script_reports_both_envs(capsys):
    """benchmarks/bench_env.py, run as its own main on a tiny workload (its numbers: README)."""
    import importlib.util
    import json
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "benchmarks" / "bench_env.py"
    spec = importlib.util.spec_from_file_location("bench_env", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    assert mod.main(["--n", "3", "--steps", "4", "--repeats", "1", "--min-time", "0", "--json"]) == 0
    (row,) = json.loads(capsys.readouterr().out)["rows"]
    assert row["n"] == 3 and row["steps"] == 4 and row["control_dt"] == 1.0
    assert row["threads"] == 1                                # 3 ships: below THREADS_FROM, one call
    for k in ("native_env_steps_per_s", "sync_env_steps_per_s", "native_env_steps_per_cpu_s", "ratio", "ratio_cpu"):
        assert row[k] > 0
    assert row["ratio"] == pytest.approx(row["native_env_steps_per_s"] / row["sync_env_steps_per_s"])
    assert mod.main(["--threads", "0"]) == 2
    assert "--threads must be in [1, " in capsys.readouterr().err
