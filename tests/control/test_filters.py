"""Command filters: known frequency-response truths, causal application, error paths."""

import numpy as np
import pytest
from scipy import signal

from trms.control.shaping import (
    CommandFilter,
    bands_around,
    butterworth_bandstop,
    butterworth_lowpass,
    elliptic_bandstop,
    multiband_bandstop,
)
from trms.errors import InputError

# Bilinear design with pre-warping puts the -3 dB points exactly at the design edges;
# 1e-9 dB leaves room for floating point only.
DB_TOL = 1e-9
MINUS_3DB = 10 * np.log10(0.5)


@pytest.mark.parametrize("order", [1, 2, 3, 5])
@pytest.mark.parametrize("cutoff, ts", [(0.1, 0.2), (0.2, 0.2), (0.3, 0.2), (0.05, 0.1)])
def test_lowpass_is_minus_3db_at_cutoff_and_unity_at_dc(order, cutoff, ts):
    f = butterworth_lowpass(order, cutoff, ts)
    assert f.gain_db([cutoff])[0] == pytest.approx(MINUS_3DB, abs=DB_TOL)
    assert f.dc_gain() == pytest.approx(1.0, abs=1e-12)
    assert f.order == order
    # maximally flat and monotone: the gain falls with frequency
    g = f.gain_db(np.linspace(0.0, 0.5 / ts, 200))
    assert np.all(np.diff(g) <= 1e-9)


@pytest.mark.parametrize("order", [1, 2, 3])
@pytest.mark.parametrize("band", [(0.2, 0.4), (0.15, 0.35), (0.25, 0.4)])
def test_bandstop_edges_centre_and_passbands(order, band):
    ts = 0.2
    f = butterworth_bandstop(order, band, ts)
    assert f.gain_db(list(band)) == pytest.approx([MINUS_3DB] * 2, abs=DB_TOL)
    assert f.dc_gain() == pytest.approx(1.0, abs=1e-12)
    assert abs(f.frequency_response([0.5 / ts])[0]) == pytest.approx(1.0, abs=1e-9)
    # the notch (infinite attenuation) sits at the pre-warped geometric centre
    w = [np.tan(np.pi * b * ts) for b in band]
    centre = np.arctan(np.sqrt(w[0] * w[1])) / (np.pi * ts)
    assert abs(f.frequency_response([centre])[0]) < 1e-6
    assert f.order == 2 * order


def test_elliptic_bandstop_meets_its_ripple_and_attenuation():
    f = elliptic_bandstop(2, (0.25, 0.4), 0.1, passband_ripple_db=1.0, stopband_attenuation_db=40.0)
    assert f.gain_db([0.25, 0.4]) == pytest.approx([-1.0, -1.0], abs=1e-6)
    pass_f = np.r_[np.linspace(0, 0.25, 50), np.linspace(0.4, 5.0, 200)]
    assert np.all(f.gain_db(pass_f) >= -1.0 - 1e-6)
    # somewhere inside the band the 40 dB floor is reached, and never exceeded upward inside it
    inside = f.gain_db(np.linspace(0.3, 0.34, 200))
    assert inside.min() < -40.0 + 1e-6


def test_multiband_is_the_product_of_its_bands():
    ts = 0.2
    bands = bands_around([0.25, 0.34], 0.2)
    assert bands == [pytest.approx((0.15, 0.35)), pytest.approx((0.24, 0.44))]
    both = multiband_bandstop(2, bands, ts)
    parts = [butterworth_bandstop(2, b, ts) for b in bands]
    fq = np.linspace(0.0, 2.5, 97)
    assert both.frequency_response(fq) == pytest.approx(
        parts[0].frequency_response(fq) * parts[1].frequency_response(fq), abs=1e-12
    )
    assert both.order == 8
    chained = parts[0].then(parts[1])
    assert chained.frequency_response(fq) == pytest.approx(both.frequency_response(fq), abs=1e-12)
    ell = multiband_bandstop(2, [(0.05, 0.15), (0.25, 0.4)], 0.1, kind="elliptic", passband_ripple_db=0.5)
    e1 = elliptic_bandstop(2, (0.05, 0.15), 0.1, passband_ripple_db=0.5)
    e2 = elliptic_bandstop(2, (0.25, 0.4), 0.1, passband_ripple_db=0.5)
    fq = np.linspace(0.0, 5.0, 101)
    assert ell.gain_db(fq) == pytest.approx(e1.gain_db(fq) + e2.gain_db(fq), abs=1e-9)


