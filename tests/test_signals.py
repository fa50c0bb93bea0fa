"""Excitation signals: exact shapes, reproducibility, and the spectrum behind "bandwidth"."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.signal

from trms.errors import InputError
from trms.signals import (
    doublet,
    make_rng,
    multisine,
    multistep_3211,
    prbs,
    random_binary,
    sample_count,
    square_wave,
    uniform_noise,
)


def held_sinc2(f: np.ndarray, bandwidth: float, ts: float) -> np.ndarray:
    """Spectrum shape of a random level held for m = 1 / (B Ts) samples, normalised to 1 at f = 0."""
    m = 1.0 / (bandwidth * ts)
    with np.errstate(invalid="ignore", divide="ignore"):
        s = (np.sin(np.pi * f / bandwidth) / (m * np.sin(np.pi * f * ts))) ** 2
    return np.where(f == 0, 1.0, s)


@pytest.mark.parametrize("generator", [random_binary, uniform_noise])
@pytest.mark.parametrize("bandwidth", [10.0, 5.0, 2.0])
def test_bandwidth_is_the_clock_frequency_of_a_sinc2_spectrum(generator, bandwidth):
    # 4000 s at Ts = 0.1 s, Welch with 256-sample segments: ~310 averaged half-overlapping segments,
    # so a bin's relative standard error is ~6 %. The median over the band must sit within 8 %
    # of the held-sequence sinc^2 shape, and no bin (f = 0 and Nyquist excluded: Welch's detrend
    # and one-sided folding treat them specially) may be off by more than 30 %.
    ts = 0.1
    u = generator(4000.0, ts, bandwidth, 1.0, seed=1)
    f, p = scipy.signal.welch(u, fs=1 / ts, nperseg=256)
    p = p / np.trapezoid(p, f)
    theory = held_sinc2(f, bandwidth, ts)
    theory = theory / np.trapezoid(theory, f)
    band = (f > 0) & (f <= 0.9 * bandwidth) & (f < 0.5 / ts)
    rel = np.abs(p[band] / theory[band] - 1)
    assert np.median(rel) < 0.08
    assert rel.max() < 0.30
    if bandwidth < 1 / ts:
        # The first null is at the bandwidth: power there is < 1 % of the low-frequency level.
        low = np.mean(p[(f > 0) & (f < 0.25 * bandwidth)])
        assert p[np.argmin(np.abs(f - bandwidth))] / low < 0.01
        # Half the bandwidth is 3.9 dB down (sinc^2(1/2) = 0.405 for long holds): the band
        # average over +-20 % of B/2 matches the same average of the theory within 15 %
        # (the spread of that average over seeds is about 5 %).
        near = np.abs(f - bandwidth / 2) <= 0.2 * bandwidth / 2
        assert np.mean(p[near]) == pytest.approx(np.mean(theory[near]), rel=0.15)


def test_non_integer_clock_keeps_the_mean_rate_and_puts_the_null_near_the_bandwidth():
    ts, bandwidth = 0.2, 2.0  # 2.5 samples per level: holds alternate between 2 and 3 samples
    u = random_binary(3000.0, ts, bandwidth, 1.0, seed=3)
    idx = np.flatnonzero(np.diff(np.floor(np.arange(len(u)) * ts * bandwidth + 1e-9)))
    assert set(np.diff(idx)) == {2, 3}
    f, p = scipy.signal.welch(u, fs=1 / ts, nperseg=250)
    low = np.mean(p[(f > 0) & (f < 0.2)])
    # the jittered clock fills the null partly; it stays 10x below the flat part
    assert p[np.argmin(np.abs(f - bandwidth))] / low < 0.1


def test_prbs_levels_and_switch_rate():
    u = random_binary(60.0, 0.2, 5.0, amplitude=0.5, offset=2.0, seed=0)
    assert u.shape == (300,) and u.dtype == np.float64
    assert set(np.unique(u)) == {1.5, 2.5}
    # one fair coin per sample: about half the samples switch (binomial, 299 trials, 5 sigma = 43)
    assert abs(np.count_nonzero(np.diff(u)) - 149.5) < 43
    slow = random_binary(120.0, 0.1, 2.0, 1.0, seed=0)
    runs = np.diff(np.flatnonzero(np.diff(slow)))
    assert np.all(runs % 5 == 0)  # levels can only change on the 2 Hz clock (every 5 samples)


def test_uniform_noise_is_uniform_on_the_stated_interval():
    u = uniform_noise(2000.0, 0.1, 10.0, amplitude=2.0, offset=-1.0, seed=4)
    assert u.min() >= -3.0 and u.max() <= 1.0
    # 20000 independent draws: mean within 5 standard errors (sd/sqrt(N) = 1.155/141)
    assert abs(u.mean() + 1.0) < 5 * 1.155 / np.sqrt(u.size)
    assert u.var() == pytest.approx(4.0 / 3.0, rel=0.03)
    hist, _ = np.histogram(u, bins=10, range=(-3.0, 1.0))
    assert np.all(np.abs(hist / u.size - 0.1) < 0.01)  # 5 binomial sd = 0.0106


@pytest.mark.parametrize("generator", [random_binary, uniform_noise])
def test_same_seed_same_bits_and_generators_accepted(generator):
    a = generator(30.0, 0.1, 2.0, 1.0, seed=7)
    b = generator(30.0, 0.1, 2.0, 1.0, seed=7)
    c = generator(30.0, 0.1, 2.0, 1.0, seed=8)
    assert a.tobytes() == b.tobytes()
    assert not np.array_equal(a, c)
    g = generator(30.0, 0.1, 2.0, 1.0, seed=np.random.default_rng(7))
    assert g.tobytes() == a.tobytes()


def test_multistep_3211_exact_shape():
    u = multistep_3211(0.1, 1.0, amplitude=2.0, offset=1.0, start=0.5, duration=10.0)
    assert u.shape == (100,)
    expected = np.concatenate(
        [np.full(5, 1.0), np.full(30, 3.0), np.full(20, -1.0), np.full(10, 3.0), np.full(10, -1.0), np.full(25, 1.0)]
    )
    np.testing.assert_array_equal(u, expected)
    assert multistep_3211(0.2, 1.0, 1.0).shape == (35,)


def test_doublet_exact_shape_and_zero_mean():
    u = doublet(0.2, 2.0, amplitude=1.5, start=1.0, duration=10.0)
    assert u.shape == (50,)
    np.testing.assert_array_equal(u[:5], 0.0)
    np.testing.assert_array_equal(u[5:15], 1.5)
    np.testing.assert_array_equal(u[15:25], -1.5)
    np.testing.assert_array_equal(u[25:], 0.0)
    assert u.sum() == 0.0


@pytest.mark.parametrize("start_high, first", [(True, 1.0), (False, -1.0)])
def test_square_wave_halves(start_high, first):
    u = square_wave(20.0, 0.2, 8.0, 1.0, offset=0.0, start_high=start_high)
    assert u.shape == (100,)
    np.testing.assert_array_equal(u[:20], first)
    np.testing.assert_array_equal(u[20:40], -first)
    np.testing.assert_array_equal(u[80:], first)
    # a half period of 3.5 samples: each half starts on the first sample at or after its edge,
    # so the high half [0, 0.35) s holds 4 samples and the low half [0.35, 0.7) s holds 3
    v = square_wave(1.4, 0.1, 0.7, 1.0)
    np.testing.assert_array_equal(v, [1, 1, 1, 1, -1, -1, -1] * 2)


@pytest.mark.parametrize(
    "call, match",
    [
        (
            lambda: random_binary(10.0, 0.2, 6.0, 1.0),
            r"bandwidth = 6\.0 Hz is outside the allowed range \(0\.0 Hz, 5\.0 Hz\]",
        ),
        (lambda: random_binary(10.0, 0.2, 0.0, 1.0), r"bandwidth = 0\.0 Hz is outside"),
        (lambda: random_binary(10.0, 0.2, 1.0, -1.0), r"amplitude = -1\.0 is outside"),
        (lambda: random_binary(10.0, 0.2, 1.0, 1.0, seed=-3), r"seed must be a non-negative integer or None, got -3"),
        (lambda: uniform_noise(float("nan"), 0.2, 1.0, 1.0), r"duration = nan s is outside"),
        (lambda: uniform_noise(10.0, 0.0, 1.0, 1.0), r"sample_time = 0\.0 s is outside"),
        (lambda: uniform_noise(0.05, 0.2, 1.0, 1.0), r"shorter than one sample"),
        (lambda: multistep_3211(0.2, 0.1, 1.0), r"step duration = 0\.1 s is outside the allowed range \[0\.2 s"),
        (lambda: multistep_3211(0.1, 1.0, 1.0, start=1.0, duration=5.0), r"shorter than the 3211 multistep"),
        (lambda: doublet(0.1, 1.0, 1.0, start=-1.0), r"start = -1\.0 s is outside"),
        (lambda: doublet(0.1, 1.0, 1.0, offset=float("inf")), r"offset = inf is outside"),
        (lambda: square_wave(10.0, 0.2, 0.3, 1.0), r"period = 0\.3 s is outside the allowed range \[0\.4 s"),
    ],
)
def test_bad_arguments_are_refused_with_the_allowed_range(call, match):
    with pytest.raises(InputError, match=match):
        call()


def test_sample_count_and_rng_helpers():
    assert sample_count(60.0, 0.2) == 300
    assert sample_count(1.0, 0.3) == 3
    g = np.random.default_rng(1)
    assert make_rng(g) is g
    assert make_rng(5).integers(1 << 30) == np.random.default_rng(5).integers(1 << 30)


# ---------------------------------------------------------------- maximum-length PRBS
def test_prbs_is_a_maximum_length_sequence_with_its_period():
    order, clock = 6, 3
    period = (2**order - 1) * clock
    u = prbs(3 * period * 0.1, 0.1, band=(0.0, 1.0 / clock), amplitude=0.5, offset=2.0, order=order)
    assert u.size == 3 * period and set(np.unique(u)) == {1.5, 2.5}
    np.testing.assert_array_equal(u[:period], u[period : 2 * period])
    # no shorter period: a maximum-length sequence
    levels = u[:period:clock]
    for shift in range(1, levels.size):
        assert not np.array_equal(levels, np.roll(levels, shift))
    # 2^(n-1) ones and 2^(n-1) - 1 zeros per period
    assert np.sum(levels > 2.0) == 2 ** (order - 1)


def test_prbs_circular_autocorrelation_is_flat_off_lag_zero():
    order = 7
    levels = prbs((2**order - 1) * 0.2, 0.2, order=order)
    length = levels.size
    acf = np.array([levels @ np.roll(levels, k) for k in range(length)])
    assert acf[0] == length
    np.testing.assert_array_equal(acf[1:], -1.0)
    # hence a flat periodogram: every harmonic but DC carries the same power
    power = np.abs(np.fft.fft(levels)) ** 2
    np.testing.assert_allclose(power[1:], length + 1, rtol=1e-9)
    assert power[0] == pytest.approx(1.0)


@pytest.mark.parametrize("clock", [1, 2, 5])
def test_prbs_band_is_matlabs_fraction_of_nyquist(clock):
    ts, order = 0.01, 12
    u = prbs((2**order - 1) * clock * ts, ts, band=(0.0, 1.0 / clock), order=order)  # one period
    edges = np.flatnonzero(np.diff(u)) + 1
    assert np.all(edges % clock == 0)  # levels change only on the clock of 1 / B samples
    f, pxx = scipy.signal.periodogram(u, fs=1 / ts, detrend=False)
    # one period: every harmonic carries the hold's envelope |sin(pi f P Ts) / (P sin(pi f Ts))|^2, exactly
    envelope = held_sinc2(f[1:], 1.0 / (clock * ts), ts)
    nonzero = envelope > 1e-12
    ratio = pxx[1:][nonzero] / envelope[nonzero]
    np.testing.assert_allclose(ratio, ratio[0], rtol=1e-6)
    nyquist = 0.5 / ts
    edge = np.argmin(np.abs(f - nyquist / clock))
    down_db = 10 * np.log10(ratio[0] / pxx[edge])
    expected = {1: 0.0, 2: 3.01, 5: 3.77}[clock]  # at the band edge B * Nyquist
    assert down_db == pytest.approx(expected, abs=0.02)
    if clock > 1:
        assert pxx[np.argmin(np.abs(f - 2 * nyquist / clock))] < 1e-20  # first null at 2 B * Nyquist


def test_prbs_default_order_covers_the_signal_without_repeating():
    u = prbs(100.0, 0.1, band=(0.0, 0.5))  # 1000 samples, clock 2: 500 levels need 9 bits (511)
    levels = u[::2]
    assert levels.size == 500
    assert not np.array_equal(levels[:255], levels[255:510])


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda: prbs(10.0, 0.1, 5.0), r"band must be a pair \(0, B\)"),
        (lambda: prbs(10.0, 0.1, (0.1, 0.5)), r"lower edge must be 0"),
        (lambda: prbs(10.0, 0.1, (0.0, 0.4)), r"clock period 1 / B = 2\.5 samples must be a whole number"),
        (lambda: prbs(10.0, 0.1, (0.0, 1.5)), r"band upper edge = 1\.5 is outside the allowed range \(0\.0, 1\.0\]"),
        (lambda: prbs(10.0, 0.1, order=40), r"order = 40 is outside the allowed range \[2, 32\]"),
        (lambda: prbs(10.0, 0.1, order=5.0), r"order must be an int, got 5\.0"),
    ],
)
def test_prbs_bad_input(call, match):
    with pytest.raises(InputError, match=match):
        call()


@pytest.mark.parametrize("phases", ["schroeder", "random", "zero"])
def test_multisine_spectrum_is_exactly_on_the_chosen_lines(phases):
    # 3 periods of 200 samples, lines between 0.1 and 0.6 of Nyquist: k = 10 .. 60
    ms = multisine(60.0, 0.1, period=20.0, band=(0.1, 0.6), amplitude=2.0, offset=1.0, phases=phases, seed=3)
    assert ms.signal.shape == (600,) and ms.period == 200
    np.testing.assert_array_equal(ms.lines, np.arange(10, 61))
    np.testing.assert_allclose(ms.frequency, ms.lines / 20.0)
    np.testing.assert_array_equal(ms.signal[:200], ms.signal[200:400])
    spectrum = np.fft.rfft(ms.signal[:200] - 1.0)
    off = np.setdiff1d(np.arange(spectrum.size), ms.lines)
    on = np.abs(spectrum[ms.lines])
    assert np.max(np.abs(spectrum[off])) < 1e-12 * on.max()
    np.testing.assert_allclose(on, on[0], rtol=1e-12)  # equal amplitudes
    np.testing.assert_allclose(np.angle(spectrum[ms.lines] * np.exp(-1j * ms.phases)), 0.0, atol=1e-9)
    # the stated peak, and the crest factor of one period
    assert np.max(np.abs(ms.signal - 1.0)) == pytest.approx(2.0, rel=1e-12)
    rms = np.sqrt(np.mean((ms.signal[:200] - 1.0) ** 2))
    assert ms.crest_factor == pytest.approx(2.0 / rms, rel=1e-12)


def test_multisine_crest_factor_schroeder_below_random_below_zero_phases():
    k = 64
    crest = {p: multisine(25.6, 0.1, band=(0.0, 0.5), phases=p).crest_factor for p in ("schroeder", "random", "zero")}
    assert multisine(25.6, 0.1, band=(0.0, 0.5)).lines.size == k
    # aligned cosines peak at K with RMS sqrt(K / 2): crest factor sqrt(2 K) exactly
    assert crest["zero"] == pytest.approx(np.sqrt(2 * k), rel=1e-12)
    assert crest["schroeder"] < 2.0 < crest["random"] < crest["zero"]


def test_multisine_random_phases_are_seeded_and_skip_thins_the_lines():
    a = multisine(10.0, 0.1, phases="random", seed=1)
    np.testing.assert_array_equal(a.signal, multisine(10.0, 0.1, phases="random", seed=1).signal)
    assert not np.allclose(a.signal, multisine(10.0, 0.1, phases="random", seed=2).signal)
    odd = multisine(10.0, 0.1, band=(0.0, 1.0), skip=2)
    np.testing.assert_array_equal(odd.lines, np.arange(1, 50, 2))
    assert a.lines[-1] == 49  # the Nyquist line of a 100-sample period is left out


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"band": (0.5, 0.2)}, r"band lower edge = 0.5 is outside the allowed range \[0.0, 0.2\]"),
        ({"band": (0.0, 1.5)}, r"band upper edge = 1.5 is outside the allowed range \(0.0, 1.0\]"),
        ({"band": (0.3, 0.3)}, r"band = \(0.3, 0.3\) is empty"),
        ({"band": (0.311, 0.319)}, r"holds no line of a 100-sample period"),
        ({"band": "wide"}, r"band must be a pair \(low, high\)"),
        ({"period": 20.0}, r"period = 20.0 s is longer than duration = 10.0 s"),
        ({"phases": "flat"}, r"unknown phases 'flat'; allowed: 'schroeder', 'random', 'zero'"),
        ({"skip": 0}, r"skip = 0 is outside the allowed range \[1, inf\]"),
        ({"amplitude": -1.0}, r"amplitude = -1.0 is outside the allowed range"),
    ],
)
def test_multisine_bad_input(kwargs, match):
    with pytest.raises(InputError, match=match):
        multisine(10.0, 0.1, **kwargs)
