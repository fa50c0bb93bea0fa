"""Input shapers with impulses at any time: zero residual vibration at the design mode, ZVD's flatness, convolution."""

import control
import numpy as np
import pytest

from trms.control.shaping import InputShaper, model_modes, shaper_for_modes, zv_shaper, zvd_shaper
from trms.errors import InputError

MODES = [(0.25, 0.0), (0.34, 0.041), (0.1, 0.2), (1.0, 0.5)]


@pytest.mark.parametrize("f, zeta", MODES)
@pytest.mark.parametrize("design", [zv_shaper, zvd_shaper])
def test_shaper_cancels_its_mode(design, f, zeta):
    s = design(f, zeta)
    assert s.amplitudes.sum() == pytest.approx(1.0, abs=1e-12)
    assert s.residual_vibration(f, zeta) < 1e-12
    assert zv_shaper(f, zeta).residual_vibration(2 * f, zeta) > 0.1  # not a trivial zero everywhere


def test_undamped_zv_is_two_half_impulses_half_a_period_apart():
    s = zv_shaper(0.25, 0.0)
    assert s.amplitudes == pytest.approx([0.5, 0.5])
    assert s.times == pytest.approx([0.0, 2.0])


@pytest.mark.parametrize("f, zeta", MODES)
def test_zvd_is_flat_to_frequency_error_where_zv_is_not(f, zeta):
    # V(f (1 + e)) is O(e) for ZV and O(e^2) for ZVD: halving e halves V for ZV, quarters it for ZVD.
    zv, zvd = zv_shaper(f, zeta), zvd_shaper(f, zeta)
    e = 1e-3
    assert zv.residual_vibration(f * (1 + e), zeta) / zv.residual_vibration(f * (1 + e / 2), zeta) == pytest.approx(
        2.0, rel=0.01
    )
    assert zvd.residual_vibration(f * (1 + e), zeta) / zvd.residual_vibration(f * (1 + e / 2), zeta) == pytest.approx(
        4.0, rel=0.01
    )


def test_convolved_shaper_cancels_both_modes_and_sampling_moves_the_zero():
    both = shaper_for_modes([(0.25, 0.05), (0.34, 0.041)], kind="zv")
    assert both.residual_vibration(0.25, 0.05) < 1e-12 and both.residual_vibration(0.34, 0.041) < 1e-12
    assert both.times.size == 4
    # rounded to the 0.2 s grid a 0.34 Hz shaper's impulses move by up to 0.1 s and the zero moves off the mode
    rounded = zvd_shaper(0.34, 0.041).rounded(0.2)
    assert 0.05 < rounded.residual_vibration(0.34, 0.041) < 0.15
    # the taps' vibration is that of the same impulses as a continuous shaper
    nz = np.flatnonzero(rounded.taps)
    same = InputShaper(rounded.taps[nz], (nz - nz[0]) * 0.2, "taps as impulses")
    assert rounded.residual_vibration(0.34, 0.041) == pytest.approx(same.residual_vibration(0.34, 0.041), abs=1e-15)
    assert rounded.robust_band(0.34, 0.041, 0.2) == pytest.approx(same.robust_band(0.34, 0.041, 0.2), abs=1e-12)


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda: zv_shaper(0.0, 0.1), "frequency = 0.0 Hz is outside"),
        (lambda: zvd_shaper(0.3, 1.0), "damping = 1.0 is outside"),
        (lambda: zvd_shaper(0.3, -0.1), "damping = -0.1 is outside"),
        (lambda: shaper_for_modes([]), "at least one"),
        (lambda: shaper_for_modes([(0.3, 0.1)], kind="ei"), "unknown shaper kind 'ei'"),
        (lambda: InputShaper(np.array([0.5, 0.4]), np.array([0.0, 1.0]), "x"), "must sum to 1"),
        (lambda: InputShaper(np.array([0.5, 0.5]), np.array([1.0, 0.0]), "x"), "start at 0 s and not decrease"),
        (lambda: zv_shaper(0.3, 0.1).at(0.0), "sample_time = 0.0 s is outside"),
        (lambda: model_modes(control.tf([1], [1, 1])), "discrete-time"),
    ],
)
def test_bad_shaper_input_is_refused(call, match):
    with pytest.raises(InputError, match=match):
        call()
