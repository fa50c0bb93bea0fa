"""Closed-loop damping of the plant's mode: a damping feedback raises it, a cancelling design keeps the plant's."""

import control
import numpy as np
import pytest

from trms.control.damping import MIN_DAMPING, closed_loop_modes, discrete_modes, mode_damping
from trms.control.hinf import design_mixsyn, pitch_weights
from trms.errors import InputError
from trms.worlds import design_model


def _oscillator(f_hz: float, zeta: float, ts: float) -> control.StateSpace:
    w = 2 * np.pi * f_hz
    return control.c2d(control.ss(control.tf([w * w], [1.0, 2 * zeta * w, w * w])), ts)


@pytest.mark.parametrize("f_hz, zeta, ts", [(0.34, 0.041, 0.2), (0.1, 0.03, 0.1), (1.0, 0.2, 0.05)])
def test_the_modes_of_a_sampled_oscillator_come_back(f_hz, zeta, ts):
    (m,) = discrete_modes(_oscillator(f_hz, zeta, ts))
    assert m.frequency_hz == pytest.approx(f_hz, rel=1e-9) and m.damping == pytest.approx(zeta, rel=1e-9)


def test_zero_feedback_leaves_the_plant_mode_and_a_small_gain_moves_it_continuously():
    G = _oscillator(0.34, 0.041, 0.2)
    none = mode_damping(G, control.ss([], [], [], [[0.0]], 0.2))
    assert none.closed.damping == pytest.approx(0.041, rel=1e-9)
    # a little positive velocity-like feedback (a lag of about -150 deg at the mode) adds damping smoothly
    lag = control.ss(control.tf([0.05], [1.0, -0.7], 0.2))
    small, large = mode_damping(G, lag), mode_damping(G, 2 * lag)
    assert abs(small.closed.frequency_hz - 0.34) < 0.05
    assert small.closed.damping != pytest.approx(0.041)
    assert (small.closed.damping - 0.041) * (large.closed.damping - 0.041) > 0  # the same direction, further


def test_mixed_sensitivity_cancels_the_pitch_mode_and_the_disturbance_channel_damps_it():
    """Known behaviour (Skogestad and Postlethwaite, ch. 9.3): S/KS designs cancel lightly damped plant poles."""
    model = design_model("1dof")
    W1, W2 = pitch_weights()
    plain = mode_damping(model, design_mixsyn(model, W1, W2).discrete_controller)
    assert abs(plain.closed.damping - plain.plant.damping) < 0.01
    assert abs(plain.closed.frequency_hz - plain.plant.frequency_hz) < 0.005
    damped = mode_damping(model, design_mixsyn(model, W1, W2, Wd=control.tf([0.5], [1.0])).discrete_controller)
    assert damped.meets() and damped.closed.damping > 3 * plain.plant.damping
    assert not plain.meets() and plain.meets(0.04)


def test_the_closed_loop_modes_of_a_static_gain_match_the_continuous_theory():
    G = control.c2d(control.ss(control.tf([1.0], [1.0, 0.2, 4.0])), 0.01)
    (m,) = closed_loop_modes(G, control.ss([], [], [], [[5.0]], 0.01))
    assert m.frequency_hz == pytest.approx(3.0 / (2 * np.pi), rel=2e-3)


def test_refusals_are_one_line():
    lag = control.ss([[0.9]], [[0.1]], [[1.0]], [[0.0]], 0.1)
    with pytest.raises(InputError, match="model has no oscillatory mode to follow"):
        mode_damping(lag, control.ss([], [], [], [[1.0]], 0.1))
    with pytest.raises(InputError, match="frequency_hz = 9.0 Hz is outside"):
        mode_damping(_oscillator(0.34, 0.04, 0.2), control.ss([], [], [], [[1.0]], 0.2), frequency_hz=9.0)
    with pytest.raises(InputError, match="discrete python-control StateSpace"):
        discrete_modes(control.ss([[-1.0]], [[1.0]], [[1.0]], [[0.0]]))
    assert MIN_DAMPING == 0.1
