"""Recursive ARX / ARMAX (RLS, RELS) on known truth: batch equivalence, tracking, convergence, bad input."""

from __future__ import annotations

import doctest

import numpy as np
import pytest
import scipy.signal

import trms.identification.recursive as recursive_module
from trms.errors import InputError
from trms.identification.dataset import Dataset
from trms.identification.linear import armax, arx
from trms.identification.recursive import RecursiveEstimator, recursive_armax, recursive_arx
from trms.record import Record

TS = 0.2

#: A known second-order ARMAX system (the RELS convergence check): 1/C - 1/2 is strictly positive real.
A2, B2, C2 = np.array([1.0, -1.5, 0.7]), np.array([0.0, 1.0, 0.5]), np.array([1.0, -0.7, 0.2])


def armax2_data(n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    u, e = np.sign(rng.standard_normal(n)), 0.3 * rng.standard_normal(n)
    return scipy.signal.lfilter(B2, A2, u) + scipy.signal.lfilter(C2, A2, e), u


def test_recursive_arx_with_no_forgetting_ends_at_batch_arx(truth):
    y, u = truth.data(1000, 0)
    batch = arx(y, u, 4, 4, 1, sample_time=TS)
    # P(0) = 1e8 I: the regularisation I / p0 moves the estimate by ~1e-7 (measured 2.9e-7)
    res = recursive_arx(y, u, 4, 4, 1, sample_time=TS, initial_covariance=1e8)
    assert res.trajectory.shape == (1000, 8)
    np.testing.assert_allclose(res.model.parameters, batch.parameters, rtol=0, atol=1e-6)
    np.testing.assert_allclose(res.trajectory[-1], res.model.parameters)
    # before start = 4 nothing is updated; noise variance and covariance are the least-squares ones
    np.testing.assert_array_equal(res.trajectory[:4], 0.0)
    np.testing.assert_allclose(res.model.std_errors, batch.std_errors, rtol=1e-5)
    assert res.model.noise_variance == pytest.approx(batch.noise_variance, rel=1e-5)
    # the default p0 = 1e4 regularises visibly more (measured 2.9e-3), so the 1e-6 above is not automatic
    default = recursive_arx(y, u, 4, 4, 1, sample_time=TS)
    assert np.max(np.abs(default.model.parameters - batch.parameters)) > 1e-4
    assert default.model.method == "recursive-arx" and default.model.info["forgetting"] == 1.0


@pytest.mark.parametrize("nc", [0, 2])
def test_the_online_estimator_reproduces_the_batch_trajectory(nc):
    y, u = armax2_data(600, 3)
    batch = recursive_armax(y, u, 2, 2, nc, 1, sample_time=0.1, forgetting=0.99)
    est = RecursiveEstimator(2, 2, nc, 1, sample_time=0.1, forgetting=0.99)
    online = np.array([est.update(yt, ut) for yt, ut in zip(y, u)])
    np.testing.assert_allclose(online, batch.trajectory, rtol=0, atol=1e-12)
    np.testing.assert_allclose(est.covariance, batch.covariance, rtol=1e-10, atol=1e-14)
    assert est.prediction_error == pytest.approx(batch.prediction_errors[-1], abs=1e-12)
    model = est.model()
    np.testing.assert_allclose(model.parameters, batch.model.parameters, atol=1e-12)
    assert model.noise_variance == pytest.approx(batch.model.noise_variance, rel=1e-10)
    assert est.n_samples == 600


def test_zero_input_delay_uses_the_current_input():
    rng = np.random.default_rng(4)
    u = np.sign(rng.standard_normal(300))
    y = scipy.signal.lfilter([0.7, 0.2], [1.0, -0.5], u)
    res = recursive_arx(y, u, 1, 2, 0, sample_time=0.1, initial_covariance=1e10)
    np.testing.assert_allclose(res.model.parameters, [-0.5, 0.7, 0.2], atol=1e-6)
    est = RecursiveEstimator(1, 2, 0, 0, sample_time=0.1, initial_covariance=1e10)
    for yt, ut in zip(y, u):
        theta = est.update(yt, ut)
    np.testing.assert_allclose(theta, res.model.parameters, atol=1e-12)


def jump_data(seed: int, n: int = 1000) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """y(t) = 0.8 y(t-1) + b(t) u(t-1) + e(t) with b jumping from 0.5 to 1.0 at sample n / 2."""
    rng = np.random.default_rng(seed)
    u, e = np.sign(rng.standard_normal(n)), 0.05 * rng.standard_normal(n)
    b = np.where(np.arange(n) < n // 2, 0.5, 1.0)
    # the time-varying system by lfilter on the input term b(t) u(t-1)
    drive = np.concatenate([[0.0], b[1:] * u[:-1]]) + e
    return scipy.signal.lfilter([1.0], [1.0, -0.8], drive), u, b


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_forgetting_tracks_a_parameter_that_jumps_halfway(seed):
    # lambda = 0.98 remembers ~1 / (1 - lambda) = 50 samples. Stated: within 150 samples (3 memory
    # lengths) of the jump, b1 stays within 0.05 of its new value (50 seeds: at most 131, median 115).
    y, u, b = jump_data(seed)
    res = recursive_arx(y, u, 1, 1, 1, sample_time=0.1, forgetting=0.98)
    err = np.abs(res.trajectory[:, 1] - b)
    assert np.all(err[100:500] < 0.05)
    assert np.all(err[650:] < 0.05)
    assert np.all(np.abs(res.trajectory[650:, 0] + 0.8) < 0.05)
    # without forgetting the estimate averages the two halves: still far from 1.0 after 150 samples
    stiff = recursive_arx(y, u, 1, 1, 1, sample_time=0.1)
    assert abs(stiff.trajectory[650, 1] - 1.0) > 0.3


@pytest.mark.parametrize("seed", range(5))
def test_rels_armax_converges_to_the_truth_within_three_batch_standard_errors(seed):
    # 5000 samples of a known ARMAX(2, 2, 2); RELS is consistent but less efficient than PEM
    # (over 40 seeds its largest |z| against batch armax's standard errors has median 1.8, max 3.1).
    y, u = armax2_data(5000, seed)
    batch = armax(y, u, 2, 2, 2, 1, sample_time=0.1)
    res = recursive_armax(y, u, 2, 2, 2, 1, sample_time=0.1)
    truth = np.concatenate([A2[1:], B2[1:], C2[1:]])
    z = (res.model.parameters - truth) / batch.std_errors
    assert np.all(np.abs(z) < 3.0), z
    assert res.model.method == "recursive-armax" and res.model.orders == (2, 2, 2, 1)
    # the innovations variance is that of the noise, 0.3^2
    assert res.model.noise_variance == pytest.approx(0.09, rel=0.1)


def test_rels_without_its_noise_model_is_biased():
    # the same data by recursive ARX: the coloured equation error biases a1, a2 far beyond 3 standard errors
    y, u = armax2_data(5000, 0)
    batch = armax(y, u, 2, 2, 2, 1, sample_time=0.1)
    res = recursive_arx(y, u, 2, 2, 1, sample_time=0.1)
    z = (res.model.parameters[:2] - A2[1:]) / batch.std_errors[:2]
    assert np.max(np.abs(z)) > 10.0


def test_records_and_datasets_are_taken_as_the_batch_estimators_take_them():
    y, u = armax2_data(300, 5)
    trim_u, trim_y = 2.0, -0.4
    record = Record(
        np.arange(300) * 0.1,
        (u + trim_u)[:, None],
        (y + trim_y)[:, None],
        ("u1",),
        ("pitch",),
        metadata={
            "sample_time": 0.1,
            "operating_point": {
                "inputs": [trim_u],
                "outputs": [trim_y],
                "input_names": ["u1"],
                "output_names": ["pitch"],
            },
        },
    )
    from_arrays = recursive_arx(y, u, 2, 2, 1, sample_time=0.1)
    from_record = recursive_arx(record, na=2, nb=2, nk=1)
    np.testing.assert_allclose(from_record.trajectory, from_arrays.trajectory, atol=1e-9)
    assert (from_record.model.input_name, from_record.model.output_name) == ("u1", "pitch")
    one = recursive_armax(Dataset([y], [u], 0.1), na=2, nb=2, nc=1)
    np.testing.assert_allclose(one.trajectory, recursive_armax(y, u, 2, 2, 1, sample_time=0.1).trajectory)
    with pytest.raises(InputError, match="the dataset has 2 experiments"):
        recursive_arx(Dataset([y, y], [u, u], 0.1), na=2, nb=2)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"forgetting": 0.0}, r"forgetting = 0.0 is outside the allowed range \(0.0, 1.0\]"),
        ({"forgetting": 1.01}, r"forgetting = 1.01 is outside the allowed range \(0.0, 1.0\]"),
        ({"initial_covariance": -1.0}, r"initial_covariance = -1.0 is outside the allowed range \(0.0, inf\]"),
        ({"initial_parameters": [0.0, 1.0]}, r"initial_parameters must have shape \(4,\), got shape \(2,\)"),
        ({"na": 2.0}, r"na must be an int, got 2.0"),
        ({"nb": 0}, r"nb = 0 is outside the allowed range \[1, inf\]"),
    ],
)
def test_bad_settings_get_one_clear_line(kwargs, message):
    y, u = armax2_data(50, 0)
    args = {"na": 2, "nb": 2, "nk": 1, **kwargs}
    with pytest.raises(InputError, match=message):
        recursive_arx(y, u, sample_time=0.1, **args)
    with pytest.raises(InputError, match=message):
        RecursiveEstimator(sample_time=0.1, **args)


