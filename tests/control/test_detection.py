"""The innovation chi-square detector: its false-alarm rate as designed, its innovations from a known filter."""

from __future__ import annotations

import control
import numpy as np
import pytest

from trms.control.detection import ChiSquareDetector, innovations
from trms.errors import InputError


@pytest.mark.parametrize("p, window, rate", [(1, 1, 0.01), (2, 1, 0.001), (1, 10, 0.01), (2, 20, 0.005)])
def test_fault_free_white_innovations_alarm_at_the_designed_rate(p, window, rate):
    cov = np.array([[0.04, 0.01], [0.01, 0.02]])[:p, :p]
    det = ChiSquareDetector(cov, window=window, false_alarm_rate=rate)
    rng = np.random.default_rng(7)
    chol = np.linalg.cholesky(cov)
    runs = [det.run(rng.standard_normal((2000, p)) @ chol.T) for _ in range(100)]
    alarms = np.concatenate([r.alarms[window - 1 :] for r in runs])
    # window 1: independent samples, a binomial band of 4 standard deviations; overlapping windows correlate the
    # alarms (fewer independent trials), so the band widens by the window's square root
    sd = np.sqrt(rate * (1 - rate) / alarms.size) * np.sqrt(window)
    assert abs(alarms.mean() - rate) < 4 * sd + 1e-12, (alarms.mean(), rate)


def test_a_bias_of_three_standard_deviations_alarms_within_a_window_and_a_quiet_run_does_not_early():
    det = ChiSquareDetector([[1.0]], window=10, false_alarm_rate=1e-3)
    rng = np.random.default_rng(3)
    e = rng.standard_normal(400)
    e[200:] += 3.0
    result = det.run(e)
    assert result.first_alarm is not None and 200 <= result.first_alarm < 210
    assert result.false_alarm_rate(before=200) < 0.01


def test_the_online_test_alarms_where_the_whole_run_does():
    det = ChiSquareDetector(np.diag([0.5, 2.0]), window=5, false_alarm_rate=0.05)
    e = np.random.default_rng(1).standard_normal((300, 2)) * [0.7, 1.4]
    e[150:, 0] += 1.5
    whole = det.run(e)
    det.reset()
    online = np.array([det.update(x) for x in e])
    np.testing.assert_array_equal(online, whole.alarms)


def test_a_kalman_predictors_innovations_are_white_with_its_predicted_covariance():
    # Known truth: x+ = A x + B u + w, y = C x + v with known noise; the steady-state predictor's innovations
    # have covariance S = C P C' + R and no correlation between samples.
    a = np.array([[1.6, -0.8], [1.0, 0.0]])
    b = np.array([[1.0], [0.0]])
    c = np.array([[0.2, 0.1]])
    qw, rv = 0.01, 0.0004
    rng = np.random.default_rng(5)
    n = 20000
    u = np.sign(rng.standard_normal(n))
    x = np.zeros(2)
    y = np.empty(n)
    for k in range(n):  # the truth, simulated sample by sample
        y[k] = c[0] @ x + np.sqrt(rv) * rng.standard_normal()
        x = a @ x + b[:, 0] * u[k] + np.array([np.sqrt(qw) * rng.standard_normal(), 0.0])
    m, p, _ = control.dlqe(a, np.array([[1.0], [0.0]]), c, [[qw]], [[rv]], method="scipy")
    gain = m  # python-control: x+ = A x + B u + L (y - C x), the predictor form
    s = (c @ p @ c.T).item() + rv
    e = innovations(a, b, c, gain, u, y)[:, 0]
    assert np.var(e[100:]) == pytest.approx(s, rel=0.05)
    lag1 = np.corrcoef(e[100:-1], e[101:])[0, 1]
    assert abs(lag1) < 4 / np.sqrt(n)
    quiet = ChiSquareDetector([[s]], window=10, false_alarm_rate=0.01).run(e[100:])
    assert quiet.false_alarm_rate() < 0.02


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"covariance": [[1.0, 2.0], [2.0, 1.0]]}, "covariance must be positive definite"),
        ({"covariance": [[1.0, 0.5], [0.0, 1.0]]}, "covariance must be symmetric"),
        ({"covariance": [1.0, 2.0]}, r"covariance must be a square \(p, p\) matrix, got shape \(1, 2\)"),
        ({"covariance": [[1.0]], "window": 0}, r"window = 0 is outside the allowed range \[1, inf\]"),
        ({"covariance": [[1.0]], "false_alarm_rate": 0.0}, r"false_alarm_rate = 0.0 is outside the allowed range"),
        ({"covariance": [[np.nan]]}, "covariance must be finite"),
    ],
)
def test_bad_designs_are_refused_in_one_line(kwargs, match):
    with pytest.raises(InputError, match=match):
        ChiSquareDetector(**kwargs)


def test_bad_calibration_runs_are_refused_in_one_line():
    rng = np.random.default_rng(0)
    with pytest.raises(InputError, match="runs must be a list of runs"):
        ChiSquareDetector.calibrated(rng.standard_normal((2000, 2)))  # one array, not a list of runs
    with pytest.raises(InputError, match=r"every run must be \(N, p\) with the same p outputs"):
        ChiSquareDetector.calibrated([np.zeros((100, 2)), np.zeros((100, 3))])
    with pytest.raises(InputError, match="runs must be a list of runs"):
        ChiSquareDetector.calibrated(None)  # type: ignore[arg-type]
    with pytest.raises(InputError, match="before = -3 samples is outside"):
        ChiSquareDetector([[1.0]]).run(np.zeros(20)).false_alarm_rate(before=-3)
    with pytest.raises(InputError, match="the longest run holds 5 samples, fewer than the window of 10"):
        ChiSquareDetector.calibrated([rng.standard_normal(5)], window=10)  # no windowed statistic to calibrate on


def test_bad_sequences_are_refused_in_one_line():
    det = ChiSquareDetector(np.eye(2))
    with pytest.raises(InputError, match=r"innovations must have shape \(N, 2\), got \(10, 1\)"):
        det.run(np.zeros(10))
    with pytest.raises(InputError, match="innovation must have 2 entries, got 3"):
        det.update([0.0, 0.0, 0.0])
    with pytest.raises(InputError, match=r"B must have shape \(1, 1\) for these data, got \(1, 2\)"):
        innovations([[0.5]], [[1.0, 1.0]], [[1.0]], [[0.1]], np.zeros(5), np.zeros(5))
    with pytest.raises(InputError, match=r"inputs and outputs must be \(N, m\) and \(N, p\) with N > 0"):
        innovations([[0.5]], [[1.0]], [[1.0]], [[0.1]], [], [])
    with pytest.raises(InputError, match="inputs and outputs must have the same length, got 5 and 4"):
        innovations([[0.5]], [[1.0]], [[1.0]], [[0.1]], np.zeros(5), np.zeros(4))
    rng = np.random.default_rng(0)
    with pytest.raises(InputError, match=r"overflow from sample \d+ of 100000: A - L C has a pole of \|z\| = 1.5"):
        innovations([[1.5]], [[1.0]], [[1.0]], [[0.0]], rng.standard_normal(100_000), rng.standard_normal(100_000))
