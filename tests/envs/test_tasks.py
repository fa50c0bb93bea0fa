"""The control tasks behind both APIs: Gymnasium's env checker, dm_env's conformance mixin, one engine, and
both APIs' contracts under misuse."""

import unittest
import warnings

import dm_env
import gymnasium
import numpy as np
import pytest
from dm_env import test_utils
from gymnasium.utils.env_checker import check_env

import trms.envs.gym  # noqa: F401  (registers the environments)
from trms.envs.gym import ENV_IDS, InvalidActionError
from trms.envs.suite import SUITE, load
from trms.envs.tasks import TASKS, TaskRunner, get_task
from trms.errors import DivergenceError, InputError
from trms.twin.render import TwinRenderer

BAD_ACTIONS = [
    ("a", "text values are not allowed"),
    (np.array([1.0 + 1.0j, 0.0]), "complex values are not allowed"),
    (np.array([np.nan, 0.0]), "must be finite; found nan"),
    (np.zeros(3), r"must have shape \(2,\), got shape \(3,\)"),
    (np.zeros((2, 1)), r"must have shape \(2,\), got shape \(2, 1\)"),
    (0.5, r"must have shape \(2,\), got shape \(\)"),
]


@pytest.mark.parametrize("env_id", list(ENV_IDS.values()))
def test_every_normalised_task_passes_gymnasiums_checker_without_a_warning_and_renders(env_id):
    env = gymnasium.make(env_id, render_mode="rgb_array", normalised=True)
    assert env.action_space == gymnasium.spaces.Box(-1.0, 1.0, env.action_space.shape, np.float32)
    assert env.observation_space.dtype == np.float32
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(env.unwrapped)
    env.reset(seed=3)
    frame = env.render()
    assert frame.shape == (240, 320, 3) and frame.dtype == np.uint8 and frame.std() > 0
    env.close()


# In volts the checker recommends normalised actions (the reason ``normalised=True`` exists), and nothing else.
@pytest.mark.filterwarnings("ignore:.*symmetric and normalized space")
@pytest.mark.parametrize("env_id", list(ENV_IDS.values()))
def test_every_task_in_volts_passes_gymnasiums_checker(env_id):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        warnings.filterwarnings("ignore", ".*symmetric and normalized space")
        check_env(gymnasium.make(env_id).unwrapped)


def test_normalised_actions_are_the_voltage_range_and_run_the_same_episode():
    volts_env = gymnasium.make("trms/AttitudeTracking-v0")
    unit_env = gymnasium.make("trms/AttitudeTracking-v0", normalised=True)
    a, _ = volts_env.reset(seed=4)
    b, _ = unit_env.reset(seed=4)
    assert b.dtype == np.float32 and np.array_equal(a.astype(np.float32), b)
    rng = np.random.default_rng(0)
    for _ in range(10):
        unit = rng.uniform(-1.0, 1.0, 2).astype(np.float32)
        a, ra, *_, ia = volts_env.step(10.0 * unit.astype(np.float64))
        b, rb, *_, ib = unit_env.step(unit)
        assert ra == rb and np.array_equal(a.astype(np.float32), b)
        assert np.array_equal(ia["applied_volts"], ib["applied_volts"])
    *_, info = unit_env.step(np.array([0.5, -1.0], np.float32))
    assert info["applied_volts"].tolist() == [5.0, -10.0] and not info["saturated"].any()
    *_, info = unit_env.step(np.array([1.5, 0.0], np.float32))  # beyond the range: saturated, as volts are
    assert info["applied_volts"].tolist() == [10.0, 0.0] and info["saturated"].tolist() == [True, False]


@pytest.mark.parametrize("normalised", [False, True])
def test_malformed_actions_are_refused_in_one_line_and_change_nothing(normalised):
    env = gymnasium.make("trms/HoverGusts-v0", normalised=normalised)
    good = np.array([0.1, -0.1], env.action_space.dtype)
    env.reset(seed=1)
    expected = env.step(good)[0]
    env.reset(seed=1)
    for action, message in BAD_ACTIONS:
        with pytest.raises(InvalidActionError, match=message) as err:
            env.step(action)
        assert isinstance(err.value, gymnasium.error.InvalidAction) and isinstance(err.value, InputError)
        assert "\n" not in str(err.value) and ("[-1, 1]" if normalised else "in V") in str(err.value)
    assert env.unwrapped.twin.time == 0.0
    assert np.array_equal(env.step(good)[0], expected)  # the refused actions left no trace


