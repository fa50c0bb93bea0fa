"""The vector environment: Gymnasium's SyncVectorEnv of the single environments, bit for bit, stepped on threads."""

import gymnasium
import numpy as np
import pytest

import trms.envs.gym  # noqa: F401  (registers the environments and their vector entry point)
from trms.envs.gym import InvalidActionError, InvalidSeedError, TwinTaskEnv
from trms.envs.vector import TwinVectorEnv
from trms.errors import DivergenceError, InputError


def _pair(task, n, normalised=False):
    sync = gymnasium.vector.SyncVectorEnv([lambda: TwinTaskEnv(task, normalised=normalised) for _ in range(n)])
    return sync, TwinVectorEnv(task, n, normalised=normalised, threads=2)  # two shares, whatever the machine


def _assert_same(a, b):
    for x, y in zip(a[:-1], b[:-1]):
        assert x.dtype == y.dtype and x.tobytes() == y.tobytes()
    assert set(a[-1]) == set(b[-1])
    for key, value in a[-1].items():
        assert np.array_equal(value, b[-1][key]), key


@pytest.mark.parametrize("task, steps", [("HoverGusts", 305), ("PitchTracking", 60), ("AttitudeTracking", 30)])
def test_each_environment_is_the_single_one_through_autoresets(task, steps):
    sync, vec = _pair(task, 3)
    _assert_same(sync.reset(seed=11), vec.reset(seed=11))
    trim = vec.runners[0].twin.operating_point.inputs
    rng = np.random.default_rng(0)
    for _ in range(steps):  # HoverGusts' 300-step episodes end and restart on the next step
        actions = trim + rng.uniform(-0.4, 0.4, (3, trim.size))
        _assert_same(sync.step(actions), vec.step(actions))
    assert vec.metadata["autoreset_mode"] == gymnasium.vector.AutoresetMode.NEXT_STEP
    vec.close()


def test_normalised_spaces_and_seeds_per_environment():
    sync, vec = _pair("PitchTracking", 2, normalised=True)
    assert vec.single_action_space == sync.single_action_space and vec.observation_space == sync.observation_space
    _assert_same(sync.reset(seed=[5, None]), vec.reset(seed=[5, None]))
    actions = np.array([[0.2], [-0.1]], np.float32)
    _assert_same(sync.step(actions), vec.step(actions))
    mask = np.array([False, True])
    _assert_same(sync.reset(seed=3, options={"reset_mask": mask}), vec.reset(seed=3, options={"reset_mask": mask}))


def test_make_vec_builds_it_from_the_registry():
    envs = gymnasium.make_vec("trms/HoverGusts-v0", num_envs=2)
    assert isinstance(envs.unwrapped, TwinVectorEnv) and envs.num_envs == 2
    obs, _ = envs.reset(seed=0)
    assert obs.shape == (2, len(envs.unwrapped.observation_names))
    envs.close()


def test_a_diverged_environment_ends_its_episode_and_restarts_on_the_next_step(monkeypatch):
    vec = TwinVectorEnv("PitchTracking", 2, threads=2)
    vec.reset(seed=0)
    twin = vec.runners[1].twin

    def blow_up(u):
        raise DivergenceError("simulation diverged (forced)")

    monkeypatch.setattr(twin, "step", blow_up)
    trim = np.tile(twin.operating_point.inputs, (2, 1))
    obs, reward, terminated, truncated, info = vec.step(trim)
    assert terminated.tolist() == [False, True] and reward[1] == 0.0 and info["_diverged"].tolist() == [False, True]
    monkeypatch.undo()
    obs, reward, terminated, truncated, info = vec.step(trim)  # the next step resets it: its action is ignored
    assert reward[1] == 0.0 and not terminated.any() and info["time"][1] == 0.0 and info["_reference"][1]


@pytest.mark.parametrize(
    "actions, match",
    [
        (np.zeros((3, 1)), r"actions must have shape \(2, 1\)"),
        (np.array([[0.0], [np.nan]]), r"action \(u1\) in V"),
        (np.array([["a"], ["b"]]), r"action \(u1\) in V"),
        (np.array([[1j], [0.0]]), r"action \(u1\) in V"),
    ],
)
def test_malformed_actions_are_refused_in_one_line_and_change_nothing(actions, match):
    vec = TwinVectorEnv("PitchTracking", 2, threads=1)
    vec.reset(seed=0)
    with pytest.raises(InvalidActionError, match=match):
        vec.step(actions)
    assert [r.twin.time for r in vec.runners] == [0.0, 0.0]


