# tier: gl
"""saccade.envs: Gymnasium's API contract (what gymnasium.utils.env_checker checks), the
fixation task, bad actions, and the vector env's batching and autoreset."""

import math

import numpy as np
import pytest

import saccade
from saccade.envs import AutoresetMode, FixationEnv, VectorFixationEnv

SIZE = 32


def same_image(a, b):
    # Env i of a vector env is drawn as a single env's head is (each tile at the origin of its
    # own layer, internal_batch.cc): the same pixels to the bit.
    return a.dtype == b.dtype and np.array_equal(a, b)


@pytest.fixture(scope="module")
def env():
    e = FixationEnv(render_mode="rgb_array", image_size=SIZE, max_episode_steps=5)
    yield e
    e.close()


def check_obs(obs, space, shape):
    assert set(obs) == {"left", "right", "joints"}
    assert obs["left"].shape == shape + (SIZE, SIZE, 3) and obs["left"].dtype == np.uint8
    assert obs["joints"].dtype == np.float32
    assert space.contains(obs)


def test_api_shapes_dtypes_and_spaces(env):
    assert env.metadata["render_modes"] == ["rgb_array"] and env.metadata["render_fps"] == 25
    assert env.render_mode == "rgb_array"
    obs, info = env.reset(seed=0)
    check_obs(obs, env.observation_space, ())
    assert isinstance(info, dict) and info["axis_error"].shape == (2,)
    assert obs["left"].std() > 1.0, "the eyes see a scene, not a blank image"
    action = env.action_space.sample()
    assert env.action_space.contains(action)
    obs, reward, terminated, truncated, info = env.step(action)
    check_obs(obs, env.observation_space, ())
    assert isinstance(reward, float) and isinstance(terminated, bool) and isinstance(truncated, bool)
    frame = env.render()
    assert frame.shape == (SIZE, 2 * SIZE, 3) and frame.dtype == np.uint8
    assert isinstance(env.np_random, np.random.Generator)


def test_same_seed_same_observations_and_steps(env):
    def rollout(seed):
        obs, _ = env.reset(seed=seed)
        env.action_space.seed(seed)
        out = [obs]
        for _ in range(3):
            obs, reward, *_ = env.step(env.action_space.sample())
            out.append((obs, reward))
        return out

    a, b = rollout(123), rollout(123)
    assert all(np.array_equal(a[0][k], b[0][k]) for k in a[0])
    for (obs_a, r_a), (obs_b, r_b) in zip(a[1:], b[1:]):
        assert r_a == r_b
        assert all(np.array_equal(obs_a[k], obs_b[k]) for k in obs_a)
    c = rollout(124)
    assert not np.array_equal(a[0]["left"], c[0]["left"]), "another seed, another scene"


def test_truncation_after_max_episode_steps(env):
    env.reset(seed=1)
    zero = np.zeros(4, np.float32)
    flags = [env.step(zero)[3] for _ in range(5)]
    assert flags == [False, False, False, False, True]


def test_fixating_with_ik_is_rewarded_and_terminates():
    e = FixationEnv(image_size=SIZE, action_mode="target", success_deg=1.0)
    obs, info = e.reset(seed=7)
    head = e._heads.head
    ik = head.fixate(info["target_W"])
    assert ik.reachable, ik.message
    target = np.asarray(ik.joints, dtype=np.float32)
    rewards = []
    terminated = False
    for _ in range(50):
        obs, reward, terminated, truncated, info = e.step(target)
        rewards.append(reward)
        if terminated:
            break
    assert terminated and info["is_success"]
    assert rewards[-1] > 0.9 and rewards[0] < rewards[-1]
    assert np.all(info["axis_error"] < math.radians(1.0))
    e.close()


@pytest.mark.parametrize("action, message", [
    (np.zeros(3, np.float32), r"shape \(4,\)"),
    (np.array([np.nan, 0, 0, 0], np.float32), "non-finite"),
    (np.array([0, 0, -np.inf, 0]), "non-finite"),
    (np.array([0, 100.0, 0, 0], np.float32), "joint 'tilt' is 100 rad/s; expected"),
    ("left", "numbers"),
])
def test_bad_actions_are_refused_with_a_clear_error(env, action, message):
    env.reset(seed=2)
    with pytest.raises(saccade.InvalidArgument, match=message):
        env.step(action)


def test_bad_construction_is_refused():
    with pytest.raises(saccade.InvalidArgument, match="render_mode"):
        FixationEnv(render_mode="human")
    with pytest.raises(saccade.InvalidArgument, match="action_mode"):
        FixationEnv(action_mode="torque")
    # saccade.InvalidArgument without gymnasium; with it, Gymnasium's own error (gymnasium_test.py).
    gymnasium = saccade.envs.fixation._gymnasium
    with pytest.raises((ValueError,) + ((gymnasium.error.Error,) if gymnasium else ()),
                       match="(?i)seed"):
        FixationEnv(image_size=SIZE).reset(seed=-1)


