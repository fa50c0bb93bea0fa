"""MIMO ARX and ARMAX (diagonal C) on known 2x2 systems."""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest
import scipy.signal

from trms.errors import InputError
from trms.identification import Dataset, MimoPolynomialModel, armax_mimo, arx_mimo
from trms.identification.data import detrend
from trms.record import Record

TS = 0.1
#: The 2x2 ARMAX truth, one equation per output with both inputs (nb = [[2, 1], [1, 2]], nk = 1, nc = 1):
#: A1 y1 = (1 + 0.5 q^-1) q^-1 u1 + 0.3 q^-1 u2 + (1 + 0.5 q^-1) e1,  A1 = 1 - 1.2 q^-1 + 0.5 q^-2
#: A2 y2 = 0.4 q^-1 u1 + (0.8 - 0.2 q^-1) q^-1 u2 + (1 - 0.4 q^-1) e2,  A2 = 1 - 0.6 q^-1 + 0.2 q^-2
TRUE_ROWS = (
    np.array([-1.2, 0.5, 1.0, 0.5, 0.3, 0.5]),
    np.array([-0.6, 0.2, 0.4, 0.8, -0.2, -0.4]),
)
NA, NB = np.diag([2, 2]), np.array([[2, 1], [1, 2]])
NOISE = 0.1


@cache
def _armax_data(seed: int, n: int = 2000) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    u = np.repeat(np.sign(rng.standard_normal((n // 2 + 1, 2))), 2, axis=0)[:n]
    e = NOISE * rng.standard_normal((n, 2))
    a1, a2 = [1, -1.2, 0.5], [1, -0.6, 0.2]
    lf = scipy.signal.lfilter
    y1 = lf([0, 1.0, 0.5], a1, u[:, 0]) + lf([0, 0.3], a1, u[:, 1]) + lf([1, 0.5], a1, e[:, 0])
    y2 = lf([0, 0.4], a2, u[:, 0]) + lf([0, 0.8, -0.2], a2, u[:, 1]) + lf([1, -0.4], a2, e[:, 1])
    return np.column_stack([y1, y2]), u


def test_armax_mimo_recovers_the_2x2_truth_within_its_standard_errors():
    y, u = _armax_data(0)
    model = armax_mimo(y, u, NA, NB, 1, 1, sample_time=TS)
    assert isinstance(model, MimoPolynomialModel) and model.method == "armax-mimo"
    for theta, cov, truth in zip(model.parameters, model.covariances, TRUE_ROWS):
        se = np.sqrt(np.diag(cov))
        assert np.all(np.abs(theta - truth) < 4 * se), (theta, truth, se)
        assert np.all(se < 0.03)
    np.testing.assert_allclose(model.noise_covariance, NOISE**2 * np.eye(2), atol=0.1 * NOISE**2)
    assert model.loss == pytest.approx(np.linalg.det(model.noise_covariance))
    np.testing.assert_allclose(model.C, [[1.0, 0.5], [1.0, -0.4]], atol=0.05)
    # ARX of the same orders is biased by the coloured noise; ARMAX predicts better
    arx = arx_mimo(y, u, NA, NB, 1, sample_time=TS)
    assert model.loss < 0.97 * arx.loss
    # the free run on fresh noise-free data follows the truth
    yv, uv = _armax_data(1, 600)
    clean = _armax_data_noise_free(uv)
    assert np.all(model.fit(clean, uv) > 97.0)
    assert np.all(model.fit(yv, uv) > 80.0)


def _armax_data_noise_free(u: np.ndarray) -> np.ndarray:
    a1, a2 = [1, -1.2, 0.5], [1, -0.6, 0.2]
    lf = scipy.signal.lfilter
    y1 = lf([0, 1.0, 0.5], a1, u[:, 0]) + lf([0, 0.3], a1, u[:, 1])
    y2 = lf([0, 0.4], a2, u[:, 0]) + lf([0, 0.8, -0.2], a2, u[:, 1])
    return np.column_stack([y1, y2])


def test_arx_mimo_is_exact_on_noise_free_data_with_cross_coupled_outputs():
    rng = np.random.default_rng(2)
    n = 300
    u = np.sign(rng.standard_normal((n, 2)))
    y = np.zeros((n, 2))
    a1 = np.array([[-0.5, 0.2], [0.1, -0.3]])  # A(q) = I + A1 q^-1 (full: y2's past enters y1's equation)
    b1 = np.array([[1.0, 0.0], [0.5, 2.0]])
    for t in range(1, n):
        y[t] = -a1 @ y[t - 1] + b1 @ u[t - 1]
    model = arx_mimo(y, u, 1, 1, 1, sample_time=TS)
    np.testing.assert_allclose(model.A[:, :, 1], a1, atol=1e-10)
    np.testing.assert_allclose(model.B[:, :, 1], b1, atol=1e-10)
    np.testing.assert_allclose(model.simulate(u), y, atol=1e-9)
    assert model.to_ss().nstates == 4 and model.loss < 1e-25


def test_a_dataset_and_a_record_are_fitted_as_the_arrays():
    y, u = _armax_data(0)
    whole = armax_mimo(y, u, NA, NB, 1, 1, sample_time=TS)
    two = armax_mimo(Dataset([y[:1000], y[1000:]], [u[:1000], u[1000:]], TS), None, NA, NB, 1, 1)
    assert two.info["experiments"] == 2 and two.n_samples == whole.n_samples - 2
    for a, b in zip(two.parameters, whole.parameters):
        np.testing.assert_allclose(a, b, atol=0.02)
    rec = detrend(Record(np.arange(y.shape[0]) * TS, u, y, ("u1", "u2"), ("pitch", "yaw")))
    from_record = arx_mimo(rec, None, NA, NB, 1)
    assert from_record.output_names == ("pitch", "yaw") and from_record.input_names == ("u1", "u2")


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"na": np.ones((2, 3), int)}, r"na must be an int or an array of shape \(2, 2\).*got shape \(2, 3\)"),
        ({"nb": np.array([[2, -1], [1, 2]])}, r"nb\[0, 1\] = -1 is outside the allowed range \[0"),
        ({"nc": -1}, r"nc = -1 is outside the allowed range \[0"),
        ({"nk": 1.5}, r"nk must be an int, got 1.5"),
        ({"nb": np.array([[0, 0], [1, 2]])}, r"every output's equation needs an input coefficient"),
        ({"max_iter": 0}, r"max_iter = 0 is outside the allowed range \[1"),
    ],
)
def test_bad_input_is_refused_with_one_line(kwargs, match):
    y, u = _armax_data(0)
    with pytest.raises(InputError, match=match):
        armax_mimo(y, u, sample_time=TS, **kwargs)


def test_too_short_data_are_refused():
    y, u = _armax_data(0)
    with pytest.raises(InputError, match=r"output 1 \(10 parameters, .*\) need at least \d+ samples.*have 12"):
        arx_mimo(y[:12], u[:12], 2, 3, 1, sample_time=TS)
