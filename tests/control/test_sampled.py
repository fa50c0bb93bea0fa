"""Input shapers on a sample grid: an exact zero at the discrete pole, the documented rounding and robustness."""

import control
import numpy as np
import pytest
from scipy.signal import lfilter

from trms.control.shaping import InputShaper, shaper_for_modes, zv_shaper, zvd_shaper
from trms.control.shaping.sampled import SampledShaper, discrete_shaper
from trms.control.shaping.vibration import MAX_SHAPER_DAMPING, SHAPER_KINDS
from trms.errors import InputError


def test_sampled_shaper_leaves_no_residual_vibration_on_the_grid():
    # A 0.25 Hz undamped mode at Ts = 0.2 s: half a period is exactly 10 samples, so the sampled
    # ZVD equals the continuous one and the zero-order-hold response settles exactly.
    ts, f = 0.2, 0.25
    wn = 2 * np.pi * f
    mode = control.c2d(control.tf([wn**2], [1, 0, wn**2]), ts, "zoh")
    sampled = zvd_shaper(f, 0.0).at(ts)
    assert sampled.taps.size == 21
    step = np.ones(200)
    _, y = control.forced_response(mode, T=np.arange(200) * ts, U=sampled.apply(step))
    assert np.abs(y[21:] - 1.0).max() < 1e-9
    _, y_raw = control.forced_response(mode, T=np.arange(200) * ts, U=step)
    assert np.abs(y_raw[21:] - 1.0).max() > 0.9  # unshaped: full oscillation


def test_shaper_apply_keeps_rest_level_and_columns():
    s = zv_shaper(0.25, 0.0).at(0.2)
    x = np.column_stack([np.ones(30), np.full(30, 2.0)])
    y = s.apply(x, initial=[0.0, 2.0])
    assert y[:10, 0] == pytest.approx(0.5) and y[10:, 0] == pytest.approx(1.0)
    assert y[:, 1] == pytest.approx(2.0)


#: (f Hz, zeta, Ts s): the TRMS pitch mode at the rig's 0.2 s (Td / 2 = 7.36 samples), an undamped and a
#: damped mode whose half damped period is exactly 10 and 7 samples, a heavily damped fast mode, a slow
#: mode on a coarse grid, modes one or two samples from Nyquist, and a damping just below the limit.
GRID_CASES = [
    (0.34, 0.041, 0.2),
    (0.25, 0.0, 0.2),
    (1.0 / (1.4 * np.sqrt(1.0 - 0.1**2)), 0.1, 0.1),
    (1.0, 0.5, 0.05),
    (0.1, 0.2, 0.3),
    (2.0, 0.3, 0.2),
    (2.4, 0.0, 0.2),
    (0.34, 0.98, 0.2),
]


def _discrete_pole(f, zeta, ts):
    """The mode's discrete pole ``exp(s Ts)``, ``s = -zeta w + j w sqrt(1 - zeta^2)``."""
    w = 2.0 * np.pi * f
    return np.exp((-zeta * w + 1j * w * np.sqrt(1.0 - zeta * zeta)) * ts)


def _fir_at(taps, z):
    """``H(z) = sum h_k z^-k`` and ``dH/dz``, each relative to the sum of the magnitudes of its terms."""
    k = np.arange(taps.size)
    terms, dterms = taps * z ** (-k), -k * taps * z ** (-k - 1.0)
    return abs(terms.sum()) / np.abs(terms).sum(), abs(dterms.sum()) / np.abs(dterms).sum()


@pytest.mark.parametrize("f, zeta, ts", GRID_CASES)
def test_grid_shaper_has_an_exact_zero_at_the_discrete_pole(f, zeta, ts):
    p = _discrete_pole(f, zeta, ts)
    zv, zvd = discrete_shaper([(f, zeta)], ts, kind="zv"), discrete_shaper([(f, zeta)], ts, kind="zvd")
    h_zv, dh_zv = _fir_at(zv.taps, p)
    h_zvd, dh_zvd = _fir_at(zvd.taps, p)
    assert h_zv < 1e-12 and h_zvd < 1e-12
    assert dh_zvd < 1e-12  # ZVD: a double zero
    assert dh_zv > 1e-2  # ZV: a simple one (the derivative check can fail)
    for s in (zv, zvd):
        assert s.taps.sum() == pytest.approx(1.0, abs=1e-12)  # unit static gain
        assert s.taps.min() >= 0.0
        assert s.residual_vibration(f, zeta) < 1e-12
    # the FIR of InputShaper.at is the same design
    np.testing.assert_array_equal(zvd_shaper(f, zeta).at(ts).taps, zvd.taps)
    np.testing.assert_array_equal(zv_shaper(f, zeta).at(ts).taps, zv.taps)
    # at most one (ZV) or two (ZVD) samples longer than the continuous shaper
    assert zv.duration <= zv_shaper(f, zeta).duration + ts + 1e-12
    assert zvd.duration <= zvd_shaper(f, zeta).duration + 2 * ts + 1e-12