def test_vector_env_contract_and_batch_equals_single_envs():
    n = 3
    venv = VectorFixationEnv(num_envs=n, image_size=SIZE, max_episode_steps=4)
    assert venv.num_envs == n
    assert venv.single_observation_space["left"].shape == (SIZE, SIZE, 3)
    assert venv.observation_space["left"].shape == (n, SIZE, SIZE, 3)
    assert venv.action_space.shape == (n, 4)
    assert venv.metadata["autoreset_mode"].value == "NextStep"
    obs, infos = venv.reset(seed=10)
    check_obs(obs, venv.observation_space, (n,))
    # Env i of the vector, seeded seed + i, sees what a single env seeded seed + i sees.
    single = FixationEnv(image_size=SIZE)
    for i in range(n):
        o, info = single.reset(seed=10 + i)
        assert same_image(o["left"], obs["left"][i]) and same_image(o["right"], obs["right"][i])
        assert np.allclose(info["target_W"], infos["target_W"][i])
    actions = venv.action_space.sample()
    obs, rewards, terminations, truncations, infos = venv.step(actions)
    assert rewards.shape == (n,) and terminations.dtype == bool and truncations.shape == (n,)
    assert infos["_axis_error"].all()
    with pytest.raises(saccade.InvalidArgument, match=r"shape \(3, 4\)"):
        venv.step(np.zeros(4, np.float32))
    venv.close()


def test_vector_env_autoreset_next_step():
    venv = VectorFixationEnv(num_envs=2, image_size=SIZE, max_episode_steps=2)
    venv.reset(seed=0)
    zero = np.zeros((2, 4), np.float32)
    venv.step(zero)
    _, _, _, truncated, _ = venv.step(zero)
    assert truncated.all()
    # The next step resets: reward 0, flags clear, episode counters back to 0.
    obs, rewards, terminated, truncated, _ = venv.step(zero)
    assert not truncated.any() and not terminated.any() and np.all(rewards == 0.0)
    assert np.all(venv._heads.steps == 0)
    venv.close()


def test_vector_env_autoreset_same_step():
    venv = VectorFixationEnv(num_envs=2, image_size=SIZE, max_episode_steps=1,
                             autoreset_mode=AutoresetMode.SAME_STEP)
    venv.reset(seed=0)
    obs, rewards, terminated, truncated, infos = venv.step(np.zeros((2, 4), np.float32))
    assert truncated.all()
    assert infos["_final_obs"].all() and infos["final_obs"][0]["left"].shape == (SIZE, SIZE, 3)
    assert np.all(venv._heads.steps == 0)
    venv.close()


# Issue 42: the env takes any head; its joints are the head's driven joints, by name.
@pytest.mark.parametrize("name", ["humanoid", "pan_tilt_vergence", "popeye_urdf"])
def test_any_head_fixates_its_target_with_its_own_joints(name):
    e = FixationEnv(image_size=SIZE, action_mode="target", success_deg=1.0, head=name)
    head = saccade.head.Head.from_file(saccade.envs.fixation.head_file(name))
    assert e.joint_names == head.driven_joints
    obs, info = e.reset(seed=7)
    assert obs["joints"].shape == (len(head.driven_joints),)
    assert e.action_space.shape == (len(head.driven_joints),)
    ik = head.fixate(info["target_W"])
    assert ik.reachable, ik.message
    driven = [head.joint_names.index(n) for n in e.joint_names]
    target = ik.joints[driven].astype(np.float32)
    start = np.abs(obs["joints"] - target).max()
    terminated = False
    for _ in range(60):
        obs, reward, terminated, truncated, info = e.step(target)
        if terminated:
            break
    assert terminated and info["is_success"], info["axis_error"]
    # The joints went toward the solution: nearer it than at the start.
    assert np.abs(obs["joints"] - target).max() < start
    # The target is in both eyes' images near their centres: the view changed with the head.
    assert obs["left"].std() > 0 and obs["right"].std() > 0


def test_an_action_of_popeyes_size_on_another_head_names_its_joints():
    e = FixationEnv(image_size=SIZE, head="pan_tilt_vergence")
    e.reset(seed=1)
    with pytest.raises(saccade.InvalidArgument, match=r"shape \(3,\) \(pan, tilt, vergence\)"):
        e.step(np.zeros(4, np.float32))


def test_an_unknown_head_lists_the_shipped_ones():
    with pytest.raises(saccade.InvalidArgument, match="shipped: .*humanoid"):
        FixationEnv(image_size=SIZE, head="octopus")
