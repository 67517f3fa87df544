# tier: gl
# cost: 80  (seconds on CI's 2 cores: ctest -j starts the longest first; tests/python/python_tests.cmake)
"""saccade.envs judged by Gymnasium 1.4.0's own code (../shared/third_party/gymnasium beside the
checkout, not a Debian package): check_env on every documented construction of FixationEnv,
gymnasium.make / make_vec with the standard wrappers, VectorFixationEnv step for step against
gymnasium.vector.SyncVectorEnv of FixationEnv in every autoreset mode (observations to the bit,
rewards, flags, infos with their masks, final_obs / final_info), pickling mid-episode, and the
seeding errors. Skipped, saying why, where Gymnasium's package is missing."""

import importlib
import os
import pickle
import sys
import warnings

import numpy as np
import pytest

GYMNASIUM_DIR = os.path.normpath(os.path.join(
    os.environ.get("SACCADE_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", "..")),
    "..", "shared", "third_party", "gymnasium"))
try:
    import gymnasium  # noqa: F401 - on PYTHONPATH already
except ImportError:
    if not os.path.isdir(os.path.join(GYMNASIUM_DIR, "gymnasium")):
        pytest.skip(f"Gymnasium's package is not at {GYMNASIUM_DIR} (../shared/third_party/"
                    "gymnasium beside the checkout): these tests need Gymnasium itself",
                    allow_module_level=True)
    sys.path.insert(0, GYMNASIUM_DIR)
    import gymnasium

from gymnasium.utils.env_checker import check_env, data_equivalence  # noqa: E402
from gymnasium.utils.env_match import check_environments_match  # noqa: E402
from gymnasium.vector import AutoresetMode, SyncVectorEnv  # noqa: E402

import saccade  # noqa: E402
import saccade.envs.fixation  # noqa: E402

if saccade.envs.fixation._gymnasium is None:
    # saccade.envs was imported before Gymnasium was on the path (by another test file of the
    # same run): the envs chose their gymnasium-free classes then. Reload them as a user with
    # Gymnasium installed gets them.
    for module in ("saccade.envs.spaces", "saccade.envs.fixation", "saccade.envs"):
        importlib.reload(sys.modules[module])
# conftest.py imported saccade before Gymnasium was on the path: register as `import saccade`
# does with Gymnasium installed (once).
saccade._register_gymnasium()

from saccade.envs import ENV_ID, EpisodeEnded, FixationEnv, VectorFixationEnv  # noqa: E402

SIZE = 32  # small images: the whole file runs in seconds on llvmpipe
# Short episodes (and a generous success angle, so some end by termination) for autoresets.
SHORT = dict(image_size=SIZE, max_episode_steps=3, success_deg=20.0)


# The one warning of check_env that saccade keeps on purpose (docs/python.md): actions in rad/s
# or rad, not [-1, 1] (RescaleAction gives that).
PHYSICAL_UNITS = "For Box action spaces, we recommend using a symmetric and normalized space"


