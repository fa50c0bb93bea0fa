"""The Gymnasium environments' constructor and actions: bad values are one clear line."""

import gymnasium
import numpy as np
import pytest

import trms.envs.gym  # noqa: F401  (registers the environments)
from trms.envs.gym import InvalidActionError
from trms.errors import InputError


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"width": "abc"}, r"width = 'abc' must be a whole number of pixels \(int\)"),
        ({"height": 2.5}, r"height = 2\.5 must be a whole number of pixels \(int\)"),
        ({"width": True}, r"width = True must be a whole number of pixels"),
    ],
)
def test_an_image_size_that_is_not_an_int_is_refused(kwargs, match):
    with pytest.raises(InputError, match=match):
        gymnasium.make("trms/PitchTracking-v0", render_mode="rgb_array", **kwargs)


def test_an_int_image_size_renders_that_size():
    env = gymnasium.make("trms/PitchTracking-v0", render_mode="rgb_array", width=np.int64(64), height=48)
    env.reset(seed=0)
    assert env.render().shape == (48, 64, 3)


@pytest.mark.parametrize("action", [None, [None]])
def test_none_is_not_a_voltage_and_changes_nothing(action):
    env = gymnasium.make("trms/PitchTracking-v0")
    env.reset(seed=0)
    before = env.unwrapped.twin.time
    with pytest.raises(InvalidActionError, match=r"action \(u1\) in V: None is not a voltage"):
        env.step(action)
    assert env.unwrapped.twin.time == before


@pytest.mark.parametrize("seed", [-1, 1.5, "a", True])
def test_a_bad_reset_seed_is_one_line_naming_it_and_changes_nothing(seed):
    from trms.envs.gym import InvalidSeedError

    env = gymnasium.make("trms/PitchTracking-v0")
    env.reset(seed=0)
    before = env.unwrapped.twin.time
    env.step(env.action_space.sample() * 0.0)
    with pytest.raises(InvalidSeedError, match=r"reset seed = .*; allowed: None or a whole number >= 0") as err:
        env.reset(seed=seed)
    assert isinstance(err.value, gymnasium.error.Error) and "\n" not in str(err.value)
    assert env.unwrapped.twin.time > before  # the running episode is untouched
    assert env.reset(seed=np.int64(3))[0].shape == env.reset(seed=3)[0].shape  # a numpy integer is a seed


def test_human_rendering_without_pygame_is_refused_when_the_environment_is_made(monkeypatch):
    import importlib.util

    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: None if name == "pygame" else real(name, *a))
    with pytest.raises(InputError, match=r"render_mode='human' shows the frames in a window with pygame, which is not"):
        gymnasium.make("trms/PitchTracking-v0", render_mode="human")
    with pytest.raises(InputError, match=r"render_mode='human' needs a window"):
        trms.envs.gym.TwinTaskEnv("PitchTracking", render_mode="human")
