"""Gymnasium environments: check_env, seeded determinism, vector == single per ship, bad input."""

import numpy as np
import pytest

gym = pytest.importorskip("gymnasium")

import steerlab.gym  # noqa: E402,F401  (registers the ids)
from steerlab.errors import InputError  # noqa: E402

KW = {"episode_s": 60.0}                     # short episodes: 60 env steps


def _run(env, actions):
    out = []
    for a in actions:
        o, r, te, tr, _ = env.step(np.array([a], dtype=np.float32))
        out.append((o.copy(), r, te, tr))
        if te or tr:
            break
    return out


@pytest.mark.parametrize("env_id", sorted(steerlab.gym.IDS))
def test_check_env_passes(env_id):
    from gymnasium.utils.env_checker import check_env

    env = gym.make(env_id, **KW)
    check_env(env.unwrapped, skip_render_check=True)


def test_same_seed_same_episode_and_a_course_change_steers():
    env = gym.make("steerlab/CourseChange-v0", **KW)
    acts = np.linspace(-0.5, 0.5, 60)
    o1, _ = env.reset(seed=5)
    a = _run(env, acts)
    o2, _ = env.reset(seed=5)
    b = _run(env, acts)
    assert np.array_equal(o1, o2) and len(a) == len(b) == 60
    assert all(np.array_equal(x[0], y[0]) and x[1] == y[1] for x, y in zip(a, b))
    assert a[-1][3] and not a[-1][2]                       # truncated at episode_s, not diverged
    env.reset(seed=6)
    c = _run(env, acts)
    assert not np.array_equal(a[10][0], c[10][0])          # another seed, another sea
    # the reference stepped 20 deg at t = 10 s: the heading error jumps by 20 deg
    assert a[10][0][0] > np.radians(15.0)
    assert all(x[1] <= 0.0 for x in a)                     # reward -(e^2 + lam delta^2) dt


def test_vector_env_equals_single_envs_ship_by_ship():
    n = 3
    venv = gym.make_vec("steerlab/CourseKeeping-v0", num_envs=n, vectorization_mode="vector_entry_point", **KW)
    assert type(venv.unwrapped).__name__ == "SteeringVectorEnv"
    singles = [gym.make("steerlab/CourseKeeping-v0", **KW) for _ in range(n)]
    rng = np.random.default_rng(0)
    acts = rng.uniform(-1, 1, size=(70, n, 1)).astype(np.float32)
    vo, _ = venv.reset(seed=10)
    so = [e.reset(seed=10 + i)[0] for i, e in enumerate(singles)]
    assert np.array_equal(vo, np.stack(so))
    for k in range(70):
        vo, vr, vte, vtr, _ = venv.step(acts[k])
        for i, e in enumerate(singles):
            if k == 60:                                      # NEXT_STEP autoreset after the 60th step
                o, _ = e.reset()
                assert np.array_equal(vo[i], o) and vr[i] == 0.0
                continue
            o, r, te, tr, _ = e.step(acts[k, i])
            assert np.array_equal(vo[i], o) and vr[i] == r and vte[i] == te and vtr[i] == tr
    assert not np.array_equal(vo[0], vo[1])


def test_action_outside_the_space_is_refused():
    env = gym.make("steerlab/CourseKeeping-v0", **KW)
    env.reset(seed=0)
    for bad in (1.5, np.nan):
        with pytest.raises(InputError) as ei:
            env.step(np.array([bad], dtype=np.float32))
        assert ei.value.field == "action"


def test_a_diverged_ship_ends_the_episode_and_says_why():
    env = gym.make("steerlab/CourseKeeping-v0", ship="nomoto1", speed_kn=10.0,
                   ship_options={"K": 0.1, "T": -0.05}, environment={"constant_rudder_deg": 1.0}, **KW)
    env.reset(seed=0)
    for k in range(60):
        o, r, te, tr, info = env.step(np.array([0.0], dtype=np.float32))
        if te or tr:
            break
    assert te and not tr and k < 59 and info["reason"] == "diverged"
    assert np.all(np.isfinite(o)) and np.isfinite(r) and env.observation_space.contains(o)
    with pytest.raises(RuntimeError):                      # no stepping a finished episode
        env.step(np.array([0.0], dtype=np.float32))


def test_bad_settings():
    with pytest.raises(InputError) as ei:
        gym.make("steerlab/CourseKeeping-v0", control_dt=0.25)
    assert ei.value.field == "control_dt"
    with pytest.raises(InputError) as ei:
        gym.make("steerlab/CourseKeeping-v0", ship="titanic")
    assert ei.value.field == "ship.model"
    # a misspelt keyword was Python's TypeError from deep inside; now it is named, with the allowed ones
    with pytest.raises(InputError) as ei:
        gym.make("steerlab/CourseKeeping-v0", shipp="esso")
    assert ei.value.field == "shipp" and "did you mean 'ship'?" in ei.value.message
    assert "speed_kn" in ei.value.message and "render_mode" in ei.value.message
    from steerlab.gym.vector_env import SteeringVectorEnv

    with pytest.raises(InputError) as ei:
        SteeringVectorEnv(num_envs=2, episode_seconds=100.0)
    assert ei.value.field == "episode_seconds" and "did you mean 'episode_s'?" in ei.value.message



