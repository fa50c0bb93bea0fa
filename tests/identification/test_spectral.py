"""Spectra, coherence (eq. 3.1), mode finding and attenuation, on signals of known content."""

from __future__ import annotations

import control
import numpy as np
import pytest
import scipy.signal

from trms.errors import InputError
from trms.identification.spectral import (
    attenuation_db,
    coherence,
    csd,
    find_modes,
    mean_coherence,
    psd,
    transfer_estimate,
)
from trms.reference import EQ_3_11_DEN, EQ_3_11_NUM, eq_3_11
from trms.signals import uniform_noise

TS = 0.2


def test_psd_integrates_to_the_variance():
    x = np.random.default_rng(0).standard_normal(20000) * 3.0
    f, p = psd(x, TS)
    assert f[0] == 0.0 and f[-1] == pytest.approx(0.5 / TS)
    # Parseval: the one-sided density integrates to the variance (9); 20000 samples, 5 % tolerance
    assert np.trapezoid(p, f) == pytest.approx(9.0, rel=0.05)


def test_csd_of_a_signal_with_itself_is_its_psd():
    x = uniform_noise(200.0, TS, 5.0, 1.0, seed=2)
    f1, p = psd(x, TS, nperseg=128)
    f2, pxy = csd(x, x, TS, nperseg=128)
    np.testing.assert_allclose(f1, f2)
    np.testing.assert_allclose(pxy.real, p, rtol=1e-12)
    np.testing.assert_allclose(pxy.imag, 0.0, atol=1e-15)


@pytest.mark.parametrize("f0", [0.25, 0.34, 0.46, 0.3516])
def test_find_modes_resolves_a_sinusoid_finer_than_the_bin(f0):
    # Welch bins of 5 Hz / 128 = 0.039 Hz; the parabolic (log) interpolation must land within
    # 0.005 Hz (an eighth of a bin) whether the tone sits on a bin (0.3516) or between bins.
    t = np.arange(3000) * TS
    x = np.sin(2 * np.pi * f0 * t) + 0.01 * np.random.default_rng(1).standard_normal(t.size)
    f, p = psd(x, TS, nperseg=128)
    (peak,) = find_modes(f, p, band=(0.1, 1.0), n=1)
    assert abs(peak.frequency - f0) < 0.005
    assert peak.height >= p.max()


def test_find_modes_on_the_eq_3_11_frequency_response_and_psd():
    # The resonance of (3.11): poles 0.8929 +- 0.4095j, 0.342 Hz, damping 0.041.
    hz = np.linspace(0.01, 2.5, 400)
    mag = np.abs(control.frequency_response(eq_3_11(), 2 * np.pi * hz).magnitude).ravel()
    peaks = find_modes(hz, mag, quantity="amplitude")
    assert len(peaks) == 1 and peaks[0].frequency == pytest.approx(0.342, abs=0.003)
    u = uniform_noise(2000.0, TS, 5.0, 1.0, seed=1)
    y = scipy.signal.lfilter([0.0, *EQ_3_11_NUM], EQ_3_11_DEN, u)
    f, p = psd(y, TS)
    main = max(find_modes(f, p, band=(0.2, 1.0)), key=lambda pk: pk.height)
    assert main.frequency == pytest.approx(0.342, abs=0.005)
    assert find_modes(f, p, band=(0.2, 1.0), n=1) == [main]


def test_coherence_of_a_noise_free_linear_system_is_one():
    u = uniform_noise(2000.0, TS, 5.0, 1.0, seed=1)
    damped = scipy.signal.lfilter([0.0, 0.2, 0.1], [1.0, -1.0, 0.4], u)
    f, c = coherence(u, damped, TS)
    # A well-damped system: only the finite-segment (leakage) bias remains, < 0.002 here.
    assert np.all(c[1:] > 0.995)
    # The lightly damped (3.11): leakage at the 0.34 Hz resonance is the resolution bias the
    # thesis names; it shrinks as segments grow (default N // 8 = 1250 samples).
    y = scipy.signal.lfilter([0.0, *EQ_3_11_NUM], EQ_3_11_DEN, u)
    mins = [coherence(u, y, TS, nperseg=n)[1][1:].min() for n in (128, 512, None)]
    assert mins[0] < mins[1] < mins[2] and mins[2] > 0.95
    assert mean_coherence(*coherence(u, y, TS), band=(0.05, 2.0)) > 0.998