@pytest.mark.parametrize("f, zeta, ts, n", [(0.25, 0.0, 0.2, 10), (1.0 / (1.4 * np.sqrt(1.0 - 0.1**2)), 0.1, 0.1, 7)])
def test_grid_shaper_is_the_sampled_continuous_one_when_ts_divides_the_half_period(f, zeta, ts, n):
    k = np.exp(-zeta * np.pi / np.sqrt(1.0 - zeta**2))
    zv = zv_shaper(f, zeta).at(ts)
    assert np.flatnonzero(zv.taps).tolist() == [0, n]
    assert zv.taps[[0, n]] == pytest.approx(np.array([1.0, k]) / (1.0 + k), abs=1e-12)
    np.testing.assert_allclose(zv.taps, zv_shaper(f, zeta).rounded(ts).taps, rtol=0.0, atol=1e-12)
    np.testing.assert_allclose(zvd_shaper(f, zeta).at(ts).taps, zvd_shaper(f, zeta).rounded(ts).taps, atol=1e-12)


def test_grid_shaper_splits_the_second_impulse_when_ts_does_not_divide_the_half_period():
    # 0.34 Hz, zeta 0.041: Td / 2 = 1.4718 s = 7.36 samples of 0.2 s, so the ZV's second impulse sits on 7 and 8
    zv = zv_shaper(0.34, 0.041).at(0.2)
    assert np.flatnonzero(zv.taps).tolist() == [0, 7, 8]
    assert zv.duration == pytest.approx(1.6)


@pytest.mark.parametrize("design, printed", [(zv_shaper, 0.072), (zvd_shaper, 0.093)])
def test_rounded_shaper_leaves_the_documented_vibration_where_the_grid_one_leaves_none(design, printed):
    f, zeta, ts = 0.34, 0.041, 0.2
    s = design(f, zeta)
    assert s.rounded(ts).residual_vibration(f, zeta) == pytest.approx(printed, abs=5e-4)  # the module docstring
    grid = s.at(ts).residual_vibration(f, zeta)
    assert grid <= 1e-12 and grid <= 0.02  # the target: at most 2 % on the rig's grid


@pytest.mark.parametrize("kind", SHAPER_KINDS)
@pytest.mark.parametrize("f, zeta, ts", [(0.34, 0.041, 0.2), (1.0, 0.5, 0.05), (2.0, 0.3, 0.2)])
def test_mode_driven_through_the_grid_shaper_rests_once_the_shaper_ends(kind, f, zeta, ts):
    w = 2.0 * np.pi * f
    mode = control.c2d(control.tf([w * w], [1.0, 2.0 * zeta * w, w * w]), ts, "zoh")
    den = np.ravel(mode.den[0][0])
    num = np.concatenate([np.zeros(den.size - np.ravel(mode.num[0][0]).size), np.ravel(mode.num[0][0])])
    shaper = discrete_shaper([(f, zeta)], ts, kind=kind)
    n, m = 400, shaper.taps.size
    step = np.ones(n)
    y = lfilter(num, den, shaper.apply(step))
    assert np.abs(y[m:] - 1.0).max() < 1e-9  # one sample of ZOH delay after the last tap: at rest
    rounded = (zv_shaper if kind == "zv" else zvd_shaper)(f, zeta).rounded(ts)
    y_rounded = lfilter(num, den, rounded.apply(step))
    raw = lfilter(num, den, step)
    if zeta < 0.1:  # the lightly damped mode rings on unshaped and with the rounded shaper
        assert np.abs(raw[m:] - 1.0).max() > 0.5
        assert np.abs(y_rounded[m:] - 1.0).max() > 0.03


def _band_percent(band):
    return tuple(round(100.0 * e, 1) for e in band)


def test_robust_band_reproduces_the_documented_numbers():
    f, zeta, ts = 0.34, 0.041, 0.2
    zv, zvd = zv_shaper(f, zeta), zvd_shaper(f, zeta)
    assert _band_percent(zv.robust_band(f, zeta)) == (-3.4, 3.4)
    assert _band_percent(zv.at(ts).robust_band(f, zeta)) == (-3.5, 3.5)
    assert _band_percent(zvd.robust_band(f, zeta)) == (-15.2, 15.5)
    assert _band_percent(zvd.at(ts).robust_band(f, zeta)) == (-15.5, 15.9)
    assert zvd.duration == pytest.approx(2.94, abs=5e-3) and zvd.at(ts).duration == pytest.approx(3.2)
    for s in (zv.rounded(ts), zvd.rounded(ts)):
        assert np.isnan(s.robust_band(f, zeta)).all()  # above 5 % at the design frequency itself