def test_settings_the_task_does_not_read_warn():
    """``change_deg`` on course keeping, a start offset on a course change, a course change at
    t = 1000 s in a 300 s episode (it never happens): accepted silently before; a negative
    change time is refused."""
    from steerlab.errors import InertSettingWarning

    with pytest.warns(InertSettingWarning, match="change_deg: has no effect here"):
        gym.make("steerlab/CourseKeeping-v0", change_deg=30.0)
    with pytest.warns(InertSettingWarning, match="initial_offset_deg: has no effect here"):
        gym.make("steerlab/CourseChange-v0", initial_offset_deg=5.0)
    with pytest.warns(InertSettingWarning, match="change_t: the course change at 1000 s comes after the episode's end"):
        gym.make("steerlab/CourseChange-v0", change_t=1000.0, episode_s=300.0)
    with pytest.raises(InputError) as ei:
        gym.make("steerlab/CourseChange-v0", change_t=-5.0)
    assert ei.value.field == "change_t"
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error", InertSettingWarning)        # the defaults and a real change: quiet
        gym.make("steerlab/CourseChange-v0", change_t=50.0, change_deg=-30.0)
        gym.make("steerlab/CourseKeeping-v0", initial_offset_deg=5.0)
        gym.make("steerlab/CourseChange-v0", episode_s=8.0)        # a short episode with the default change_t


def test_without_gymnasium_the_import_says_what_to_install():
    import subprocess
    import sys

    code = "import sys; sys.modules['gymnasium'] = None; import steerlab.gym"   # None: as if not installed
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.returncode == 1
    last = out.stderr.strip().splitlines()[-1]
    assert last == "ImportError: steerlab.gym needs gymnasium: pip install 'steerlab[rl]'"


def test_a_steerlab_pid_beats_a_random_policy_through_the_env():
    from steerlab.components.controller import controller

    env = gym.make("steerlab/CourseChange-v0", episode_s=200.0)
    pid = controller("pid", ship="esso", speed_kn=16.0, sample_time=1.0)
    rng = np.random.default_rng(0)

    def episode(policy):
        obs, _ = env.reset(seed=1)
        pid.reset()
        total, k, done = 0.0, 0, False
        while not done:
            obs, r, te, tr, _ = env.step(policy(obs, k))
            total, k, done = total + r, k + 1, te or tr
        return total, obs

    rand, _ = episode(lambda o, k: rng.uniform(-1, 1, size=1).astype(np.float32))
    dmax = np.radians(35.0)
    ctrl, last = episode(lambda o, k: np.array([np.clip(pid.step(k, 0.0, o[1], o[0], rudder=o[2]) / dmax, -1, 1)],
                                               dtype=np.float32))
    assert ctrl > 2.0 * rand                   # returns are negative: the PID's cost is under half
    assert abs(last[0]) < np.radians(8.0)      # and it has turned most of the 20 deg (slow Esso)


def test_track_following_with_a_pid_converges_on_the_route():
    from steerlab.components.controller import controller

    env = gym.make("steerlab/TrackFollowing-v0", ship="nomoto1", speed_kn=10.0, environment={},
                   episode_s=600.0, control_dt=0.5, dt=0.5)
    pid = controller("pid", Kp=3.0, Ki=0.0, Kd=67.0, sample_time=0.5)   # docs/guidance.md's LOS example
    obs, _ = env.reset(seed=0)
    xte = []
    dmax = np.radians(35.0)
    for k in range(1200):
        a = np.clip(pid.step(0.5 * k, 0.0, obs[1], obs[0], rudder=obs[2]) / dmax, -1, 1)
        obs, r, te, tr, info = env.step(np.array([a], dtype=np.float32))
        xte.append(info["xte"])
        if te or tr:
            break
    assert abs(xte[0]) > 150.0                  # started 200 m off the line
    assert abs(xte[-1]) < 10.0                  # and converged onto it


def test_selectable_rewards_are_the_criteria_of_the_observed_error():
    envs = {name: gym.make("steerlab/CourseKeeping-v0", reward=name, **KW) for name in ("speed_loss", "itae", "iae")}
    out = {}
    for name, env in envs.items():
        env.reset(seed=3)
        for _ in range(4):
            o, r, *_ = env.step(np.array([0.2], dtype=np.float32))
        out[name] = (o, r)
    o = out["iae"][0]
    assert np.array_equal(o, out["itae"][0]) and np.array_equal(o, out["speed_loss"][0])
    assert out["iae"][1] == pytest.approx(-abs(o[0]) * 1.0)
    assert out["itae"][1] == pytest.approx(-4.0 * abs(o[0]) * 1.0)          # t = 4 s
    assert out["speed_loss"][1] == pytest.approx(-(o[0] ** 2 + 0.1 * o[2] ** 2))
    with pytest.raises(InputError) as ei:
        gym.make("steerlab/CourseKeeping-v0", reward="fun")
    assert ei.value.field == "reward"