def test_apply_matches_scipy_transfer_function_filtering():
    rng = np.random.default_rng(3)
    x = rng.standard_normal(300)
    f = butterworth_lowpass(3, 0.1, 0.2)
    b, a = signal.butter(3, 0.1, fs=5.0)
    assert f.apply(x) == pytest.approx(signal.lfilter(b, a, x), abs=1e-10)


def test_apply_is_causal_columnwise_and_respects_rest_level():
    f = butterworth_bandstop(2, (0.2, 0.4), 0.2)
    x = np.zeros((100, 2))
    x[40:, 0] = 1.0
    x[:, 1] = 0.3
    y = f.apply(x, initial=[0.0, 0.3])
    assert np.all(y[:40, 0] == 0.0)  # nothing before the step
    assert y[:, 1] == pytest.approx(np.full(100, 0.3), abs=1e-15)  # at rest stays at rest
    assert f.apply(x[:, 0]).shape == (100,)
    assert f.apply(x[:, 0]) == pytest.approx(y[:, 0], abs=1e-15)


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda: butterworth_lowpass(2, 2.5, 0.2), r"cutoff = 2.5 Hz is outside the allowed range \(0 Hz, 2.5 Hz\)"),
        (lambda: butterworth_lowpass(2, 0.0, 0.2), "cutoff = 0.0 Hz is outside"),
        (lambda: butterworth_lowpass(0, 0.1, 0.2), r"order = 0 must be an integer in \[1, 12\]"),
        (lambda: butterworth_lowpass(1.5, 0.1, 0.2), "order = 1.5"),
        (lambda: butterworth_lowpass(2, 0.1, -0.2), "sample_time = -0.2 s is outside"),
        (lambda: butterworth_bandstop(2, (0.4, 0.2), 0.2), "must have low edge < high edge"),
        (lambda: butterworth_bandstop(2, 0.3, 0.2), "band must be a pair"),
        (
            lambda: elliptic_bandstop(2, (0.2, 0.4), 0.2, passband_ripple_db=0.0),
            "passband_ripple_db = 0.0 dB is outside",
        ),
        (
            lambda: elliptic_bandstop(2, (0.2, 0.4), 0.2, stopband_attenuation_db=0.5),
            "stopband_attenuation_db = 0.5 dB",
        ),
        (lambda: multiband_bandstop(2, [], 0.2), "at least one"),
        (lambda: multiband_bandstop(2, [(0.1, 0.2)], 0.2, kind="cheby"), "unknown band-stop kind 'cheby'"),
        (lambda: multiband_bandstop(2, [(0.1, 0.2)], 0.2, passband_ripple_db=1.0), "apply only to kind='elliptic'"),
        (lambda: bands_around([0.05], 0.2), "centre frequency = 0.05 Hz is outside"),
        (lambda: butterworth_lowpass(2, 0.1, 0.2).then(butterworth_lowpass(2, 0.1, 0.1)), "different sample times"),
        (lambda: butterworth_lowpass(2, 0.1, 0.2).apply([1.0, np.nan]), "command must be finite"),
        (lambda: butterworth_lowpass(2, 0.1, 0.2).apply(np.zeros((3, 2, 2))), r"shape \(N,\) or \(N, m\)"),
        (lambda: butterworth_lowpass(2, 0.1, 0.2).gain_db([3.0]), r"frequencies must lie in \[0, 2.5\] Hz"),
        (lambda: CommandFilter(np.zeros((1, 6)), 0.2, "bad"), "a0 != 0"),
    ],
)
def test_bad_filter_input_is_refused(call, match):
    with pytest.raises(InputError, match=match):
        call()