def test_step_needs_a_reset_first_and_after_every_episode(monkeypatch):
    raw = trms.envs.gym.TwinTaskEnv("PitchTracking")
    with pytest.raises(gymnasium.error.ResetNeeded, match=r"Cannot call env.step\(\) before calling env.reset\(\)"):
        raw.step(np.array([1.0]))
    with pytest.raises(gymnasium.error.ResetNeeded):
        gymnasium.make("trms/PitchTracking-v0").step(np.array([1.0]))
    env = gymnasium.make("trms/PitchTracking-v0")  # TimeLimit at the task's duration, as the task itself
    env.reset(seed=0)
    trim = env.unwrapped.twin.operating_point.inputs
    steps, truncated = 0, False
    while not truncated:
        *_, terminated, truncated, _ = env.step(trim)
        steps += 1
    assert steps == get_task("PitchTracking").n_steps and not terminated
    with pytest.raises(gymnasium.error.ResetNeeded, match="after the episode ended .* at t = 40.000 s"):
        env.step(trim)
    env.reset(seed=0)
    env.step(trim)  # a reset starts the next episode

    def blow_up(u):
        raise DivergenceError("simulation diverged")

    monkeypatch.setattr(env.unwrapped.twin, "step_checked", blow_up)
    *_, terminated, truncated, info = env.step(trim)
    assert terminated and not truncated and "diverged" in info
    with pytest.raises(gymnasium.error.ResetNeeded, match="after the episode ended"):
        env.step(trim)


def test_bad_seeds_and_unknown_reset_options_are_refused_before_anything_changes():
    env = gymnasium.make("trms/HoverGusts-v0")
    first, _ = env.reset(seed=2)
    after = env.step(np.array([0.3, 0.3]))[0]
    with pytest.raises(gymnasium.error.Error, match=r"reset seed = -1 \(int\); allowed: None or a whole number >= 0"):
        env.reset(seed=-1)
    with pytest.raises(gymnasium.error.Error, match=r"reset seed = 1.5 \(float\)"):
        env.reset(seed=1.5)
    with pytest.raises(InputError, match=r"^unknown reset option 'foo'; allowed keys: none"):
        env.reset(options={"foo": 1})
    with pytest.raises(InputError, match="reset options must be a dict or None, got str"):
        env.reset(options="foo")
    assert env.unwrapped.twin.time == 0.1  # the episode runs on where it was
    again, _ = env.reset(seed=2, options={})
    assert np.array_equal(first, again) and np.array_equal(env.step(np.array([0.3, 0.3]))[0], after)


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
    from trms.worlds import GUST

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


def test_task_runner_refuses_bad_seeds_and_steps_without_an_episode():
    with pytest.raises(InputError, match="seed must be a non-negative integer, got -1"):
        TaskRunner("PitchTracking", seed=-1)
    runner = TaskRunner("PitchTracking")
    with pytest.raises(InputError, match="seed must be a non-negative integer or None, got 1.5"):
        runner.reset(1.5)
    with pytest.raises(InputError, match=r"no episode is running .* call reset\(\) before step\(\)"):
        runner.step(runner.twin.operating_point.inputs)
    runner.reset(0)
    with pytest.raises(InputError, match=r"action \(u1\) in V must be finite"):
        runner.step([np.inf])
    assert runner.twin.time == 0.0


def test_dm_env_steps_before_reset_as_a_reset_and_refuses_bad_actions_in_one_line():
    env = load("HoverGusts", {"random": 3})
    first = env.step(np.array([5.0, 5.0]))  # no episode yet: dm_env starts one, ignoring the action
    assert first.step_type == dm_env.StepType.FIRST and env.twin.time == 0.0
    expected = env.step(np.array([0.2, 0.2]))
    env = load("HoverGusts", {"random": 3})
    assert env.reset().step_type == dm_env.StepType.FIRST
    for action, message in BAD_ACTIONS:
        with pytest.raises(InputError, match=message) as err:
            env.step(action)
        assert "\n" not in str(err.value)
    ts = env.step(np.array([0.2, 0.2]))
    assert ts.step_type == dm_env.StepType.MID and ts.reward == expected.reward
    assert all(np.array_equal(ts.observation[k], expected.observation[k]) for k in ts.observation)


def test_dm_env_physics_is_the_live_twin_and_renders_its_pose():
    env = load("PitchTracking", {"random": 0})
    reference = load("PitchTracking", {"random": 0})
    env.reset()
    reference.reset()
    physics = env.physics  # built mid-episode: the simulation must go on exactly as without it
    assert physics is env.physics and physics.model.ptr is env.twin.model and physics.data.ptr is env.twin.data
    for volts in (9.0, 9.0, 9.0, -2.0):
        a, b = env.step(np.array([volts])), reference.step(np.array([volts]))
        assert np.array_equal(a.observation["angles"], b.observation["angles"])
    assert np.array_equal(physics.named.data.qpos["pitch"], env.twin.data.qpos[env.twin.output_qpos])
    frame = physics.render(72, 96, camera_id="front")
    with TwinRenderer(env.twin.model, 96, 72) as r:
        same = r.frame(data=env.twin.data).astype(int)
        flat = r.frame(env.twin.trim.qpos).astype(int)
    assert frame.shape == (72, 96, 3) and frame.dtype == np.uint8
    assert np.mean(np.abs(frame - same)) < 1.0  # the pose the twin is in ...
    assert np.mean(np.abs(frame - flat)) > 3 * max(np.mean(np.abs(frame - same)), 0.1)  # ... not the trim's
    env.close()
    env.close()  # idempotent