def test_bad_data_is_refused_and_a_bad_sample_leaves_the_estimator_unchanged():
    with pytest.raises(InputError, match=r"the data have 3 samples; orders na=4, nb=4, nk=1 need more than 4"):
        recursive_arx(np.zeros(3), np.ones(3), sample_time=0.1)
    with pytest.raises(InputError, match="y must be finite"):
        recursive_arx(np.array([0.0, np.nan, 1.0]), np.ones(3), 1, 1, sample_time=0.1)
    est = RecursiveEstimator(1, 1, 1, sample_time=0.1)
    for yt, ut in [(0.0, 1.0), (0.5, -1.0), (0.1, 1.0)]:
        est.update(yt, ut)
    before = (est.parameters, est.covariance, est.n_samples)
    with pytest.raises(InputError, match=r"y = nan is outside the allowed range"):
        est.update(float("nan"), 1.0)
    with pytest.raises(InputError, match=r"u must be a real number"):
        est.update(0.0, "1")
    np.testing.assert_array_equal(est.parameters, before[0])
    np.testing.assert_array_equal(est.covariance, before[1])
    assert est.n_samples == before[2]
    with pytest.raises(InputError, match=r"sample_time = 0.0 s is outside the allowed range"):
        RecursiveEstimator(1, 1, sample_time=0.0)


def test_examples_run():
    result = doctest.testmod(recursive_module, optionflags=doctest.ELLIPSIS)
    assert result.attempted > 0 and result.failed == 0
