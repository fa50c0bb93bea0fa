"""Polynomial NARX by FROLS on known truth: the terms and coefficients of a polynomial system, against the RBF."""

from __future__ import annotations

import numpy as np
import pytest

from trms.errors import EstimationError, InputError
from trms.identification import narx_rbf
from trms.identification.frols import PolynomialNarx, candidate_terms, narx_poly
from trms.identification.validation import billings_voon_tests, fit_percent

TS = 0.1


def _truth(n, seed, noise=0.0):
    """y(t) = 0.5 y(t-1) + 0.3 u(t-1) + 0.2 y(t-1) u(t-1) - 0.1 u(t-2)^2 (+ white noise)."""
    rng = np.random.default_rng(seed)
    u = rng.uniform(-1, 1, n)
    e = noise * rng.standard_normal(n)
    y = np.zeros(n)
    for t in range(2, n):
        y[t] = 0.5 * y[t - 1] + 0.3 * u[t - 1] + 0.2 * y[t - 1] * u[t - 1] - 0.1 * u[t - 2] ** 2 + e[t]
    return y, u


TRUE = {"y(t-1)": 0.5, "u(t-1)": 0.3, "y(t-1) u(t-1)": 0.2, "u(t-2) u(t-2)": -0.1}


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_the_polynomial_truth_is_recovered_term_for_term_in_noise(seed):
    y, u = _truth(1500, seed, noise=0.02)
    model = narx_poly(y, u, ny=2, nu=2, degree=3, max_terms=4, sample_time=TS)
    got = dict(zip(model.term_names(), model.coefficients))
    assert set(got) == set(TRUE)
    for name, value in TRUE.items():
        assert got[name] == pytest.approx(value, abs=0.02), name
    assert model.err.sum() > 0.95 and model.err[0] == max(model.err)  # the largest reduction is chosen first


def test_it_beats_the_thesiss_gaussian_network_on_a_polynomial_truth_out_of_sample():
    y, u = _truth(1200, 4, noise=0.01)
    yv, uv = _truth(800, 5, noise=0.01)
    poly = narx_poly(y, u, ny=2, nu=2, degree=2, sample_time=TS)
    rbf = narx_rbf(y, u, ny=8, nu=8, sample_time=TS)  # the thesis's 8th-order NARX-RBF
    fit_poly = fit_percent(yv, poly.simulate(uv, yv))
    fit_rbf = fit_percent(yv, rbf.simulate(uv, yv))
    # the noise inside the recursion caps a free run's fit near 94 %; the network trails by about 12 points
    assert fit_poly > 92.0 and fit_poly > fit_rbf + 8.0, (fit_poly, fit_rbf)


def test_the_residuals_of_the_true_structure_pass_the_five_correlation_tests_and_a_linear_model_does_not():
    passed, linear = [], []
    for seed in range(20, 30):  # each test has a 5 % false rejection: count over ten seeds
        y, u = _truth(2000, seed, noise=0.02)
        model = narx_poly(y, u, ny=2, nu=2, degree=2, max_terms=4, sample_time=TS)
        passed += [t.passed for t in billings_voon_tests(u[2:], model.residuals(y, u)[2:])]
        arx = narx_poly(y, u, ny=2, nu=2, degree=1, sample_time=TS)
        linear += [t.passed for t in billings_voon_tests(u[2:], arx.residuals(y, u)[2:]) if t.name in ("u2e", "u2e2")]
    assert np.mean(passed) >= 0.86  # 0.95 expected
    assert np.mean(linear) <= 0.2  # the squared-input terms the linear model lacks show in u^2 e


def test_prediction_horizons_run_from_one_step_to_the_free_run():
    y, u = _truth(300, 7)
    model = narx_poly(y, u, ny=2, nu=2, degree=2, max_terms=4, sample_time=TS)
    np.testing.assert_allclose(model.predict(y, u, 1), y, atol=1e-9)  # noise-free: exact one step ahead
    np.testing.assert_allclose(model.simulate(u, y), y, atol=1e-8)  # and exact free run from y's start
    assert np.allclose(model.predict(y, u, 300), model.simulate(u, y))


def test_candidates_and_the_equation_read_as_the_model():
    assert len(candidate_terms(2, 2, 1, 2)) == 1 + 4 + 10
    assert len(candidate_terms(1, 1, 0, 3)) == 1 + 2 + 3 + 4
    y, u = _truth(400, 8)
    model = narx_poly(y, u, ny=1, nu=2, degree=2, max_terms=4, sample_time=TS)
    assert model.equation().startswith("y(t) = ") and "y(t-1) u(t-1)" in model.equation()
    assert isinstance(model, PolynomialNarx) and "4 terms of 10" in repr(model)


@pytest.mark.parametrize(
    "kwargs, error, match",
    [
        ({"degree": 5}, InputError, r"degree = 5 is outside the allowed range \[1, 4\]"),
        ({"ny": 0}, InputError, r"ny = 0 is outside the allowed range \[1, inf\]"),
        ({"tolerance": 2.0}, InputError, r"tolerance = 2.0 is outside the allowed range"),
        ({"max_terms": 2.5}, InputError, "max_terms must be an int, got 2.5"),
    ],
)
def test_bad_settings_are_refused_in_one_line(kwargs, error, match):
    y, u = _truth(200, 9)
    with pytest.raises(error, match=match):
        narx_poly(y, u, sample_time=TS, **kwargs)


def test_too_few_samples_or_a_silent_output_are_refused():
    y, u = _truth(40, 10)
    with pytest.raises(EstimationError, match="candidate terms; at least"):
        narx_poly(y, u, ny=4, nu=4, degree=3, sample_time=TS)
    with pytest.raises(EstimationError, match="the output is zero at every sample"):
        narx_poly(np.zeros(400), u.repeat(10), sample_time=TS)


@pytest.mark.parametrize("level", [0.0, 0.3])
def test_a_zero_or_constant_input_is_refused(level):
    y, _ = _truth(400, 11)
    with pytest.raises(InputError, match=r"input u is (identically zero|constant \(0.3 throughout\))"):
        narx_poly(y, np.full(400, level), sample_time=TS)
