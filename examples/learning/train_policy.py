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


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=1_500_000, help="PPO timesteps (all ships together)")
    ap.add_argument("--envs", type=int, default=64, help="ships stepped together")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--ship", default="esso")
    ap.add_argument("--out", default="out/policy.npz")
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
