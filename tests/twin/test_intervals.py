"""Sandwich intervals for correlated residuals, on a linear fit whose truth and error process are known."""

import numpy as np
import pytest

from trms.twin.calibration.intervals import (
    bartlett_bandwidth,
    fixed_b_critical_value,
    long_run_covariance,
    record_scores,
    sandwich_intervals,
)


def _ar1(rng, n, rho):
    e = np.empty(n)
    e[0] = rng.standard_normal() / np.sqrt(1 - rho**2)
    w = rng.standard_normal(n)
    for t in range(1, n):
        e[t] = rho * e[t - 1] + w[t]
    return e


def _coverage(rho, trials=300, records=3, n=400):
    """Fraction of trials whose slope lies in its sandwich (and its white) 95 % interval."""
    rng = np.random.default_rng(7)
    t = np.linspace(0, 1, n)
    x_rec = np.column_stack([np.sin(2 * np.pi * 3 * t), np.ones(n)])  # a slow regressor and an offset
    x = np.vstack([x_rec] * records)
    inv = np.linalg.inv(x.T @ x)
    inside = white = 0
    for _ in range(trials):
        e = np.concatenate([_ar1(rng, n, rho) for _ in range(records)])
        beta = inv @ x.T @ e  # truth 0
        r = e - x @ beta
        half, _, _ = sandwich_intervals(np.split(r, records), x, inv, 1)
        s2 = r @ r / (r.size - 2)
        inside += abs(beta[0]) <= half[0]
        white += abs(beta[0]) <= 1.96 * np.sqrt(s2 * inv[0, 0])
    return inside / trials, white / trials


def test_with_white_errors_the_sandwich_is_the_usual_interval():
    covered, white = _coverage(0.0)
    assert 0.92 <= covered <= 0.99 and 0.92 <= white <= 0.99


def test_with_strongly_correlated_errors_the_sandwich_covers_where_the_white_interval_does_not():
    covered, white = _coverage(0.97)
    assert white < 0.6
    assert covered >= 0.9


def test_scores_bandwidth_and_long_run_covariance():
    r = [np.array([1.0, 2.0, 3.0, 4.0]), np.array([1.0, -1.0])]
    jac = np.column_stack([np.ones(6), np.arange(6.0)])
    scores = record_scores(r, jac, 2)
    assert [s.shape for s in scores] == [(2, 2), (1, 2)]
    np.testing.assert_allclose(scores[0], [[3.0, 2.0], [7.0, 18.0]])
    np.testing.assert_allclose(scores[1], [[0.0, -1.0]])
    g = [np.array([[1.0], [2.0], [3.0]])]
    np.testing.assert_allclose(long_run_covariance(g, 0), [[14.0]])
    np.testing.assert_allclose(long_run_covariance(g, 1), [[14.0 + 0.5 * 2 * (2.0 + 6.0)]])
    rng = np.random.default_rng(0)
    smooth = [np.cumsum(rng.standard_normal((2000, 1)), axis=0) * 0.01 + _ar1(rng, 2000, 0.99)[:, None]]
    assert bartlett_bandwidth(smooth) > 10 * bartlett_bandwidth([rng.standard_normal((2000, 1))])
    with pytest.raises(ValueError, match="the residuals have 6 entries, the Jacobian 5 rows"):
        record_scores(r, jac[:5], 2)


def test_fixed_b_critical_value_grows_from_the_normal_quantile():
    values = [fixed_b_critical_value(b) for b in np.linspace(0, 1, 11)]
    assert values[0] == 1.96 and np.all(np.diff(values) > 0) and values[-1] < 5.0
