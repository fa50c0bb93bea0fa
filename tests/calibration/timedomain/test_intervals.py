"""Sandwich intervals for correlated residuals, on a linear fit whose truth and error process are known."""

import numpy as np
import pytest
import scipy.signal

from trms.calibration.timedomain.intervals import (
    bartlett_bandwidth,
    disturbance_intervals,
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


_MODE = [1.0, -2 * 0.99 * np.cos(2 * np.pi / 60), 0.99**2]  # a lightly damped mode, 60 samples a period


def _ringing(rng, n, white=1.0):
    """The mode rung by noise (unit variance), plus white measurement noise of std ``white``: the shape of a
    rig's output error under ambient turbulence (the pitch mode, encoder noise)."""
    e = scipy.signal.lfilter([1.0], _MODE, rng.standard_normal(n + 500))[500:]
    return e / e.std() + white * rng.standard_normal(n)


def _coverage(errors, trials=300, records=3, n=400, ringing_regressor=False, **kw):
    """Fraction of trials whose slope lies in its sandwich (and its white) 95 % interval, and the median
    ratio of the two half-widths. The regressor is a slow sine, or (``ringing_regressor``) a binary input
    through the mode, as a parameter's sensitivity is. ``kw`` goes to :func:`sandwich_intervals`
    (``bandwidth``) or, with ``plug_in=True``, asks for Andrews' plug-in bandwidth."""
    rng = np.random.default_rng(7)
    t = np.linspace(0, 1, n)
    if ringing_regressor:
        x = np.vstack(
            [
                np.column_stack(
                    [scipy.signal.lfilter([1.0], _MODE, np.sign(rng.standard_normal(n // 20)).repeat(20)), np.ones(n)]
                )
                for _ in range(records)
            ]
        )
    else:
        x = np.vstack([np.column_stack([np.sin(2 * np.pi * 3 * t), np.ones(n)])] * records)  # slow, and an offset
    inv = np.linalg.inv(x.T @ x)
    plug_in = kw.pop("plug_in", False)
    inside = white = 0
    ratio = []
    for _ in range(trials):
        e = np.concatenate([errors(rng, n) for _ in range(records)])
        beta = inv @ x.T @ e  # truth 0
        r = e - x @ beta
        parts = np.split(r, records)
        if plug_in:
            kw["bandwidth"] = bartlett_bandwidth(record_scores(parts, x, 1))
        half, _, _ = sandwich_intervals(parts, x, inv, 1, **kw)
        s2 = r @ r / (r.size - 2)
        white_half = 1.96 * np.sqrt(s2 * inv[0, 0])
        inside += abs(beta[0]) <= half[0]
        white += abs(beta[0]) <= white_half
        ratio.append(half[0] / white_half)
    return inside / trials, white / trials, float(np.median(ratio))


def test_with_white_errors_the_sandwich_covers_and_is_not_much_wider_than_the_usual_interval():
    # one record: as the white interval (300 trials: 0.95 +- 0.025); several: on the safe side (the
    # critical value is one record's), at a cost in width: 1.2 times the white interval, and 2 for three records
    for records, least, widest in ((1, 0.91, 1.4), (3, 0.95, 2.3)):
        covered, white, ratio = _coverage(lambda rng, n: rng.standard_normal(n), records=records)
        assert least <= covered and 0.91 <= white <= 0.99
        assert 1.0 < ratio < widest, (records, ratio)


def test_with_strongly_correlated_errors_the_sandwich_covers_where_the_white_interval_does_not():
    covered, white, _ = _coverage(lambda rng, n: _ar1(rng, n, 0.97))
    assert white < 0.6
    assert covered >= 0.9


@pytest.mark.parametrize("white_noise", [0.3, 1.0])
def test_a_rung_mode_under_white_noise_fools_the_plug_in_bandwidth_not_the_reported_interval(white_noise):
    """Andrews' AR(1) plug-in reads a ringing error under white noise as nearly white (short bandwidth) and
    undercovers; the whole-record bandwidth with its fixed-b critical value (the reported interval) covers."""

    def errors(rng, n):
        return _ringing(rng, n, white=white_noise)

    covered, _, _ = _coverage(errors, trials=200, records=2, n=1200, ringing_regressor=True)
    plug_in, _, _ = _coverage(errors, trials=200, records=2, n=1200, ringing_regressor=True, plug_in=True)
    assert plug_in < 0.88
    assert covered >= 0.93


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
    np.testing.assert_allclose(long_run_covariance(g, 2), [[14.0 + 2 / 3 * 2 * 8.0 + 1 / 3 * 2 * 3.0]])
    rng = np.random.default_rng(0)
    smooth = [np.cumsum(rng.standard_normal((2000, 1)), axis=0) * 0.01 + _ar1(rng, 2000, 0.99)[:, None]]
    assert bartlett_bandwidth(smooth) > 10 * bartlett_bandwidth([rng.standard_normal((2000, 1))])
    with pytest.raises(ValueError, match="the residuals have 6 entries, the Jacobian 5 rows"):
        record_scores(r, jac[:5], 2)


def test_the_long_run_covariance_by_fft_equals_the_sum_over_lags():
    """Two records, three parameters, every bandwidth up to the whole record: the FFT's lagged products are
    the direct sums (cross terms between parameters kept, no wrap-around)."""
    rng = np.random.default_rng(4)
    scores = [rng.standard_normal((37, 3)), rng.standard_normal((20, 3))]
    for bandwidth in (0, 1, 5, 19, 36, 100):
        direct = np.zeros((3, 3))
        for g in scores:
            direct += g.T @ g
            for lag in range(1, min(bandwidth, len(g) - 1) + 1):
                gamma = g[lag:].T @ g[:-lag]
                direct += (1.0 - lag / (bandwidth + 1.0)) * (gamma + gamma.T)
        np.testing.assert_allclose(long_run_covariance(scores, bandwidth), direct, rtol=1e-10, atol=1e-10)


def test_the_default_bandwidth_is_the_longest_record():
    rng = np.random.default_rng(2)
    x = rng.standard_normal((30, 1))
    _, _, lag = sandwich_intervals([rng.standard_normal(20), rng.standard_normal(10)], x, np.eye(1), 1)
    assert lag == 19


def test_fixed_b_critical_value_grows_from_the_normal_quantile():
    values = [fixed_b_critical_value(b) for b in np.linspace(0, 1, 11)]
    assert values[0] == 1.96 and np.all(np.diff(values) > 0) and values[-1] < 5.0


_SLOW_MODE = [1.0, -2 * 0.995 * np.cos(2 * np.pi / 60), 0.995**2]  # rings for a record's length


def _slow_ringing(rng, n):
    return scipy.signal.lfilter([1.0], _SLOW_MODE, rng.standard_normal(n + 2000))[2000:] / 10


def _disturbance_fit(rng, n, gain, white, records=2):
    """A slope and an offset fitted to records whose error is ``gain`` times the simulated disturbance plus white
    noise of std ``white``; the regressor is a binary input through the same mode (truth 0)."""
    x = np.vstack(
        [
            np.column_stack(
                [
                    scipy.signal.lfilter([1.0], _SLOW_MODE, np.sign(rng.standard_normal(n // 30)).repeat(30)) / 10,
                    np.ones(n),
                ]
            )
            for _ in range(records)
        ]
    )
    e = np.concatenate([gain * _slow_ringing(rng, n) + white * rng.standard_normal(n) for _ in range(records)])
    inv = np.linalg.inv(x.T @ x)
    beta = inv @ x.T @ e
    draws = np.array([np.concatenate([_slow_ringing(rng, n) for _ in range(records)]) for _ in range(32)])
    half, _, scale = disturbance_intervals(np.split(e - x @ beta, records), x, draws, 1, 20)
    return beta, half, scale, inv


def test_disturbance_intervals_find_the_disturbances_scale_and_cover_the_truth():
    """The data's disturbance is 2.5 times the simulated one (scale 6.25) under white noise: the scale is read off
    the residuals' autocovariance, and the intervals (its upper bound) hold the truth."""
    rng = np.random.default_rng(7)
    inside, scales = 0, []
    for _ in range(150):
        beta, half, scale, _ = _disturbance_fit(rng, 300, 2.5, 0.3)
        inside += abs(beta[0]) <= half[0]
        scales.append(scale)
    assert 4.5 < np.median(scales) < 7.5
    assert inside / 150 >= 0.95


def test_without_a_correlated_error_the_disturbance_interval_is_about_the_white_one():
    """White errors: the scale found is nil, the white rest is the whole residual, and the interval is the white
    one, widened only by the scale's upper bound (one realisation cannot rule a small disturbance out)."""
    ratios = []
    for seed in range(5):
        beta, half, scale, inv = _disturbance_fit(np.random.default_rng(seed), 3000, 0.0, 1.0, records=1)
        assert scale < 0.005
        ratios.append(half[0] / (1.96 * np.sqrt(inv[0, 0])))
    assert min(ratios) > 0.9 and np.median(ratios) < 1.7, ratios
