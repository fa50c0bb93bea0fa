"""The sample time and the physics step a twin runs at."""

import numpy as np
import pytest
from scipy.signal import welch

from trms import signals
from trms.errors import ConfigurationError
from trms.twin import Twin, load_spec, physics_timestep


@pytest.mark.parametrize(
    "ts, step",
    [(0.1, 0.002), (0.2, 0.002), (0.002, 0.002), (0.001, 0.001), (0.003, 0.0015), (0.005, 0.005 / 3), (0.007, 0.00175)],
)
def test_the_physics_step_divides_the_sample_time_and_is_never_longer_than_the_files(ts, step):
    got = physics_timestep(ts, 0.002)
    assert got == pytest.approx(step, rel=1e-12) and got <= 0.002
    assert abs(ts / got - round(ts / got)) < 1e-9


@pytest.mark.parametrize("ts", [0.0005, 0.0015, 40.0, float("nan")])
def test_sample_times_off_the_kernels_grid_are_refused_by_name(ts):
    with pytest.raises(ConfigurationError, match="sample_time"):
        physics_timestep(ts, 0.002)


def test_the_files_step_follows_a_finer_one_through_a_thesis_experiment():
    # The 2-DOF PRBS of ch. 3.4 on u1 (2 Hz, 0.05 V, 60 s at 10 Hz), ambient excitation and encoder included, at the
    # file's 2 ms step and at 1 ms: the same seed gives nearly the same record (measured: 0.7 % and 0.1 % of each
    # output's RMS) and the same spectral peaks, bin for bin.
    spec = load_spec()
    finer = load_spec()
    finer.option.timestep = 0.001
    records = []
    for s in (spec, finer):
        twin = Twin("2dof", 0.1, seed=101, spec=s)
        du = signals.random_binary(60.0, 0.1, 2.0, 0.05, seed=101)
        records.append(twin.run(twin.operating_point.with_signal(du, "u1")))
        assert twin.model.opt.timestep == s.option.timestep
    a, b = (r.outputs - r.outputs.mean(axis=0) for r in records)
    assert np.all(np.sqrt(((a - b) ** 2).mean(axis=0)) < 0.05 * a.std(axis=0))
    for k in range(a.shape[1]):
        f, pa = welch(a[:, k], fs=10.0, nperseg=256)
        _, pb = welch(b[:, k], fs=10.0, nperseg=256)
        band = (f > 0.02) & (f < 1.0)
        assert f[band][np.argmax(pa[band])] == f[band][np.argmax(pb[band])]
