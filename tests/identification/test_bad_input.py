"""Bad input across the identification entry points: one clear error, or the right answer."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import scipy.signal

from trms.errors import InputError
from trms.identification import armax, arx, compare, narx_rbf, whiteness_test

TS = 0.2


def _data(n: int = 400, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    u = np.sign(rng.standard_normal(n))
    y = scipy.signal.lfilter([0.0, 0.5, 0.2], [1.0, -1.2, 0.5], u) + 0.01 * rng.standard_normal(n)
    return y, u


@pytest.mark.parametrize(
    "call",
    [
        lambda y, u: arx(y + 1e-3j, u, 2, 2, 1, sample_time=TS),
        lambda y, u: armax(y, u.astype(complex), 2, 2, 1, 1, sample_time=TS),
        lambda y, u: narx_rbf(list(y + 0j), u, 2, 2, 1, sample_time=TS),
        lambda y, u: whiteness_test(y * (1 + 1j)),
    ],
)
def test_complex_arrays_are_refused_with_one_clear_error(call):
    y, u = _data()
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no ComplexWarning on the way: the error comes first
        with pytest.raises(InputError, match=r"must be real numbers .*complex values are not allowed"):
            call(y, u)


def test_non_integer_horizons_and_lags_are_refused_not_truncated():
    y, u = _data()
    model = arx(y, u, 2, 2, 1, sample_time=TS)
    with pytest.raises(InputError, match=r"horizon must be an int, got 2\.5"):
        model.predict(y, u, 2.5)
    with pytest.raises(InputError, match=r"horizon must be an int, got 2\.5"):
        compare(model, y, u, horizon=2.5)
    with pytest.raises(InputError, match=r"max_lag must be an int, got 10\.0"):
        whiteness_test(y, 10.0)
    with pytest.raises(InputError, match=r"nb must be an int, got 2\.0"):
        armax(y, u, 2, 2.0, 1, 1, sample_time=TS)


@pytest.mark.parametrize("estimator", [arx, armax])
def test_a_constant_input_is_refused_also_with_one_input_coefficient(estimator):
    y, _ = _data()
    with pytest.raises(InputError, match=r"input u is constant \(0\.3 throughout\)"):
        estimator(y, np.full(y.size, 0.3), 2, 1, sample_time=TS)


def test_noise_free_data_with_the_correct_orders_give_the_exact_armax_model():
    _, u = _data()
    a, b = np.array([1.0, -1.2, 0.5]), np.array([0.0, 0.5, 0.2])
    y = scipy.signal.lfilter(b, a, u)
    model = armax(y, u, 2, 2, 1, 1, sample_time=TS)
    np.testing.assert_allclose(model.A, a, atol=1e-12)
    np.testing.assert_allclose(model.B, b, atol=1e-12)
    np.testing.assert_array_equal(model.C, [1.0, 0.0])
    assert model.info["noise_free"] and model.covariance.shape == (5, 5)
    # the same orders on noisy data still run the prediction-error search
    noisy = armax(*_data(), 2, 2, 1, 1, sample_time=TS)
    assert "noise_free" not in noisy.info and noisy.info["iterations"] >= 1


@pytest.mark.parametrize("n", [60, 120, 400, 2000])
def test_noise_free_armax_is_exact_at_any_length(n):
    rng = np.random.default_rng(n)
    u = np.sign(rng.standard_normal(n))
    a, b = np.array([1.0, -1.5, 0.7]), np.array([0.0, 1.0, 0.5])
    y = scipy.signal.lfilter(b, a, u)
    model = armax(y, u, 2, 2, 2, 1, sample_time=TS)
    np.testing.assert_allclose(model.A, a, atol=1e-10)
    np.testing.assert_allclose(model.B, b, atol=1e-10)
    np.testing.assert_array_equal(model.C, [1.0, 0.0, 0.0])