def strict_check_env(env, allowed=()):
    """check_env with every Gymnasium warning an error, except PHYSICAL_UNITS and those
    matching `allowed`."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for message in (PHYSICAL_UNITS,) + tuple(allowed):
            warnings.filterwarnings("ignore", message=".*" + message)
        check_env(env)


def same(a, b):
    return data_equivalence(a, b, exact=True)


def test_envs_are_gymnasiums_classes():
    env = FixationEnv(image_size=SIZE)
    venv = VectorFixationEnv(num_envs=2, image_size=SIZE)
    assert isinstance(env, gymnasium.Env)
    assert isinstance(venv, gymnasium.vector.VectorEnv)
    assert isinstance(env.observation_space, gymnasium.spaces.Dict)
    assert venv.metadata["autoreset_mode"] is AutoresetMode.NEXT_STEP
    env.close()
    venv.close()


# Every construction docs/python.md names: action modes, image sizes (a side, or width and
# height), render modes, and no step limit of its own.
CONSTRUCTIONS = [
    dict(image_size=SIZE),
    dict(image_size=SIZE, action_mode="target"),
    dict(image_size=(48, SIZE), render_mode="rgb_array"),
    dict(image_size=SIZE, action_mode="target", render_mode="rgb_array", max_episode_steps=None),
    # Any head (issue 42): six joints, a mimic vergence, a camera pair that cannot verge.
    dict(image_size=SIZE, head="humanoid"),
    dict(image_size=SIZE, action_mode="target", head="pan_tilt_vergence"),
    dict(image_size=SIZE, head="pan_tilt_fixed"),
]


@pytest.mark.parametrize("kwargs", CONSTRUCTIONS, ids=lambda k: ",".join(f"{a}={v}" for a, v in k.items()))
def test_check_env_passes_on_every_documented_construction(kwargs):
    # Made directly (no spec: check_env says it cannot try the other render modes)...
    env = FixationEnv(**kwargs)
    strict_check_env(env, allowed=["Not able to test alternative render modes"])
    env.close()
    # ...and through gymnasium.make (with a spec: every render mode, and close twice).
    made = gymnasium.make(ENV_ID, **kwargs)
    strict_check_env(made.unwrapped)
    made.close()


def test_make_runs_every_standard_wrapper_and_the_limit_is_the_specs():
    spec = gymnasium.spec(ENV_ID)
    assert spec.max_episode_steps == saccade.envs.MAX_EPISODE_STEPS == 200
    env = gymnasium.make(ENV_ID, image_size=SIZE, max_episode_steps=3)
    assert env.spec.max_episode_steps == 3
    # The env has no limit of its own: make's TimeLimit holds it, so make(..., k) means k.
    assert env.unwrapped._heads.max_episode_steps is None
    env = gymnasium.wrappers.RescaleAction(env, -1.0, 1.0)
    env = gymnasium.wrappers.ClipAction(env)
    env = gymnasium.wrappers.FlattenObservation(env)
    env = gymnasium.wrappers.RecordEpisodeStatistics(env)
    assert any(isinstance(w, gymnasium.wrappers.TimeLimit) for w in _wrappers(env))
    obs, info = env.reset(seed=4)
    assert obs.shape == (2 * SIZE * SIZE * 3 + 4,) and obs in env.observation_space
    env.action_space.seed(4)
    lengths = []
    for _ in range(7):
        # Twice the rescaled range: ClipAction brings it back into the action space.
        obs, reward, terminated, truncated, info = env.step(2.0 * env.action_space.sample())
        if terminated or truncated:
            lengths.append(int(info["episode"]["l"]))
            env.reset()
    assert lengths and all(1 <= n <= 3 for n in lengths) and 3 in lengths, lengths
    env.close()
    # Without a step limit from make: the registered 200, in TimeLimit.
    env = gymnasium.make(ENV_ID, image_size=SIZE)
    limits = [w._max_episode_steps for w in _wrappers(env) if isinstance(w, gymnasium.wrappers.TimeLimit)]
    assert limits == [200]
    env.close()


def _wrappers(env):
    while isinstance(env, gymnasium.Wrapper):
        yield env
        env = env.env


def test_make_vec_passes_the_limit_to_the_vector_env():
    venv = gymnasium.make_vec(ENV_ID, num_envs=2, image_size=SIZE)
    assert isinstance(venv.unwrapped, VectorFixationEnv)
    assert venv.unwrapped._heads.max_episode_steps == 200
    venv.close()
    venv = gymnasium.make_vec(ENV_ID, num_envs=2, image_size=SIZE, max_episode_steps=2)
    venv = gymnasium.wrappers.vector.RecordEpisodeStatistics(venv)
    venv.reset(seed=0)
    zero = np.zeros((2, 4), np.float32)
    assert not venv.step(zero)[3].any()
    _, _, terminated, truncated, infos = venv.step(zero)
    assert truncated.all() and not terminated.any()
    assert np.array_equal(infos["episode"]["l"], [2, 2])
    venv.close()


def run_both(mode, steps, check, n=3):
    """VectorFixationEnv and SyncVectorEnv of FixationEnv, same seeds and actions, in
    autoreset `mode`; `check` compares each step's outputs. Returns what happened."""
    ours = VectorFixationEnv(num_envs=n, autoreset_mode=mode, **SHORT)
    ref = SyncVectorEnv([lambda: FixationEnv(**SHORT) for _ in range(n)], autoreset_mode=mode)
    assert ours.single_observation_space == ref.single_observation_space
    assert ours.observation_space == ref.observation_space
    assert ours.single_action_space == ref.single_action_space
    assert ours.action_space == ref.action_space
    assert ours.metadata["autoreset_mode"] == ref.metadata["autoreset_mode"]
    a, b = ours.reset(seed=21), ref.reset(seed=21)
    check("reset", a, b)
    ours.action_space.seed(5)
    seen = {"terminated": 0, "truncated": 0, "final_info": 0, "masked_resets": 0}
    for t in range(steps):
        actions = ours.action_space.sample()
        a, b = ours.step(actions), ref.step(actions)
        check(f"step {t}", a, b)
        seen["terminated"] += int(a[2].sum())
        seen["truncated"] += int(a[3].sum())
        seen["final_info"] += int("final_info" in a[4])
        ended = a[2] | a[3]
        if mode == AutoresetMode.DISABLED and ended.any():
            # Continuing an ended sub-env is refused (an AssertionError, as SyncVectorEnv's),
            # before any sub-env moves: the next steps still match. (SyncVectorEnv itself
            # would step the sub-envs before the ended one, then raise.)
            with pytest.raises(AssertionError, match=r"episodes of sub-envs \[.*\] ended"):
                ours.step(actions)
            # Reset of the ended ones only, with seeds: the others keep their generators.
            kept = [ours._rng(i).bit_generator.state for i in range(n)]
            a = ours.reset(seed=100 + t, options={"reset_mask": ended.copy()})
            b = ref.reset(seed=100 + t, options={"reset_mask": ended.copy()})
            check(f"masked reset after step {t}", a, b)
            for i in np.flatnonzero(~ended):
                assert ours._rng(i).bit_generator.state == kept[i]
                assert ref.envs[i].np_random.bit_generator.state == kept[i]
            seen["masked_resets"] += 1
    ours.close()
    ref.close()
    return seen


