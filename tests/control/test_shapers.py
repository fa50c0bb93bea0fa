"""Input shapers: zero residual vibration at the design mode, robustness of ZVD, sampled use."""

import control
import numpy as np
import pytest

from trms.control.shaping import InputShaper, model_modes, shaper_for_modes, zv_shaper, zvd_shaper
from trms.errors import InputError
from trms.reference import eq_3_11

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


def test_convolved_shaper_cancels_both_modes_and_sampling_moves_the_zero():
    both = shaper_for_modes([(0.25, 0.05), (0.34, 0.041)], kind="zv")
    assert both.residual_vibration(0.25, 0.05) < 1e-12 and both.residual_vibration(0.34, 0.041) < 1e-12
    assert both.times.size == 4
    # on the 0.2 s grid a 0.34 Hz shaper's impulses move by up to 0.1 s; ZVD keeps the leftover small
    grid = zvd_shaper(0.34, 0.041).at(0.2).as_shaper()
    assert 0.0 < grid.residual_vibration(0.34, 0.041) < 0.15


def test_modes_of_eq_3_11_match_the_derived_values():
    ((f, zeta),) = model_modes(eq_3_11())
    assert f == pytest.approx(0.342, abs=5e-4)  # TARGETS.md: 0.342 Hz, damping 0.041
    assert zeta == pytest.approx(0.041, abs=5e-4)
    s = shaper_for_modes(model_modes(eq_3_11()))
    assert s.residual_vibration(f, zeta) < 1e-12


def test_shaper_apply_keeps_rest_level_and_columns():
    s = zv_shaper(0.25, 0.0).at(0.2)
    x = np.column_stack([np.ones(30), np.full(30, 2.0)])
    y = s.apply(x, initial=[0.0, 2.0])
    assert y[:10, 0] == pytest.approx(0.5) and y[10:, 0] == pytest.approx(1.0)
    assert y[:, 1] == pytest.approx(2.0)


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
