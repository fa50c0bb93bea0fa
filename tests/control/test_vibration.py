"""Residual vibration of impulse trains against closed forms, and the modes of a discrete model."""

import control
import numpy as np
import pytest

from trms.control.shaping import InputShaper, model_modes, shaper_for_modes, zv_shaper, zvd_shaper
from trms.reference import eq_3_11


def test_modes_of_eq_3_11_match_the_derived_values():
    ((f, zeta),) = model_modes(eq_3_11())
    assert f == pytest.approx(0.342, abs=5e-4)  # TARGETS.md: 0.342 Hz, damping 0.041
    assert zeta == pytest.approx(0.041, abs=5e-4)
    s = shaper_for_modes(model_modes(eq_3_11()))
    assert s.residual_vibration(f, zeta) < 1e-12


def test_undamped_zvd_band_is_symmetric_and_capped():
    # undamped ZVD: V(e) = cos^2(pi (1 + e) / 2) = sin^2(pi e / 2) -> 5 % at e = 2 asin(sqrt(0.05)) / pi
    low, high = zvd_shaper(0.25, 0.0).robust_band(0.25, 0.0)
    edge = 2.0 * np.arcsin(np.sqrt(0.05)) / np.pi
    assert (low, high) == pytest.approx((-edge, edge), abs=1e-9)
    assert zvd_shaper(0.25, 0.0).robust_band(0.25, 0.0, limit=1.0) == pytest.approx((-0.95, 0.95))


@pytest.mark.parametrize("f, zeta", [(0.25, 0.0), (0.34, 0.041), (1.0, 0.5)])
def test_one_unit_impulse_leaves_all_the_vibration(f, zeta):
    assert InputShaper(np.array([1.0]), np.array([0.0]), "unit").residual_vibration(f, zeta) == pytest.approx(1.0)


@pytest.mark.parametrize("gap", [0.3, 1.0, 1.7, 2.0, 3.1])
def test_two_equal_impulses_leave_the_cosine_of_half_the_phase_between_them(gap):
    # undamped: C = (1 + cos wT) / 2, S = sin(wT) / 2, so V = |cos(w T / 2)|
    f = 0.25
    s = InputShaper(np.array([0.5, 0.5]), np.array([0.0, gap]), "pair")
    assert s.residual_vibration(f, 0.0) == pytest.approx(abs(np.cos(np.pi * f * gap)), abs=1e-12)


def test_the_zv_constants_of_a_damped_mode_are_the_closed_forms():
    # zeta = 0.6: sqrt(1 - zeta^2) = 0.8, K = exp(-0.6 pi / 0.8), the damped period 1 / (0.25 x 0.8) = 5 s
    s = zv_shaper(0.25, 0.6)
    k = np.exp(-0.75 * np.pi)
    assert s.amplitudes == pytest.approx([1.0 / (1.0 + k), k / (1.0 + k)], abs=1e-15)
    assert s.times == pytest.approx([0.0, 2.5], abs=1e-15)


def test_model_modes_keeps_the_oscillatory_poles_below_the_nyquist_fraction():
    ts = 0.1
    w1, w2, w3 = 2 * np.pi * 0.3, 2 * np.pi * 1.2, 2 * np.pi * 4.5  # the last above 0.8 x Nyquist = 4 Hz
    g = (
        control.tf([w1 * w1], [1.0, 2 * 0.1 * w1, w1 * w1])
        * control.tf([w2 * w2], [1.0, 2 * 0.02 * w2, w2 * w2])
        * control.tf([w3 * w3], [1.0, 2 * 0.05 * w3, w3 * w3])
        * control.tf([2.0], [1.0, 2.0])  # a real pole: no mode
    )
    modes = model_modes(control.c2d(g, ts))
    assert len(modes) == 2
    assert modes[0] == pytest.approx((0.3, 0.1), abs=1e-9)
    assert modes[1] == pytest.approx((1.2, 0.02), abs=1e-9)