def check_exact(where, a, b):
    assert len(a) == len(b)
    names = ("observations", "rewards", "terminations", "truncations", "infos")
    if len(a) == 2:
        names = ("observations", "infos")
    for name, x, y in zip(names, a, b):
        if name == "observations":
            for key in y:
                diff = np.abs(x[key].astype(float) - y[key].astype(float))
                assert x[key].dtype == y[key].dtype and np.count_nonzero(diff) == 0, (
                    f"{where}: {key} differs in {np.count_nonzero(diff)} values")
        assert same(x, y), f"{where}: {name}\nours {x}\nSyncVectorEnv {y}"


@pytest.mark.parametrize("mode", list(AutoresetMode), ids=lambda m: m.value)
def test_vector_env_matches_sync_vector_env_step_for_step(mode):
    seen = run_both(mode, steps=10, check=check_exact)
    # The run covered what it compares: both endings and, per mode, the autoreset.
    assert seen["terminated"] > 0 and seen["truncated"] > 0, seen
    if mode == AutoresetMode.SAME_STEP:
        assert seen["final_info"] > 0, seen
    if mode == AutoresetMode.DISABLED:
        assert seen["masked_resets"] > 0, seen


def test_same_step_infos_are_the_new_episodes_and_final_info_is_batched():
    venv = VectorFixationEnv(num_envs=2, autoreset_mode=AutoresetMode.SAME_STEP,
                             image_size=SIZE, max_episode_steps=1)
    venv.reset(seed=3)
    obs, _, _, truncated, infos = venv.step(np.zeros((2, 4), np.float32))
    assert truncated.all()
    final_info = infos["final_info"]
    assert isinstance(final_info, dict) and final_info["_target_W"].all()
    assert infos["final_obs"].dtype == object and infos["_final_obs"].all()
    # The top-level info is the new episode's, as the observation is.
    assert not np.array_equal(final_info["target_W"], infos["target_W"])
    assert np.array_equal(infos["target_W"], venv._heads.target)
    assert np.array_equal(obs["joints"], venv._heads.joints.astype(np.float32))
    assert set(infos["target_kind"]) <= {"picture", "mug", "box", "sphere"}
    venv.close()


