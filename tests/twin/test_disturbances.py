"""The Ornstein-Uhlenbeck disturbances drawn a record at a time: the same draws and bits as one interval at a time."""

import numpy as np
import pytest

from trms.twin import Gust
from trms.twin.disturbances import Turbulence, ou_advance, ou_path


@pytest.mark.parametrize("std", [0.004, (0.003, 0.001), (0.0, 0.002), np.array([0.001, 0.003])])
def test_a_path_is_its_steps_bit_for_bit(std):
    step_rng, path_rng = np.random.default_rng(7), np.random.default_rng(7)
    x = np.array([0.1, -0.3])
    steps = [x]
    for _ in range(300):
        x = ou_advance(x, std, 0.8, 0.2, step_rng)
        steps.append(x)
    path = ou_path(steps[0], std, 0.8, 0.2, path_rng, 300)
    assert np.stack(steps).tobytes() == path.tobytes()
    assert step_rng.standard_normal() == path_rng.standard_normal()  # the generators stand at the same draw


def test_switched_off_processes_draw_nothing():
    rng = np.random.default_rng(0)
    assert not Turbulence().path(np.zeros(2), 0.1, rng, 5).any()
    assert not Gust().path(np.zeros(2), 0.1, rng, 5).any()
    assert rng.standard_normal() == np.random.default_rng(0).standard_normal()
    assert ou_path(np.zeros(2), 1.0, 1.0, 0.1, rng, 0).shape == (1, 2)


def test_gusts_and_turbulence_paths_are_their_advances():
    for process, start in ((Gust(0.002, 1.5), np.array([0.001, -0.002])), (Turbulence((0.01, 0.02), 0.7), np.ones(2))):
        a, b = np.random.default_rng(3), np.random.default_rng(3)
        x = start
        for _ in range(40):
            x = process.advance(x, 0.05, a)
        assert process.path(start, 0.05, b, 40)[-1].tobytes() == x.tobytes()


@pytest.mark.parametrize("block", [1, 3, 256])
def test_normals_drawn_a_block_at_a_time_are_the_generators_in_order(block):
    from trms.twin.disturbances import NormalDraws

    plain, drawn = np.random.default_rng(11), NormalDraws(np.random.default_rng(11), block=block)
    for shape in [2, (2,), (5, 2), 1, (300,), (3,), (7, 3)]:  # across block boundaries and larger than a block
        assert plain.standard_normal(shape).tobytes() == drawn.standard_normal(shape).tobytes()
