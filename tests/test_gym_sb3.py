"""Stable-Baselines3 on the native vector env (steerlab.gym.sb3): SB3's conventions, episodes bit-identical
to single environments, PPO trains through the public adapter; the reward terms and the normalised
observation. A real part: CI installs stable-baselines3 (``.ci/run``), so a skip there fails the run."""

import importlib.util

import numpy as np
import pytest

gym = pytest.importorskip("gymnasium")
# found, not imported: stable-baselines3 brings torch (seconds of CPU), which only the worker
# that runs these tests should pay for, not every worker's collection
pytestmark = pytest.mark.skipif(importlib.util.find_spec("stable_baselines3") is None,
                                reason="stable-baselines3 is not installed: pip install 'steerlab[learn]'")

import steerlab.gym  # noqa: E402,F401
from steerlab.errors import InputError  # noqa: E402

KW = {"episode_s": 8.0, "observation": "normalised", "reward": "autopilot"}   # 8 env steps an episode


def test_sb3_adapter_matches_dummy_vec_env_of_single_envs_bit_for_bit_through_autoresets():
    from stable_baselines3.common.env_checker import check_env
    from stable_baselines3.common.vec_env import DummyVecEnv

    from steerlab.gym.sb3 import make_sb3_vec_env

    n = 5
    ours = make_sb3_vec_env("steerlab/CourseChange-v0", n, **KW)
    ref = DummyVecEnv([lambda: gym.make("steerlab/CourseChange-v0", **KW) for _ in range(n)])
    check_env(gym.make("steerlab/CourseChange-v0", **KW).unwrapped)
    ours.seed(21)
    ref.seed(21)
    assert np.array_equal(ours.reset(), ref.reset())
    acts = np.random.default_rng(3).uniform(-1, 1, size=(20, n, 1)).astype(np.float32)
    ends = 0
    for a in acts:                                           # 20 steps: two autoresets of every ship
        o1, r1, d1, i1 = ours.step(a)
        o2, r2, d2, i2 = ref.step(a)
        assert np.array_equal(o1, o2) and np.array_equal(r1, r2) and r1.dtype == r2.dtype
        assert np.array_equal(d1, d2)
        for x, y in zip(i1, i2):
            assert ("terminal_observation" in x) == ("terminal_observation" in y)
            if "terminal_observation" in x:
                ends += 1
                assert np.array_equal(x["terminal_observation"], y["terminal_observation"])
                assert x["TimeLimit.truncated"] is y["TimeLimit.truncated"] is True
    assert ends == 2 * n


def test_ppo_trains_a_few_hundred_steps_through_the_public_adapter(tmp_path):
    import torch
    from stable_baselines3 import PPO

    from steerlab.gym.sb3 import make_sb3_vec_env

    torch.set_num_threads(1)
    venv = make_sb3_vec_env("steerlab/CourseKeeping-v0", 8, **KW)
    model = PPO("MlpPolicy", venv, n_steps=16, batch_size=64, n_epochs=1, seed=0,
                policy_kwargs={"net_arch": [8, 8]}, device="cpu")
    model.learn(total_timesteps=256)
    assert model.num_timesteps >= 256
    obs = venv.reset()
    act, _ = model.predict(obs, deterministic=True)
    assert act.shape == (8, 1) and np.all(np.abs(act) <= 1.0)
    # exported in one call, the policy controller's kernel gives torch's deterministic action
    from steerlab.control.policy import pack_policy, policy_update
    from steerlab.control.policy_file import load_policy
    from steerlab.gym.policy_export import export_policy
    from steerlab.ships.state import IPSI, IR

    pol = load_policy(export_policy(model, tmp_path / "tiny.npz"))
    dmax = venv.venv.core.delta_max
    p = pack_policy(pol.layers, pol.activation, dmax, dmax)
    core = venv.venv.core
    for i in range(8):
        x, ref = core.X[i].copy(), core.REF[i].copy()
        assert x[IPSI] != 0.0 and np.isfinite(x[IR])
        u = policy_update(np.zeros(200), p, 0.0, x, ref, 1.0)
        assert u == pytest.approx(float(act[i, 0]) * dmax, rel=1e-5, abs=1e-6)   # float32 torch vs float64