def test_reset_mask_is_checked_as_gymnasium_does():
    venv = VectorFixationEnv(num_envs=2, autoreset_mode=AutoresetMode.DISABLED, image_size=SIZE)
    venv.reset(seed=0)
    with pytest.raises(ValueError, match="at least one True"):
        venv.reset(options={"reset_mask": np.zeros(2, dtype=bool)})
    with pytest.raises(saccade.InvalidArgument, match=r"bool array of shape \(2,\)"):
        venv.reset(options={"reset_mask": np.ones(3, dtype=bool)})
    venv.close()


def test_negative_seed_raises_gymnasiums_error():
    env = FixationEnv(image_size=SIZE)
    with pytest.raises(gymnasium.error.Error, match="Seed must be greater or equal to zero"):
        env.reset(seed=-1)
    venv = VectorFixationEnv(num_envs=2, image_size=SIZE)
    with pytest.raises(gymnasium.error.Error, match="Seed must be greater or equal to zero"):
        venv.reset(seed=-1)
    env.close()
    venv.close()


def test_pickle_round_trip_mid_episode_gives_the_same_next_steps():
    env = FixationEnv(image_size=SIZE, render_mode="rgb_array")
    env.reset(seed=8)
    env.action_space.seed(8)
    for _ in range(2):
        env.step(env.action_space.sample())
    copy = pickle.loads(pickle.dumps(env))
    assert copy is not env and copy._heads.renderer is not env._heads.renderer
    assert same(copy.render(), env.render())
    for _ in range(2):
        action = env.action_space.sample()
        assert copy.action_space.sample() is not None  # the copy's space continues alike
        assert same(copy.step(action), env.step(action))
    # The generator came along: the next unseeded episodes are the same.
    assert same(copy.reset(), env.reset())
    # Gymnasium's own comparison of two envs, seeded alike.
    check_environments_match(env, pickle.loads(pickle.dumps(env)), num_steps=3, seed=2)
    env.close()
    copy.close()


@pytest.mark.parametrize("mode", list(AutoresetMode), ids=lambda m: m.value)
def test_vector_env_pickles_mid_episode(mode):
    venv = VectorFixationEnv(num_envs=2, autoreset_mode=mode, **SHORT)
    venv.reset(seed=30)
    venv.action_space.seed(30)
    for _ in range(2):
        venv.step(venv.action_space.sample())
    copy = pickle.loads(pickle.dumps(venv))
    assert copy.autoreset_mode == venv.autoreset_mode
    for _ in range(3):
        actions = venv.action_space.sample()
        try:
            expected = venv.step(actions)
        except EpisodeEnded:
            with pytest.raises(EpisodeEnded):
                copy.step(actions)
            break
        assert same(copy.step(actions), expected)
    venv.close()
    copy.close()


def test_same_seed_same_rollout_and_render():
    # Gymnasium's generic determinism test: two envs, the same seed and actions.
    a = FixationEnv(image_size=SIZE, render_mode="rgb_array")
    b = FixationEnv(image_size=SIZE, render_mode="rgb_array")
    check_environments_match(a, b, num_steps=5, seed=11)
    a.close()
    b.close()
