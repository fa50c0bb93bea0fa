"""Batch runs with mujoco.rollout reproduce Twin.run bit for bit, for many parameter sets at once."""

import numpy as np
import pytest

from trms.batch.rollouts import run_open_loop_batch
from trms.errors import InputError
from trms.twin import Gust, Twin, load_spec
from trms.twin.parameters import with_parameters


def test_batch_equals_serial_runs_with_different_parameters():
    spec = load_spec()
    specs = [with_parameters(spec, {"counterweight_mass": m}) for m in (0.06, 0.08, 0.1)]
    twins = [Twin("2dof", 0.1, seed=i, spec=s, noise_std=5e-4) for i, s in enumerate(specs)]
    rng = np.random.default_rng(0)
    u = twins[0].operating_point.inputs + rng.uniform(-0.2, 0.2, (3, 150, 2))
    u[1, 10, 0] = 25.0  # saturates, as in Twin.step
    out = run_open_loop_batch(twins, u, threads=2)
    for b, twin in enumerate(twins):
        rec = twin.run(u[b])
        assert np.array_equal(out[b], rec.outputs)
    assert not np.array_equal(out[0], out[2])


def test_batch_runs_each_twin_with_its_own_gusts():
    twins = [Twin("2dof", 0.1, seed=s, gust=Gust(0.0006, 1.0)) for s in (3, 4)]
    u = np.broadcast_to(twins[0].operating_point.inputs, (2, 200, 2))
    out = run_open_loop_batch(twins, u, threads=2)
    calm = Twin("2dof", 0.1, seed=3).run(u[0]).outputs
    for b, twin in enumerate(twins):
        assert np.array_equal(out[b], twin.run(u[b]).outputs)
    assert not np.array_equal(out[0], out[1]) and not np.array_equal(out[0], calm)


def test_batch_refuses_mixed_twins():
    a, b = Twin("1dof", 0.1), Twin("2dof", 0.1)
    with pytest.raises(InputError, match="share one configuration"):
        run_open_loop_batch([a, b], np.zeros((10, 1)))
    with pytest.raises(InputError, match="shape"):
        run_open_loop_batch([a], np.zeros((10, 2)))