def test_same_step_reset_lanes_and_thread_policy_of_the_native_env():
    venv = gym.make_vec("steerlab/CourseKeeping-v0", num_envs=3, vectorization_mode="vector_entry_point",
                        autoreset_mode="SameStep", **KW).unwrapped
    assert venv.core.threads == 1                               # one thread unless asked
    single = gym.make("steerlab/CourseKeeping-v0", **KW)
    venv.reset(seed=[4, 5, 6])
    for _ in range(3):
        venv.step(np.zeros((3, 1)))
    obs, infos = venv.reset_lanes([1])                          # ship 1's next episode, now
    so, sinfo = single.reset(seed=5)
    so, sinfo = single.reset()
    assert np.array_equal(obs[0], so) and infos[0]["episode"] == sinfo["episode"] == 1
    with pytest.raises(InputError, match="lanes"):
        venv.reset_lanes([3])
    with pytest.raises(InputError, match="autoreset_mode"):
        gym.make_vec("steerlab/CourseKeeping-v0", num_envs=2, vectorization_mode="vector_entry_point",
                     autoreset_mode="later")


def test_export_refuses_a_model_the_policy_controller_cannot_run_in_one_line(tmp_path):
    """Bad input at the export: a model trained on another observation layout (the raw ``[e, r,
    delta]``), a hidden layer wider than the kernel holds, or not an actor-critic model is one
    InputError naming the field, and no file is written."""
    from stable_baselines3 import PPO

    from steerlab.gym.policy_export import export_policy
    from steerlab.gym.sb3 import make_sb3_vec_env

    raw = make_sb3_vec_env("steerlab/CourseKeeping-v0", 2, episode_s=8.0)           # observation="raw"
    wide = make_sb3_vec_env("steerlab/CourseKeeping-v0", 2, **KW)
    cases = [(PPO("MlpPolicy", raw, n_steps=8, batch_size=16, device="cpu"), "model.observation_space"),
             (PPO("MlpPolicy", wide, n_steps=8, batch_size=16, device="cpu", policy_kwargs={"net_arch": [80]}),
              "controller.weights.W0"),
             (object(), "model")]
    for model, field in cases:
        with pytest.raises(InputError) as err:
            export_policy(model, tmp_path / "p.npz")
        assert err.value.field == field and "\n" not in str(err.value), str(err.value)
        assert not (tmp_path / "p.npz").exists()


def test_bench_env_reports_the_adapter_as_sb3_sees_it(capsys):
    """benchmarks/bench_env.py --sb3 on a tiny workload: env-steps/s of the adapter and of
    DummyVecEnv, and their ratio (the numbers of a real run: benchmarks/RESULTS.md)."""
    import importlib.util
    import json
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "benchmarks" / "bench_env.py"
    spec = importlib.util.spec_from_file_location("bench_env_sb3", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    assert mod.main(["--sb3", "--n", "2", "--steps", "4", "--repeats", "1", "--min-time", "0", "--json"]) == 0
    (row,) = json.loads(capsys.readouterr().out)["rows"]
    assert row["n"] == 2 and row["steps"] == 4 and "subproc_env_steps_per_s" not in row
    assert row["adapter_env_steps_per_s"] > 0 and row["dummy_env_steps_per_s"] > 0
    assert row["ratio_vs_dummy"] == pytest.approx(row["adapter_env_steps_per_s"] / row["dummy_env_steps_per_s"])


def test_the_training_example_runs_and_writes_a_policy_the_controller_loads(tmp_path, capsys):
    """examples/learning/train_policy.py end to end on a tiny budget (one PPO rollout of 4 ships,
    no warm start): it trains through the adapter and exports a policy file that loads."""
    import importlib.util
    from pathlib import Path

    from steerlab.control.policy_file import load_policy

    path = Path(__file__).resolve().parents[1] / "examples" / "learning" / "train_policy.py"
    spec = importlib.util.spec_from_file_location("train_policy", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    out = tmp_path / "p.npz"
    assert mod.main(["--warm-start", "none", "--envs", "4", "--steps", "1", "--out", str(out)]) == 0
    assert "trained 1024 steps" in capsys.readouterr().out
    pol = load_policy(out)
    assert [w.shape for w, _ in pol.layers] == [(32, 4), (32, 32), (1, 32)] and pol.activation == "tanh"
    assert mod.main(["--steps", "0"]) == 2
