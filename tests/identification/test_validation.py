"""Fit, correlation tests (eq. 3.9, 5.13) and comparisons, on models of known adequacy."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.signal

from trms.errors import InputError
from trms.identification.linear import arx
from trms.identification.polynomial import PolynomialModel
from trms.identification.validation import (
    billings_voon_tests,
    compare,
    cross_correlation,
    fit_percent,
    independence_test,
    residual_tests,
    residual_variance,
    whiteness_test,
)
from trms.signals import random_binary, uniform_noise

TS = 0.2
NAMES = ["ee", "ue", "u2e", "u2e2", "e(eu)"]


def test_fit_percent_matlab_definition():
    y = np.array([1.0, 2.0, 3.0])
    assert fit_percent(y, y) == 100.0
    assert fit_percent(y, np.full(3, 2.0)) == pytest.approx(0.0)
    assert fit_percent(y, [1.0, 2.0, 4.0]) == pytest.approx(100 * (1 - 1 / np.sqrt(2)))
    with pytest.raises(InputError, match=r"y is constant"):
        fit_percent(np.ones(3), [1.0, 2.0, 3.0])


def test_cross_correlation_matches_the_definition():
    rng = np.random.default_rng(0)
    x, e = rng.standard_normal(200), rng.standard_normal(200)
    xc, ec = x - x.mean(), e - e.mean()
    norm = np.sqrt((xc @ xc) * (ec @ ec))
    lags = np.array([-3, 0, 2, 5])
    # phi_xe(tau) = sum_t x~(t - tau) e~(t) / norm
    brute = [sum(xc[t - tau] * ec[t] for t in range(200) if 0 <= t - tau < 200) / norm for tau in lags]
    np.testing.assert_allclose(cross_correlation(x, e, lags), brute, atol=1e-14)
    assert cross_correlation(x, x, [0])[0] == pytest.approx(1.0)


def test_each_test_returns_curve_bound_and_verdict():
    rng = np.random.default_rng(1)
    u, e = rng.uniform(-1, 1, 500), rng.standard_normal(500)
    tests = billings_voon_tests(u, e, max_lag=10)
    assert [t.name for t in tests] == NAMES
    assert [t.lags[0] for t in tests] == [1, -10, -10, -10, 0]
    for t in tests:
        assert t.values.shape == t.lags.shape
        assert t.bound == pytest.approx(1.96 / np.sqrt(500), rel=1e-3)  # the thesis's band
        assert t.passed == (t.statistic <= t.threshold)
        assert t.n_outside == int(np.sum(np.abs(t.values) > t.bound))
    assert whiteness_test(e, 10, confidence=0.99).bound == pytest.approx(2.5758 / np.sqrt(500), rel=1e-4)


def _eq_3_11_model(truth) -> PolynomialModel:
    return PolynomialModel(truth.A, truth.B, truth.C, TS)


def test_true_models_pass_and_a_linear_model_of_a_nonlinear_system_fails(truth, nonlinear):
    # 10 seeds at the 99 % level. The true models' residuals are white and independent of u,
    # so each test fails with probability 1 %: 3 or more failures in 10 seeds has probability
    # 1e-4. A linear ARX of the nonlinear system misses u(t-1)^2 and y(t-1) u(t-1), so its
    # residuals correlate with u^2: it must fail every seed.
    true_fails = np.zeros(5, int)
    nl_fails = np.zeros(5, int)
    arx_rejected = 0
    for seed in range(10):
        u = uniform_noise(100.0, TS, 2.0, 1.0, seed=seed)
        e = np.random.default_rng(seed + 50).standard_normal(u.size) * truth.noise_std
        y = scipy.signal.lfilter(truth.B, truth.A, u) + scipy.signal.lfilter(truth.C, truth.A, e)
        true_fails += [not t.passed for t in residual_tests(_eq_3_11_model(truth), y, u, confidence=0.99)]
        y_nl = nonlinear.simulate(u, seed + 70)
        nl_fails += [not t.passed for t in residual_tests(nonlinear, y_nl, u, confidence=0.99)]
        linear = arx(y_nl, u, 2, 2, 1, sample_time=TS)
        arx_rejected += not all(t.passed for t in residual_tests(linear, y_nl, u, confidence=0.99))
    assert np.all(true_fails <= 2), true_fails
    assert np.all(nl_fails <= 2), nl_fails
    assert arx_rejected == 10


def test_the_linear_pair_alone_for_a_two_level_input(truth):
    # A symmetric PRBS has a constant u^2: the u^2 tests are undefined and say so, the linear
    # pair of eq. (3.9) still runs.
    u = random_binary(100.0, TS, 5.0, 1.0, seed=3)
    e = np.random.default_rng(3).standard_normal(u.size) * truth.noise_std
    y = scipy.signal.lfilter(truth.B, truth.A, u) + scipy.signal.lfilter(truth.C, truth.A, e)
    model = _eq_3_11_model(truth)
    with pytest.warns(UserWarning, match=r"u is a two-level input \(u\^2 is constant.*only the linear tests"):
        said = residual_tests(model, y, u)  # the linear pair, and why the others were skipped
    tests = residual_tests(model, y, u, nonlinear=False)
    assert [t.name for t in tests] == [t.name for t in said] == ["ee", "ue"]
    assert [t.passed for t in tests] == [t.passed for t in said]
    with pytest.raises(InputError, match=r"u\^2 is constant \(a two-level input"):
        billings_voon_tests(u[model.start :], model.residuals(y, u)[model.start :])  # asked for by name: refused


def test_arx_residuals_of_coloured_noise_fail_whiteness_but_pass_independence(truth):
    # The thesis's diagnosis (ch. 3.3.2): an ARX model of ARMAX data leaves autocorrelated
    # residuals. With 3000 samples the plant part is nearly right, the noise model is not.
    y, u = truth.data(3000, 1)
    model = arx(y, u, 4, 4, 1, sample_time=TS)
    white, indep = residual_tests(model, y, u, nonlinear=False)
    assert not white.passed and white.statistic > 10 * white.threshold
    assert abs(white.values[0]) > 10 * white.bound


def test_compare_one_step_and_free_run(truth):
    y, u = truth.data(750, 1)
    model = _eq_3_11_model(truth)
    osa = compare(model, y, u, horizon=1)
    mpo = compare(model, y, u, initial="measured")
    np.testing.assert_array_equal(osa.yhat, model.predict(y, u, 1))
    np.testing.assert_array_equal(mpo.yhat, model.simulate(u, y))
    assert (osa.horizon, mpo.horizon, osa.start) == (1, None, 4)
    # one-step prediction corrects for the noise, the free run cannot (the noise C/A rings at
    # the 0.34 Hz resonance): OSA fits better
    assert osa.fit > mpo.fit > 60.0
    assert osa.fit == pytest.approx(fit_percent(y[4:], osa.yhat[4:]))


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda e: whiteness_test(e, 0), r"max_lag = 0 samples is outside the allowed range \[1 samples, 50 samples\]"),
        (lambda e: whiteness_test(e, 51), r"too short for correlation tests to max_lag = 51 samples: .* give 200"),
        (lambda e: whiteness_test(e, 5, confidence=1.0), r"confidence = 1\.0 must be below 1"),
        (lambda e: whiteness_test(e, 5, confidence=0.0), r"confidence = 0\.0 is outside"),
        (lambda e: independence_test(e[:-1], e), r"u and e must be 1-D of equal length"),
        (lambda e: whiteness_test(np.ones(200)), r"is constant: its correlation is undefined"),
        (lambda e: whiteness_test(np.r_[e[:-1], np.inf]), r"e must be finite"),
    ],
)
def test_bad_arguments(call, match):
    e = np.random.default_rng(2).standard_normal(200)
    with pytest.raises(InputError, match=match):
        call(e)


@pytest.mark.parametrize("horizon", [None, 1])
def test_compare_on_too_short_data_names_the_length_and_the_minimum(horizon):
    rng = np.random.default_rng(0)
    u = np.sign(rng.standard_normal(300))
    y = scipy.signal.lfilter([0.0, 0.5, 0.2], [1.0, -1.2, 0.5], u) + 0.01 * rng.standard_normal(300)
    model = arx(y, u, 2, 2, 1, sample_time=0.1)  # start = 2: the fit needs samples 2 and 3 at least
    for n in (1, 2, 3):
        with pytest.raises(
            InputError,
            match=rf"^the data have {n} samples; compare needs at least 4 \(the fit is "
            r"over the samples from the model's start = 2 on, and needs 2 of them\)$",
        ):
            compare(model, y[:n], u[:n], horizon)
    assert np.isfinite(compare(model, y[:4], u[:4], horizon).fit)
    # long enough but constant: that is what is said then
    with pytest.raises(InputError, match=r"y is constant"):
        compare(model, np.ones(50), u[:50], horizon)


def _fitted():
    u = random_binary(80.0, TS, 1.0, 1.0, seed=1)
    y = scipy.signal.lfilter([0, 0.5], [1, -0.9], u)
    return arx(y, u, 1, 1, 1, sample_time=TS), y, u


@pytest.mark.parametrize(
    "call",
    [
        lambda m, y, u: compare("model", y, u),
        lambda m, y, u: compare(None, y, u),
        lambda m, y, u: residual_tests(np.zeros(3), y, u),
        lambda m, y, u: residual_variance({"start": 1}, y, u),
    ],
)
def test_something_that_is_not_a_fitted_model_is_refused_in_one_line(call):
    model, y, u = _fitted()
    with pytest.raises(InputError, match=r"model = .* is not a fitted model; allowed: a PolynomialModel or NarxRbf"):
        call(model, y, u)


@pytest.mark.parametrize("n, max_lag", [(50, 20), (30, 10), (9, 3)])
def test_a_record_too_short_for_the_correlation_tests_names_its_length(n, max_lag):
    model, y, u = _fitted()
    residuals = n - model.start
    message = rf"need at least {4 * max_lag} samples \(4 per lag\), the data give {residuals}"
    with pytest.raises(InputError, match=message):
        residual_tests(model, y[:n], u[:n], max_lag=max_lag, nonlinear=False)
    enough = model.start + 4 * max_lag
    assert len(residual_tests(model, y[:enough], u[:enough], max_lag, nonlinear=False)) == 2
