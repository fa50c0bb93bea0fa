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