def test_coherence_of_independent_signals_is_near_zero():
    rng = np.random.default_rng(3)
    x, y = rng.standard_normal(4000), rng.standard_normal(4000)
    f, c = coherence(x, y, TS)
    # ~15 averaged segments: the expected value of the estimate for independent signals is ~1/K
    assert np.mean(c) < 0.1
    assert np.all((c >= 0) & (c <= 1))


def test_transfer_estimate_matches_the_true_frequency_response():
    u = uniform_noise(2000.0, TS, 5.0, 1.0, seed=4)
    y = scipy.signal.lfilter([0.0, 0.2, 0.1], [1.0, -1.0, 0.4], u)
    f, h = transfer_estimate(u, y, TS)
    _, true = scipy.signal.freqz([0.0, 0.2, 0.1], [1.0, -1.0, 0.4], worN=f, fs=1 / TS)
    np.testing.assert_allclose(h[1:], true[1:], rtol=0.02)


@pytest.mark.parametrize("halfwidth", [0.0, 0.05])
def test_attenuation_db_of_scaled_spectra(halfwidth):
    f = np.linspace(0.0, 2.5, 101)
    ref = 1.0 + np.exp(-(((f - 0.34) / 0.03) ** 2))
    gain_db = np.where(f < 0.3, 6.0, 12.0)
    shaped = ref * 10 ** (-gain_db / 10)
    out = attenuation_db(f, ref, shaped, [0.25, 0.34], halfwidth=halfwidth)
    np.testing.assert_allclose(out, [6.0, 12.0], atol=1e-9)
    # negative = amplification
    assert attenuation_db(f, shaped, ref, 0.34)[0] == pytest.approx(-12.0)


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda: psd([1.0, np.nan] * 10, TS), r"x must be finite"),
        (lambda: psd(np.ones(5), TS), r"x has 5 samples; spectra need at least 8"),
        (
            lambda: psd(np.ones(50), TS, nperseg=60),
            r"nperseg = 60 samples is outside the allowed range \[8 samples, 50 samples\]",
        ),
        (lambda: coherence(np.ones(50), np.ones(40), TS), r"same length, got 50 and 40"),
        (lambda: coherence(np.arange(100.0), np.arange(100.0), TS, nperseg=100), r"coherence needs at least 2"),
        (lambda: psd(np.ones(50), -0.1), r"sample_time = -0\.1 s is outside"),
        (lambda: transfer_estimate(np.zeros(100), np.arange(100.0), TS), r"no power"),
        (lambda: find_modes([0, 1, 2], [1, -1, 1]), r"P must be non-negative"),
        (lambda: find_modes([0, 2, 1], [1, 1, 1]), r"strictly increasing"),
        (lambda: find_modes(np.arange(10.0), np.ones(10), band=(20.0, 30.0)), r"holds no frequency bin"),
        (lambda: find_modes(np.arange(10.0), np.ones(10), quantity="dB"), r"unknown quantity 'dB'"),
        (lambda: attenuation_db([0, 1, 2], [1, 1, 1], [1, 0, 1], [1.0]), r"P_shaped must be positive"),
        (lambda: attenuation_db([0, 1, 2], [1, 1, 1], [1, 1, 1], [3.0]), r"frequency = 3\.0 Hz is outside"),
    ],
)
def test_bad_input_is_refused(call, match):
    with pytest.raises(InputError, match=match):
        call()
