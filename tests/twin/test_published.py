"""Feedback's published model: its static pitch is where its own steps settle, its static gain that curve's slope."""

import numpy as np
import pytest

from trms.twin.published import PUBLISHED, hover, main_thrust_torque, pitch_step, static_gain, static_pitch


@pytest.mark.parametrize("dv", [-0.5, 0.5])
def test_the_static_pitch_is_where_a_step_settles(dv):
    assert pitch_step(dv, 120.0).final == pytest.approx(float(static_pitch(dv)), abs=2e-3)


def test_the_static_gain_is_the_slope_of_the_static_pitch():
    x, h = np.array([-1.0, -0.2, 0.0, 0.4]), 1e-5
    slope = (static_pitch(x + h) - static_pitch(x - h)) / (2 * h)
    np.testing.assert_allclose(static_gain(x), slope, rtol=1e-6)


def test_past_the_fold_no_pitch_holds():
    volts, _ = hover()
    fold = (-PUBLISHED["b1"] + np.sqrt(PUBLISHED["b1"] ** 2 + 4 * PUBLISHED["a1"] * PUBLISHED["Mg"])) / (
        2 * PUBLISHED["a1"]
    ) * PUBLISHED["T10"] / PUBLISHED["k1"] - volts
    assert float(main_thrust_torque(PUBLISHED["k1"] * (volts + fold) / PUBLISHED["T10"])) == pytest.approx(
        PUBLISHED["Mg"]
    )
    assert np.isfinite(static_pitch(fold - 1e-6)) and np.isnan(static_pitch(fold + 1e-6))
    assert np.isnan(static_gain(fold + 1e-6))
