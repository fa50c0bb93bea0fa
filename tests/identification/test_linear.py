"""ARX and ARMAX (PEM) on known truth: eq. (3.11) with coloured noise, and bad input."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.signal
import scipy.stats

from trms.errors import EstimationError, InputError
from trms.identification.linear import armax, arx
from trms.record import Record
from trms.reference import EQ_3_11_DEN, EQ_3_11_NUM
from trms.signals import random_binary

TS = 0.2
TRUE_A = np.array(EQ_3_11_DEN)
TRUE_B = np.array([0.0, *EQ_3_11_NUM])
TRUTH_AB = np.concatenate([TRUE_A[1:], TRUE_B[1:]])
# A chi-square test at the 99.9 % level: a correct estimator with a correct covariance
# fails it once in a thousand seeds.
CHI2_8 = scipy.stats.chi2.ppf(0.999, 8)


def mahalanobis(estimate: np.ndarray, truth: np.ndarray, cov: np.ndarray) -> float:
    d = estimate - truth
    return float(d @ np.linalg.solve(cov, d))


@pytest.fixture(scope="module")
def fits(truth):
    out = {}
    for n in (750, 3000):
        y, u = truth.data(n, 1)
        out[n] = (armax(y, u, 4, 4, 2, 1, sample_time=TS), arx(y, u, 4, 4, 1, sample_time=TS))
    return out


def test_armax_recovers_eq_3_11_within_its_own_covariance(fits, truth):
    for n, (model, _) in fits.items():
        assert model.orders == (4, 4, 2, 1)
        cov_ab = model.covariance[:8, :8]
        assert mahalanobis(model.parameters[:8], TRUTH_AB, cov_ab) < CHI2_8, n
        # every single coefficient, C included, within 4 of its own standard errors
        z = (model.parameters - np.concatenate([TRUTH_AB, truth.C[1:]])) / model.std_errors
        assert np.all(np.abs(z) < 4.0), (n, z)
        assert model.info["iterations"] < 50


def test_armax_tolerance_shrinks_as_the_record_grows(fits, truth):
    # 4x the data: standard errors shrink by sqrt(4) = 2 (asymptotic theory); allow 1.6 .. 2.5
    ratio = fits[750][0].std_errors / fits[3000][0].std_errors
    assert np.all((ratio > 1.6) & (ratio < 2.5)), ratio
    # and the estimate's noise variance converges to the true 0.02^2
    assert fits[3000][0].noise_variance == pytest.approx(truth.noise_std**2, rel=0.1)


def test_arx_on_the_same_data_is_measurably_biased(fits):
    # The coloured noise enters the ARX equation error, correlating it with the past outputs:
    # the ARX estimate is inconsistent. Its distance from the truth in its own covariance is
    # far outside the 99.9 % chi-square bound and grows with the record, while ARMAX passes.
    d750 = mahalanobis(fits[750][1].parameters, TRUTH_AB, fits[750][1].covariance)
    d3000 = mahalanobis(fits[3000][1].parameters, TRUTH_AB, fits[3000][1].covariance)
    assert d750 > 2 * CHI2_8
    assert d3000 > 2.5 * d750


def test_arx_is_exact_on_noise_free_arx_data():
    u = random_binary(120.0, TS, 5.0, 1.0, seed=5)
    y = scipy.signal.lfilter(TRUE_B, TRUE_A, u)
    model = arx(y, u, 4, 4, 1, sample_time=TS)
    np.testing.assert_allclose(model.A, TRUE_A, atol=1e-9)
    np.testing.assert_allclose(model.B, TRUE_B, atol=1e-9)
    assert model.loss < 1e-20


def test_a_record_is_used_as_deviations_from_its_operating_point():
    u = random_binary(120.0, TS, 5.0, 1.0, seed=5)
    y = scipy.signal.lfilter(TRUE_B, TRUE_A, u)
    trim_u, trim_y = 4.0, -0.3
    record = Record(
        np.arange(u.size) * TS,
        np.column_stack([u + trim_u, np.zeros_like(u)]),
        y + trim_y,
        ("u1", "u2"),
        ("y1",),
        metadata={
            "sample_time": TS,
            "operating_point": {
                "inputs": [trim_u, 0.0],
                "outputs": [trim_y],
                "input_names": ["u1", "u2"],
                "output_names": ["y1"],
            },
        },
    )
    model = arx(record, na=4, nb=4, nk=1, input="u1")
    np.testing.assert_allclose(model.A, TRUE_A, atol=1e-9)
    assert (model.input_name, model.output_name, model.sample_time) == ("u1", "y1", TS)
    with pytest.raises(InputError, match=r"the record has 2 inputs \(u1, u2\); name the input"):
        arx(record, na=4, nb=4)
    with pytest.raises(InputError, match=r"unknown input 'u3'"):
        arx(record, input="u3")
    with pytest.raises(InputError, match=r"either a Record or the arrays"):
        arx(record, u, input="u1")


@pytest.mark.parametrize(
    "call, error, match",
    [
        (
            lambda y, u: armax(np.r_[y[:-1], np.nan], u, sample_time=TS),
            InputError,
            r"y must be finite; found nan at index \(749,\)",
        ),
        (lambda y, u: armax(y, u[:-5], sample_time=TS), InputError, r"same length, got 750 and 745"),
        (lambda y, u: armax(y, u), InputError, r"sample_time \(s\) is required"),
        (
            lambda y, u: armax(y[:40], u[:40], 8, 8, 8, sample_time=TS),
            InputError,
            r"orders na=8, nb=8, nc=8, nk=1 \(24 parameters, first prediction at sample 8\) need at least 57 samples",
        ),
        (
            lambda y, u: arx(y, np.full_like(u, 2.0), 4, 4, sample_time=TS),
            InputError,
            r"not persistently exciting of order 4 \(it reaches order 1",
        ),
        (lambda y, u: armax(y, np.zeros_like(u), sample_time=TS), InputError, r"identically zero"),
        (
            lambda y, u: armax(y, u, 4, 4, 2, 1, sample_time=TS, max_iter=1),
            EstimationError,
            r"did not converge in max_iter = 1 iterations",
        ),
        (
            lambda y, u: armax(y, u, -1, 4, 2, sample_time=TS),
            InputError,
            r"na = -1 is outside the allowed range \[0, inf\]",
        ),
        (
            lambda y, u: armax(y, u, 4, 0, 2, sample_time=TS),
            InputError,
            r"nb = 0 is outside the allowed range \[1, inf\]",
        ),
        (lambda y, u: armax(y, u, 4.5, 4, 2, sample_time=TS), InputError, r"na must be an int, got 4\.5"),
    ],
)
def test_bad_input_gives_a_clear_error(call, error, match, truth):
    y, u = truth.data(750, 1)
    with pytest.raises(error, match=match):
        call(y, u)


def test_noise_free_data_with_too_high_an_order_is_refused():
    # A 2nd-order system fitted with na = nb = 3 on noise-free data: any common factor fits
    # exactly, so the regressors are singular and the model is not unique.
    u = random_binary(120.0, TS, 5.0, 1.0, seed=6)
    y = scipy.signal.lfilter([0.0, 0.5, 0.2], [1.0, -1.2, 0.5], u)
    with pytest.raises(EstimationError, match=r"linearly dependent"):
        arx(y, u, 3, 3, 1, sample_time=TS)
