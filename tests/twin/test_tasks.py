"""The control tasks behind both APIs: Gymnasium's env checker, dm_env's conformance mixin, one engine."""

import unittest

import gymnasium
import numpy as np
import pytest
from dm_env import test_utils
from gymnasium.utils.env_checker import check_env

import trms.twin.gym  # noqa: F401  (registers the environments)
from trms.errors import InputError
from trms.twin.env import SUITE, load
from trms.twin.gym import ENV_IDS
from trms.twin.tasks import TASKS, TaskRunner, get_task


# The checker recommends actions normalised to [-1, 1]; the tasks act in volts on purpose.
@pytest.mark.filterwarnings("ignore:.*symmetric and normalized space")
@pytest.mark.parametrize("env_id", list(ENV_IDS.values()))
def test_every_registered_task_passes_gymnasiums_checker_and_renders(env_id):
    env = gymnasium.make(env_id, render_mode="rgb_array")
    check_env(env.unwrapped)
    env.reset(seed=3)
    frame = env.render()
    assert frame.shape == (240, 320, 3) and frame.dtype == np.uint8 and frame.std() > 0
    env.close()


def test_registered_ids_are_in_the_trms_namespace():
    assert set(ENV_IDS.values()) == {"trms/PitchTracking-v0", "trms/HoverGusts-v0", "trms/AttitudeTracking-v0"}
    assert all(i in gymnasium.registry for i in ENV_IDS.values())


def test_seeded_reset_gives_the_same_episode_bits():
    env = gymnasium.make("trms/HoverGusts-v0")
    a = [env.reset(seed=7)[0]] + [env.step(np.array([1.0, -1.0]))[0] for _ in range(20)]
    b = [env.reset(seed=7)[0]] + [env.step(np.array([1.0, -1.0]))[0] for _ in range(20)]
    c = env.reset(seed=8)[0]
    assert all(np.array_equal(x, y) for x, y in zip(a, b))
    assert not np.array_equal(a[0], c)


def test_saturation_is_recorded_in_info():
    env = gymnasium.make("trms/AttitudeTracking-v0")
    env.reset(seed=0)
    _, _, _, _, info = env.step(np.array([12.0, -3.0]))
    assert info["saturated"].tolist() == [True, False]
    assert info["applied_volts"].tolist() == [10.0, -3.0]


def test_observations_stay_in_their_documented_bounds_under_random_volts():
    env = gymnasium.make("trms/HoverGusts-v0")
    env.action_space.seed(0)
    obs, _ = env.reset(seed=0)
    for _ in range(100):
        obs, *_ = env.step(env.action_space.sample())
        assert env.observation_space.contains(obs)
    assert len(env.unwrapped.observation_names) == env.observation_space.shape[0]


def test_episodes_truncate_at_the_tasks_duration():
    runner = TaskRunner("PitchTracking", seed=0)
    runner.reset()
    trim = runner.twin.operating_point.inputs
    steps, truncated = 0, False
    while not truncated:
        *_, terminated, truncated, _ = runner.step(trim)
        steps += 1
        assert not terminated
    assert steps == get_task("PitchTracking").n_steps


def test_reward_is_one_on_the_reference_and_falls_off_the_tolerance():
    task = get_task("AttitudeTracking")
    bounds, margin = task.tolerance
    ref = np.array([0.1, -0.2])
    assert task.reward(ref, ref) == 1.0
    assert task.reward(ref + [0, bounds + margin], ref) == pytest.approx(0.1)
    assert task.reward(ref + [2 * (bounds + margin), 0], ref) < 0.01


def test_references_are_drawn_away_from_the_trim_within_the_amplitudes():
    runner = TaskRunner("AttitudeTracking", seed=2)
    runner.reset()
    for j, axis in enumerate(runner.twin.output_names):
        lo, hi = runner.task.amplitudes[axis]
        assert np.all(np.abs(runner.reference[:, j]) >= lo) and np.all(np.abs(runner.reference[:, j]) <= hi)


def test_hover_task_starts_displaced_and_pushes_the_beam():
    runner = TaskRunner("HoverGusts", seed=0)
    obs = runner.reset()
    names = runner.observation_names
    task = runner.task
    for axis in runner.twin.output_names:
        lo, hi = task.displacement[axis]
        assert lo - 0.01 <= abs(obs[names.index(f"angle:{axis}")]) <= hi + 0.01
    assert len(runner.twin.pushes) == task.pushes


def test_hover_gusts_are_the_experiments_gust_level():
    from trms.experiments.plants import GUST

    assert (get_task("HoverGusts").gust.std, get_task("HoverGusts").gust.time_constant) == GUST


def test_unknown_tasks_are_refused_in_one_line():
    with pytest.raises(InputError, match="unknown task 'Nope'"):
        load("Nope")
    with pytest.raises(InputError, match="unknown task"):
        gymnasium.make("trms/PitchTracking-v0", task="Nope")


def test_suite_has_every_task_and_both_apis_run_the_same_episode():
    assert set(SUITE) == set(TASKS)
    for name in TASKS:
        dm = load(name, {"random": 5})
        gym_env = gymnasium.make(ENV_IDS[name])
        ts = dm.reset()
        obs, _ = gym_env.reset(seed=5)
        assert np.array_equal(np.concatenate(list(ts.observation.values())), obs)
        volts = dm.twin.operating_point.inputs + 0.5
        for _ in range(5):
            ts = dm.step(volts)
            obs, reward, *_ = gym_env.step(volts)
            assert ts.reward == reward
            assert np.array_equal(np.concatenate(list(ts.observation.values())), obs)


class PitchTrackingConformance(test_utils.EnvironmentTestMixin, unittest.TestCase):
    def make_object_under_test(self):
        return load("PitchTracking", {"random": 0})


class HoverGustsConformance(test_utils.EnvironmentTestMixin, unittest.TestCase):
    def make_object_under_test(self):
        return load("HoverGusts", {"random": 0})


class AttitudeTrackingConformance(test_utils.EnvironmentTestMixin, unittest.TestCase):
    def make_object_under_test(self):
        return load("AttitudeTracking", {"random": 0})
