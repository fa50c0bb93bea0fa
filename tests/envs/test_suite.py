"""The dm_env suite's loader: bad task arguments are one clear line, a good seed runs its episode."""

import numpy as np
import pytest

from trms.envs.suite import load
from trms.errors import InputError


@pytest.mark.parametrize(
    "task_kwargs, match",
    [
        ({"foo": 1}, r"unknown task_kwargs key 'foo'; allowed: 'random'"),
        ({"random": "x"}, r"random must be a non-negative integer or None, got 'x'"),
        ({"random": np.random.RandomState(0)}, r"random must be a non-negative integer or None, got RandomState"),
        ({"random": 1.5}, r"random must be a non-negative integer or None, got 1\.5"),
        ({"random": -1}, r"random must be a non-negative integer or None, got -1"),
        ([1, 2], r"task_kwargs = \[1, 2\] must be a dict such as \{'random': 0\}, or None"),
    ],
)
def test_bad_task_kwargs_are_refused_in_one_line(task_kwargs, match):
    with pytest.raises(InputError, match=match) as exc:
        load("PitchTracking", task_kwargs)
    assert "\n" not in str(exc.value)


@pytest.mark.parametrize("task_kwargs", [None, {}, {"random": None}, {"random": 0}, {"random": np.int64(0)}])
def test_the_default_seed_is_zero_in_every_spelling(task_kwargs):
    first = load("PitchTracking", task_kwargs).reset().observation["reference"]
    assert np.array_equal(first, load("PitchTracking", {"random": 0}).reset().observation["reference"])
    assert not np.array_equal(first, load("PitchTracking", {"random": 1}).reset().observation["reference"])


@pytest.mark.parametrize("task, axes", [("PitchTracking", ("pitch",)), ("AttitudeTracking", ("pitch", "yaw"))])
def test_physics_is_a_dm_control_physics_that_reads_the_twins_angles_after_steps(task, axes):
    from dm_control.mujoco import Physics  # imported once the physics chose its OpenGL backend (trms.twin.render)

    env = load(task, {"random": 0})
    env.reset()
    physics = env.physics
    assert isinstance(physics, Physics) and physics is env.physics
    data_ptr = physics.data.ptr
    volts = np.array([9.0, -3.0])[: env.action_spec().shape[0]]
    for _ in range(2):
        for _step in range(6):
            env.step(volts)
        angles = env.twin.channels()["true_angles"]
        for i, axis in enumerate(axes):
            assert physics.named.data.qpos[axis][0] == angles[i]
        assert physics.named.data.qpos["pitch"][0] != 0.0  # the steps moved the beam
        assert physics.data.time == env.twin.data.time == pytest.approx(6 * env.twin.sample_time)
        env.reset()  # a new episode keeps the same data, as dm_control's viewer expects of a reset
        assert physics.data.ptr is data_ptr and env.physics is physics
    env.close()
