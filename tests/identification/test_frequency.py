"""Frequency response with confidence bands on known truth, and its plot."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.signal
from matplotlib.figure import Figure

from trms.errors import InputError
from trms.identification import PolynomialModel, arx, bj, frequency_response, oe, plot_frequency_response
from trms.identification.frequency import FrequencyResponse

TS = 0.1
B = np.array([0.0, 0.4, 0.25])
F = np.array([1.0, -1.3, 0.6])


def _data(n: int, seed: int, coloured: bool = True) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    u = np.repeat(np.sign(rng.standard_normal(n // 2 + 1)), 2)[:n]
    e = 0.1 * rng.standard_normal(n)
    noise = scipy.signal.lfilter([1.0, 0.5], [1.0, -0.9], e) if coloured else e
    return scipy.signal.lfilter(B, F, u) + noise, u


def _truth(freq: np.ndarray) -> np.ndarray:
    zinv = np.exp(-2j * np.pi * freq * TS)
    return np.polyval(B[::-1], zinv) / np.polyval(F[::-1], zinv)


def test_the_true_response_lies_in_the_95_percent_band_at_most_frequencies():
    fr = frequency_response(bj(*_data(2000, 7), 2, 1, 1, 2, 1, sample_time=TS))
    inside = fr.contains(_truth(fr.frequency))
    assert inside.mean() > 0.9
    np.testing.assert_allclose(fr.magnitude, np.abs(fr.response))
    assert np.all(fr.magnitude_low <= fr.magnitude) and np.all(fr.magnitude <= fr.magnitude_high)
    assert fr.frequency[-1] == pytest.approx(0.5 / TS)


@pytest.mark.parametrize("method", ["delta", "monte-carlo"])
def test_band_coverage_over_seeds_matches_the_level(method):
    """Pointwise coverage of |G| over 20 seeds of output-error data with white noise (the noise
    the OE covariance assumes): a band 0.6 or 2 times as wide fails."""
    freq = np.geomspace(0.01, 5.0, 40)
    covered = []
    for seed in range(20):
        fr = frequency_response(
            oe(*_data(1000, 50 + seed, coloured=False), 2, 2, 1, sample_time=TS),
            freq,
            method=method,
            n_draws=400,
            seed=seed,
        )
        mag = np.abs(_truth(freq))
        covered.append(np.mean((mag >= fr.magnitude_low) & (mag <= fr.magnitude_high)))
    assert 0.85 < np.mean(covered) < 0.995


def test_monte_carlo_and_delta_bands_agree_away_from_resonance_and_are_seeded():
    model = oe(*_data(2000, 3), 2, 2, 1, sample_time=TS)
    freq = np.array([0.0, 0.05, 0.2])
    delta = frequency_response(model, freq)
    mc = frequency_response(model, freq, method="monte-carlo", seed=4)
    again = frequency_response(model, freq, method="monte-carlo", seed=4)
    np.testing.assert_array_equal(mc.magnitude_high, again.magnitude_high)
    width_d, width_m = delta.magnitude_high - delta.magnitude_low, mc.magnitude_high - mc.magnitude_low
    np.testing.assert_allclose(width_m, width_d, rtol=0.15)
    assert mc.method == "monte-carlo" and delta.confidence == 0.95


def test_plot_returns_a_figure_and_draws_on_given_axes():
    fr = frequency_response(oe(*_data(800, 1, coloured=False), 2, 2, 1, sample_time=TS))  # white: bands given
    fig = plot_frequency_response(fr, truth=_truth(fr.frequency))
    assert isinstance(fig, Figure) and len(fig.axes) == 2
    assert fig.axes[0].get_xscale() == "log"
    host = Figure()
    axes = host.subplots(2, 1)
    assert plot_frequency_response(fr, ax=axes) is host
    assert len(axes[1].lines) == 1


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda m: frequency_response(PolynomialModel([1.0, -0.5], [0.0, 1.0], [1.0], TS)), r"no parameter covariance"),
        (lambda m: frequency_response(m, [1.0, 6.0]), r"within \[0, 5\] Hz"),
        (lambda m: frequency_response(m, method="bootstrap"), r"unknown method 'bootstrap'"),
        (lambda m: frequency_response(m, confidence=1.0), r"must be below 1"),
        (lambda m: frequency_response(m, method="monte-carlo", n_draws=10), r"n_draws = 10 is outside"),
        (lambda m: plot_frequency_response(frequency_response(m), ax=[None]), r"pair \(magnitude, phase\)"),
    ],
)
def test_bad_input(call, match):
    model = oe(*_data(400, 2), 1, 1, 1, sample_time=TS)
    with pytest.raises(InputError, match=match):
        call(model)


def test_contains_is_fieller_region_of_the_numerator_and_denominator():
    """``T(g) = |N - g D|^2 / var(N - g D)`` for independent circular ``N`` and ``D`` (variances 0.01, 0.04)."""
    cov = np.diag([0.01, 0.01, 0.04, 0.04])[None]
    fr = FrequencyResponse(
        *([np.array([1.0])] * 1),
        np.array([2.0 + 0j]),
        *([np.array([2.0])] * 3),
        *([np.zeros(1)] * 3),
        0.95,
        "given",
        np.array([[1.0 + 0j, 0.5 + 0j]]),
        cov,
        np.array([5.991]),
        np.array([9.0]),
    )
    g = np.array([3.0 + 1.0j])
    expected = abs(1.0 - g[0] * 0.5) ** 2 / (0.01 + abs(g[0]) ** 2 * 0.04)
    np.testing.assert_allclose(fr.distance(g), [expected], rtol=1e-6)
    assert fr.contains(g)[0] == (expected <= 5.991)
    assert fr.contains(g, simultaneous=True)[0] == (expected <= 9.0)


def test_the_delta_region_covers_the_truth_at_a_barely_resolved_resonance():
    """40 seeds of ARX data (poles at radius 0.99, 200 samples): the 95 % region holds the truth at the
    resonance in >= 35 (the former test, inside both the magnitude and the phase band, held it in 26)."""
    f_res = np.array([0.75, 0.76])
    den = np.array([1.0, -2 * 0.99 * np.cos(2 * np.pi * 0.76 * TS), 0.99**2])
    zinv = np.exp(-2j * np.pi * f_res * TS)
    truth = 0.05 * zinv / np.polyval(den[::-1], zinv)
    held, held_all = 0, 0
    for seed in range(40):
        rng = np.random.default_rng(200 + seed)
        u = np.sign(rng.standard_normal(200))
        y = scipy.signal.lfilter([0.0, 0.05], den, u) + scipy.signal.lfilter(
            [1.0], den, 0.05 * rng.standard_normal(200)
        )
        fr = frequency_response(arx(y, u, 2, 1, 1, sample_time=TS), f_res)
        held += int(fr.contains(truth)[1])
        held_all += int(fr.contains(truth, simultaneous=True).all())
    assert held >= 35 and held_all >= held