def test_misuse_is_refused():
    vec = TwinVectorEnv("PitchTracking", 2, threads=1)
    with pytest.raises(gymnasium.error.ResetNeeded):
        vec.step(np.zeros((2, 1)))
    for kwargs, match in (
        ({"options": {"foo": 1}}, r"unknown reset option 'foo'"),
        ({"options": {"reset_mask": np.zeros(2, bool)}}, r"reset_mask = .* must be a numpy bool array"),
    ):
        with pytest.raises(InputError, match=match):
            vec.reset(**kwargs)
    for kwargs, match in (
        ({"num_envs": 0}, r"num_envs = 0 must be a whole number >= 1"),
        ({"num_envs": 2, "threads": 1.5}, r"threads = 1\.5 must be a whole number >= 1"),
        ({"num_envs": 2, "max_episode_steps": 10}, r"a PitchTracking episode is 200 steps"),
    ):
        with pytest.raises(InputError, match=match):
            TwinVectorEnv("PitchTracking", **kwargs)


@pytest.mark.parametrize(
    "seed, match",
    [
        ([1], r"reset seed = \[1\] has 1 seeds; allowed: one per environment \(2\)"),
        ([3, -1], r"reset seed\[1\] = -1 \(int\); allowed: None or a whole number >= 0"),
        ([3, 1.5], r"reset seed\[1\] = 1\.5 \(float\)"),
        ((True, 3), r"reset seed\[0\] = True \(bool\)"),
        ([None, "a"], r"reset seed\[1\] = 'a' \(str\)"),
        (-5, r"reset seed = -5 \(int\); allowed: None or a whole number >= 0 \(int\), or a list of 2 of them"),
        (np.int64(-1), r"reset seed = np\.int64\(-1\) \(int64\)"),
        ("x", r"reset seed = 'x' \(str\)"),
        (2.0, r"reset seed = 2\.0 \(float\)"),
    ],
)
def test_a_bad_seed_is_refused_in_one_line_before_any_environment_resets(seed, match):
    vec = TwinVectorEnv("PitchTracking", 2, threads=1)
    vec.reset(seed=0)
    vec.step(np.tile(vec.runners[0].twin.operating_point.inputs, (2, 1)))
    before = [(r.twin.time, r.reference.tobytes()) for r in vec.runners]
    with pytest.raises(InvalidSeedError, match=match) as info:
        vec.reset(seed=seed)
    assert isinstance(info.value, gymnasium.error.Error) and isinstance(info.value, InputError)
    assert "\n" not in str(info.value)
    assert [(r.twin.time, r.reference.tobytes()) for r in vec.runners] == before  # no environment reset


def test_seeds_set_each_environments_episodes_as_the_single_environments():
    """An int seeds environment i with seed + i, a list one each; later resets without a seed (and autoresets) draw
    each environment's next episode from its own sequence; numpy integers are seeds too."""
    sync, vec = _pair("PitchTracking", 3)
    for seed in (7, [np.int64(4), None, 9], None, None):
        _assert_same(sync.reset(seed=seed), vec.reset(seed=seed))
    first = vec.reset(seed=7)[0]
    assert not np.array_equal(first[0], first[1])  # different seeds: different references
    again = TwinVectorEnv("PitchTracking", 3, threads=2)
    assert again.reset(seed=7)[0].tobytes() == first.tobytes()  # same seed, same bits
    assert again.reset(seed=[8, 9, 7])[0][2].tobytes() == first[0].tobytes()  # environment 0's seed 7, anywhere


def test_against_a_stop_each_environment_is_still_the_single_one():
    sync, vec = _pair("PitchTracking", 2)
    _assert_same(sync.reset(seed=1), vec.reset(seed=1))
    touched = 0
    for _ in range(60):  # full thrust: the beam climbs onto its stop and rests there
        _assert_same(sync.step(np.full((2, 1), 10.0)), vec.step(np.full((2, 1), 10.0)))
        touched += sum(env.runner.twin.channels()["at_stop"][0] for env in sync.envs)
    assert touched > 40  # the solver's warm start kept in each twin's own data: the same bits on the stop too


def test_a_closed_environment_refuses_to_step():
    vec = TwinVectorEnv("PitchTracking", 2, threads=2)
    vec.reset(seed=0)
    vec.close()
    with pytest.raises(InputError, match="this vector environment is closed"):
        vec.step(np.zeros((2, 1)))
