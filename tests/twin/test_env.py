"""dm_control environments, checked with dm_env's own conformance mixin."""

import unittest

import numpy as np
from dm_env import test_utils

from trms.twin.env import hover, pitch_tracking


class PitchTrackingConformance(test_utils.EnvironmentTestMixin, unittest.TestCase):
    def make_object_under_test(self):
        return pitch_tracking(time_limit=2.0, random=0)


class HoverConformance(test_utils.EnvironmentTestMixin, unittest.TestCase):
    def make_object_under_test(self):
        return hover(time_limit=2.0, random=0)


def test_hover_at_trim_is_rewarded_and_episodes_are_seeded():
    env = hover(time_limit=1.0, random=3)
    trim = env.task.twin.operating_point.inputs
    ts = env.reset()
    first = ts.observation["angles"].copy()
    rewards = []
    while not ts.last():
        ts = env.step(trim)
        rewards.append(ts.reward)
    assert len(rewards) == 10  # 1 s at 0.1 s
    again = hover(time_limit=1.0, random=3).reset().observation["angles"]
    assert np.array_equal(first, again)


def test_pitch_tracking_reward_peaks_at_the_target():
    env = pitch_tracking(time_limit=2.0, random=1)
    env.reset()
    target = env.task.target
    with env.physics.reset_context():
        env.physics.named.data.qpos["pitch"] = target
    assert env.task.get_reward(env.physics) == 1.0
    with env.physics.reset_context():
        env.physics.named.data.qpos["pitch"] = target + 0.5
    assert env.task.get_reward(env.physics) < 0.1
