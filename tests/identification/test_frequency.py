"""Frequency response with confidence bands on known truth, and its plot."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.signal
from matplotlib.figure import Figure

from trms.errors import InputError
from trms.identification import PolynomialModel, bj, frequency_response, oe, plot_frequency_response

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
    fr = frequency_response(oe(*_data(800, 1), 2, 2, 1, sample_time=TS))
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
