"""The Gymnasium envs' reward terms (steerlab.gym.rewards) and normalised observation
(steerlab.control.policy_observation): values from their definitions, bad input names the field."""

import math

import numpy as np
import pytest

gym = pytest.importorskip("gymnasium")

import steerlab.gym  # noqa: E402,F401
from steerlab.control.policy_observation import E_SCALE, R_SCALE  # noqa: E402
from steerlab.errors import InputError  # noqa: E402


def _episode(**kw):
    env = gym.make("steerlab/CourseChange-v0", episode_s=30.0, **kw)
    acts = [0.5, -0.5] * 15                                      # a chattering rudder
    obs = [env.reset(seed=3)[0]]
    rew = []
    for a in acts:
        o, r, *_ = env.step(np.array([a], dtype=np.float32))
        obs.append(o)
        rew.append(r)
    return np.array(obs), np.array(rew), env.unwrapped.core


def test_reward_terms_follow_their_definitions_and_the_default_reward_is_unchanged():
    raw, j_default, core = _episode()
    dt = core.control_dt
    e, delta = raw[:, 0], raw[:, 2]
    j = -(e[1:] ** 2 + 0.1 * delta[1:] ** 2) * dt                   # the default: speed_loss, lam 0.1
    assert np.allclose(j_default, j, rtol=1e-12, atol=0)
    _, rate, _ = _episode(reward={"rudder_rate": 1.0})
    assert np.allclose(rate, -(np.diff(delta) / dt) ** 2 * dt, rtol=1e-12)
    _, travel, _ = _episode(reward={"rudder_travel": 1.0})
    assert np.allclose(travel, -np.abs(np.diff(delta)), rtol=1e-12)
    _, rev, _ = _episode(reward={"reversals": 1.0})
    d = np.sign(np.diff(delta))
    reversals = -np.r_[0.0, (d[1:] != d[:-1]) & (d[:-1] != 0)]
    assert np.array_equal(rev, reversals) and rev.sum() <= -10      # the chatter is counted
    _, both, _ = _episode(reward={"speed_loss": 1.0, "rudder_rate": 2.0})
    assert np.allclose(both, j + 2.0 * rate, rtol=1e-12)


def test_normalised_observation_is_the_raw_one_over_the_documented_scales():
    raw, _, core = _episode()
    norm, _, core_n = _episode(observation="normalised")
    assert norm.shape[1] == 4
    assert np.allclose(norm[:, 0] * E_SCALE, raw[:, 0], rtol=1e-12, atol=1e-15)
    assert np.allclose(norm[:, 1] * R_SCALE, raw[:, 1], rtol=1e-12, atol=1e-15)
    assert np.allclose(norm[:, 2] * core.delta_max, raw[:, 2], rtol=1e-12, atol=1e-15)
    assert np.all(norm[:, 3] == 0.0)                             # a step of the reference: no rate of turn
    assert abs(norm[12, 0]) > math.radians(15) / E_SCALE          # the 20 deg step, O(1) when normalised


@pytest.mark.parametrize("bad, field", [({"wobble": 1.0}, "reward.wobble"), ({"heading": -1.0}, "reward.heading"),
                                        ("nope", "reward")])
def test_bad_reward_names_the_field(bad, field):
    with pytest.raises(InputError, match=field.replace(".", r"\.")):
        gym.make("steerlab/CourseKeeping-v0", reward=bad)
    with pytest.raises(InputError, match="observation"):
        gym.make("steerlab/CourseKeeping-v0", observation="scaled")
