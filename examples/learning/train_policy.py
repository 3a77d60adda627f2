#!/usr/bin/env python
"""Train a PPO heading policy on steerlab's native vector env and save it for the ``policy`` controller.

    python examples/learning/train_policy.py --steps 300000 --out out/policy.npz

About 10 minutes of CPU on two cores (docs/learning.md). What makes it fast: the native vector env
through SB3's ``VecEnv`` (steerlab.gym.sb3: N ships in one compiled call), torch on ONE thread
(``torch.set_num_threads(1)``; torch's own pool was 70x slower per step on two cores) and the env on
one thread too (its default). The observation is ``"normalised"`` (every field O(1)), the reward
``"autopilot"`` (J = e^2 + 0.1 delta^2 with the rudder rate and reversals priced in); rewards are
normalised by SB3's ``VecNormalize`` (observations are not: the controller must see what the
env shows). Course keeping from initial offsets of up to 30 deg in waves covers course changes too.
"""

from __future__ import annotations

import argparse
import sys
import time


TEACHER_KP, TEACHER_KD = 1.5, 60.0
"""The PD teacher of ``--warm-start pd``: ``delta = Kp e - Kd r`` (Kp [rad/rad], Kd [s]), a stable
law for the Esso tanker at 16 kn (the tanker is course-unstable: a policy that starts from zero
drifts away, and PPO alone learned slowly from there within the budget)."""


def teacher(obs, scales):
    """The PD teacher's actions for normalised observations ``obs`` (N, 4); ``scales`` their divisors."""
    import numpy as np

    e, r, dmax = obs[:, 0] * scales[0], obs[:, 1] * scales[1], scales[2]
    return np.clip((TEACHER_KP * e - TEACHER_KD * r) / dmax, -1.0, 1.0)[:, None]


def imitate_pd(model, venv, rollout=400, noise=0.3, iters=1500, seed=0):
    """Fit the actor's mean to the PD teacher (mean-squared error, Adam) on the states the teacher
    visits with exploration noise ``noise`` (in action units): behaviour cloning as a warm start."""
    import numpy as np
    import torch

    from steerlab.control.policy_observation import obs_scales

    scales = obs_scales(venv.venv.core.delta_max)
    rng = np.random.default_rng(seed)
    obs = venv.reset()
    xs, ys = [], []
    for _ in range(rollout):
        act = teacher(obs, scales)
        xs.append(obs)
        ys.append(act)
        obs, _, _, _ = venv.step(np.clip(act + noise * rng.standard_normal(act.shape), -1.0, 1.0))
    x = torch.as_tensor(np.concatenate(xs), dtype=torch.float32)
    y = torch.as_tensor(np.concatenate(ys), dtype=torch.float32)
    pol = model.policy
    opt = torch.optim.Adam(list(pol.mlp_extractor.policy_net.parameters()) + list(pol.action_net.parameters()),
                           lr=1e-3)
    g = torch.Generator().manual_seed(seed)
    for _ in range(iters):
        idx = torch.randint(0, x.shape[0], (1024,), generator=g)
        mean = pol.action_net(pol.mlp_extractor.forward_actor(pol.extract_features(x[idx])))
        loss = torch.mean((mean - y[idx]) ** 2)
        opt.zero_grad()
        loss.backward()
        opt.step()
    print(f"warm start: actor fitted to the PD teacher on {x.shape[0]} states, mse {float(loss.detach()):.2e}", flush=True)
    venv.seed(seed)
    venv.reset()


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=1_500_000, help="PPO timesteps (all ships together)")
    ap.add_argument("--envs", type=int, default=64, help="ships stepped together")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--ship", default="esso")
    ap.add_argument("--out", default="out/policy.npz")
    ap.add_argument("--warm-start", choices=("none", "pd"), default="pd",
                    help="pd: first fit the actor to a PD teacher by regression (seconds), then PPO (default)")
    ap.add_argument("--checkpoint-every", type=int, default=0,
                    help="also export the policy (and print progress) every this many timesteps (0: at the end only)")
    a = ap.parse_args(argv)
    if a.steps < 1 or a.envs < 1:
        print("train_policy: --steps and --envs must be >= 1", file=sys.stderr)
        return 2
    import torch
    from stable_baselines3 import PPO
    from stable_baselines3.common.vec_env import VecNormalize

    from steerlab.gym.policy_export import export_policy
    from steerlab.gym.sb3 import make_sb3_vec_env

    torch.set_num_threads(1)
    venv = make_sb3_vec_env("steerlab/CourseKeeping-v0", a.envs, ship=a.ship, observation="normalised",
                            reward="autopilot", initial_offset_deg=30.0, episode_s=300.0)
    venv.seed(a.seed)
    env = VecNormalize(venv, norm_obs=False, norm_reward=True, gamma=0.995)
    model = PPO("MlpPolicy", env, n_steps=256, batch_size=1024, n_epochs=10, learning_rate=3e-4, gamma=0.995,
                gae_lambda=0.95, ent_coef=0.0, seed=a.seed, device="cpu", verbose=0,
                policy_kwargs={"net_arch": [32, 32], "log_std_init": -1.0})
    t0, c0 = time.perf_counter(), time.process_time()
    if a.warm_start == "pd":
        imitate_pd(model, venv)
    callback = None
    if a.checkpoint_every > 0:
        from stable_baselines3.common.callbacks import BaseCallback

        class Checkpoint(BaseCallback):
            last = 0

            def _on_step(self) -> bool:
                if self.num_timesteps - self.last >= a.checkpoint_every:
                    self.last = self.num_timesteps
                    export_policy(self.model, a.out)
                    print(f"{self.num_timesteps} steps, {time.process_time() - c0:.0f} s CPU, "
                          f"{time.perf_counter() - t0:.0f} s wall", flush=True)
                return True

        callback = Checkpoint()
    model.learn(total_timesteps=a.steps, callback=callback)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    path = export_policy(model, a.out)
    print(f"trained {model.num_timesteps} steps in {wall:.0f} s wall, {cpu:.0f} s CPU; policy -> {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