class PitchTrackingConformance(test_utils.EnvironmentTestMixin, unittest.TestCase):
    def make_object_under_test(self):
        return load("PitchTracking", {"random": 0})


class HoverGustsConformance(test_utils.EnvironmentTestMixin, unittest.TestCase):
    def make_object_under_test(self):
        return load("HoverGusts", {"random": 0})


class AttitudeTrackingConformance(test_utils.EnvironmentTestMixin, unittest.TestCase):
    def make_object_under_test(self):
        return load("AttitudeTracking", {"random": 0})


def test_the_reward_is_dm_controls_gaussian_tolerance_bit_for_bit():
    from dm_control.utils import rewards

    from trms.envs.tasks import gaussian_tolerance

    rng = np.random.default_rng(0)
    for task in TASKS.values():
        bounds, margin = task.tolerance
        edges = [bounds, -bounds, np.nextafter(bounds, 1.0), np.nextafter(-bounds, -1.0), 0.0, -0.0]
        err = np.concatenate([rng.normal(0.0, 0.3, 20000), edges]).reshape(-1, 2)
        expected = rewards.tolerance(err, (-bounds, bounds), margin, "gaussian")
        assert gaussian_tolerance(err, bounds, margin).tobytes() == expected.tobytes()
        per_step = [task.reward(e, np.zeros(2)) for e in err[:500]]
        assert np.array(per_step).tobytes() == np.prod(expected[:500], axis=1).tobytes()
        assert task.reward(err, np.zeros(2)).tobytes() == np.prod(expected, axis=1).tobytes()


def test_one_steps_reward_on_floats_is_the_arrays_bit_for_bit():
    rng = np.random.default_rng(3)
    for task in TASKS.values():
        bounds, margin = task.tolerance
        err = np.concatenate([rng.normal(0.0, 0.3, 4000), [bounds, -bounds, 0.0, -0.0]]).reshape(-1, 2)
        on_floats = [task.step_reward(e.tolist()) for e in err]
        assert np.array(on_floats).tobytes() == task.reward(err, np.zeros(2)).tobytes()


def test_clipped_is_numpys_clip_nan_and_edges_included():
    from trms.envs.tasks import clipped

    rng = np.random.default_rng(4)
    values = np.concatenate([rng.normal(0.0, 3.0, 997), [np.nan, 1.0, -1.0]])
    low, high = np.full(values.size, -1.0), np.full(values.size, 1.0)
    got = clipped(values.tolist(), low.tolist(), high.tolist())
    assert got.tobytes() == np.clip(values, low, high).tobytes()
    # signed zeros at the bounds, and NaN bounds
    values, low, high = (
        [-0.0, 0.0, -0.0, 0.0, 0.5, 0.5],
        [0.0, -0.0, -1.0, -1.0, np.nan, 0.0],
        [1.0, 1.0, 0.0, -0.0, 1.0, np.nan],
    )
    expected = np.clip(np.array(values), np.array(low), np.array(high))
    assert clipped(values, low, high).tobytes() == expected.tobytes()
    with pytest.raises(ValueError):
        clipped([1.0, 2.0], [0.0], [0.5])


def test_the_twins_readings_on_floats_are_its_arrays():
    runner = TaskRunner("AttitudeTracking")
    runner.reset(seed=2)
    for _ in range(5):
        runner.step_volts(runner.twin.operating_point.inputs + 1.0)
        arrays, floats = runner.twin.readings(), runner.twin.reading_values()
        assert [a.tobytes() for a in arrays] == [np.array(f).tobytes() for f in floats]
        assert arrays[0].tolist() == runner.twin.data.qpos[runner.twin.output_qpos].tolist()


def test_an_observation_of_parts_that_do_not_fit_its_bounds_is_refused():
    runner = TaskRunner("AttitudeTracking")
    runner.reset(seed=1)
    task, twin = runner.task, runner.twin
    measured = twin.encoder.measure(twin.data.qpos[twin.output_qpos], np.random.default_rng(0))
    assert task.observation(twin, measured, np.zeros(2)).shape == (8,)
    with pytest.raises(ValueError):
        task.observation(twin, measured, np.zeros(1))  # one reference short of the bounds
    with pytest.raises(ValueError):
        task.observation(twin, measured, np.zeros((2, 2)))  # not a vector