@pytest.mark.parametrize("kind", SHAPER_KINDS)
def test_robust_band_edges_are_where_the_vibration_reaches_the_limit(kind):
    f, zeta, limit = 0.34, 0.041, 0.05
    s = discrete_shaper([(f, zeta)], 0.2, kind=kind)
    low, high = s.robust_band(f, zeta, limit)
    assert low < 0.0 < high
    for e in (low, high):
        assert s.residual_vibration(f * (1.0 + e), zeta) == pytest.approx(limit, abs=1e-9)
    inside = np.linspace(low, high, 41)[1:-1]
    assert max(s.residual_vibration(f * (1.0 + e), zeta) for e in inside) < limit
    assert s.residual_vibration(f * (1.0 + 1.02 * high), zeta) > limit


@pytest.mark.parametrize("kind", SHAPER_KINDS)
def test_multi_mode_shaper_on_the_grid_cancels_every_mode(kind):
    modes, ts = [(0.25, 0.05), (0.34, 0.041), (1.1, 0.2)], 0.2
    taps = shaper_for_modes(modes, kind=kind).at(ts).taps
    np.testing.assert_array_equal(taps, discrete_shaper(modes, ts, kind=kind).taps)
    assert taps.min() >= 0.0 and taps.sum() == pytest.approx(1.0, abs=1e-12)
    for f, zeta in modes:
        h, dh = _fir_at(taps, _discrete_pole(f, zeta, ts))
        assert h < 1e-12
        assert dh < 1e-12 if kind == "zvd" else dh > 1e-6


def test_a_sequence_without_design_is_rounded_and_a_convolution_keeps_its_kinds():
    mixed = zv_shaper(0.25, 0.05).convolve(zvd_shaper(0.34, 0.041))
    assert mixed.kinds == ("zv", "zvd")
    grid = mixed.at(0.2)
    for f, zeta in mixed.modes:
        assert grid.residual_vibration(f, zeta) < 1e-12
    plain = InputShaper(mixed.amplitudes, mixed.times, "no design")
    np.testing.assert_array_equal(plain.at(0.2).taps, plain.rounded(0.2).taps)


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda: zvd_shaper(0.34, 0.9999999), r"damping = 0.9999999 is outside the allowed range \[0, 0.99\)"),
        (lambda: zv_shaper(0.34, MAX_SHAPER_DAMPING), r"damping = 0.99 is outside the allowed range \[0, 0.99\)"),
        (lambda: zvd_shaper(0.34, float("nan")), r"damping = nan is outside the allowed range \[0, 0.99\)"),
        (lambda: discrete_shaper([(0.34, 0.995)], 0.2), r"damping = 0.995 is outside"),
        (lambda: zvd_shaper(0.34, 0.041).at(1.5), r"0.34 Hz, at or above the Nyquist frequency 0.333333 Hz"),
        (lambda: discrete_shaper([(0.34, 0.041), (3.0, 0.1)], 0.2), r"3 Hz, at or above the Nyquist frequency 2.5"),
        (lambda: zvd_shaper(0.34, 0.041).rounded(2.0), r"at or above the Nyquist frequency 0.25 Hz"),
        (lambda: discrete_shaper([(0.34, 0.041)], 0.2, kind="ei"), r"unknown shaper kind 'ei'; allowed: 'zv', 'zvd'"),
        (lambda: discrete_shaper([(0.34, 0.041)], 0.2, kind="ZVD"), r"unknown shaper kind 'ZVD'"),
        (lambda: discrete_shaper([(0.34, 0.041)], 0.2, kind=None), r"unknown shaper kind None"),
        (lambda: discrete_shaper([(0.34, 0.041)], -0.2), r"sample_time = -0.2 s is outside"),
        (lambda: discrete_shaper([], 0.2), r"at least one"),
        (lambda: discrete_shaper("0.34", 0.2), r"modes must be a sequence of \(frequency Hz, damping\) pairs"),
        (
            lambda: InputShaper(np.array([0.5, 0.5]), np.array([0.0, 1.0]), "x", ((0.5, 0.0),), ("zz",)),
            r"kinds must hold one of \('zv', 'zvd'\) per mode",
        ),
        (
            lambda: InputShaper(np.array([0.5, 0.5]), np.array([0.0, 1.0]), "x", (), ("zv",)),
            r"kinds must hold one of .* per mode \(0 modes\)",
        ),
        (lambda: zv_shaper(0.34, 0.041).robust_band(0.34, 0.041, limit=0.0), r"limit = 0.0 is outside"),
        (lambda: SampledShaper(np.array([0.5, 0.6]), 0.2, "x"), r"taps must be non-empty and sum to 1"),
    ],
)
def test_bad_grid_shaper_input_is_one_clear_line(call, match):
    with pytest.raises(InputError, match=match) as info:
        call()
    assert "\n" not in str(info.value)
