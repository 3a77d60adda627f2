"""A reinforcement-learning environment: one episode of ``steerlab/CourseKeeping-v0``.

Teaches: the Gymnasium environment (``pip install 'steerlab[rl]'``; ``import steerlab.gym``
registers the ids): observation ``[heading error e [rad], yaw rate r [rad/s], rudder delta
[rad]]``, action the rudder order as a fraction of the gear limit, reward the speed-loss
criterion ``-(e^2 + lam delta^2) control_dt``. Two policies on the same seeded episode (Esso
tanker at 16 kn in the eq-39 wave noise, a seeded initial heading offset): a steerlab PID
autopilot object (``steerlab.controller``) as the policy, and a random policy. The PID's
return is the baseline a learning agent has to beat. Without gymnasium the script says so and
exits 0.
"""

import sys

import numpy as np

from _common import figure, parse_args, save

args = parse_args(__doc__)
try:
    import gymnasium as gym
except ImportError:
    print("gymnasium is not installed: this example needs the optional extra "
          "(pip install 'steerlab[rl]'); skipped")
    sys.exit(0)

import steerlab as sl
import steerlab.gym  # noqa: F401  (registers steerlab/CourseKeeping-v0, ...)

EPISODE_S = 150.0 if args.quick else 300.0     # s, one action per control_dt = 1 s
SEED = 3
env = gym.make("steerlab/CourseKeeping-v0", ship="esso", speed_kn=16.0, episode_s=EPISODE_S)
pid = sl.controller("pid", ship="esso", speed_kn=16.0, sample_time=1.0)
delta_max = np.radians(35.0)                   # the scenario gear's limit: action = order / limit


def pid_policy(obs, k):
    # the law wants heading and reference; with psi_ref = 0 the heading is -e: give it e as the
    # reference and 0 as the heading (the same error), the measured yaw rate and rudder angle
    e, r, delta = obs
    order = pid.step(k * 1.0, 0.0, r, heading_ref=e, rudder=delta)     # [rad]
    return np.array([np.clip(order / delta_max, -1.0, 1.0)], dtype=np.float32)


rng = np.random.default_rng(0)


def random_policy(obs, k):
    return rng.uniform(-1.0, 1.0, size=1).astype(np.float32)


def episode(policy):
    obs, info = env.reset(seed=SEED)           # same seed: same sea and same initial offset
    pid.reset()
    log, total, k, done = [(0.0, *obs)], 0.0, 0, False
    while not done:
        obs, reward, terminated, truncated, info = env.step(policy(obs, k))
        log.append((info["t"], *obs))
        total += reward
        done = terminated or truncated
        k += 1
    return np.array(log), total


runs = {"steerlab PID": episode(pid_policy), "random": episode(random_policy)}
for name, (_, ret) in runs.items():
    print(f"{name:<13} return {ret:9.3f}")

fig, ax = figure(2, 1, sharex=True)
for i, (name, (log, ret)) in enumerate(runs.items()):
    ax[0, 0].plot(log[:, 0], np.degrees(log[:, 1]), f"C{i}", label=f"{name} (return {ret:.2f})")
    ax[1, 0].plot(log[:, 0], np.degrees(log[:, 3]), f"C{i}", lw=0.9)
ax[0, 0].axhline(0.0, color="k", lw=0.6)
ax[0, 0].set_ylabel("heading error e [deg]")
ax[0, 0].legend(fontsize=8, loc="upper right")
ax[0, 0].set_title("steerlab/CourseKeeping-v0, Esso tanker at 16 kn in waves, seed 3", fontsize=10)
ax[1, 0].set_ylabel("rudder angle [deg]")
ax[1, 0].set_xlabel("time [s]")
save(fig, args.out / "10_rl_episode.png")
