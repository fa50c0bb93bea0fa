"""Designs that would silently be wrong are refused."""

import numpy as np
import pytest

from trms.control.lqg import design_lqg
from trms.control.metrics import step_metrics
from trms.control.shaping.shapers import shaper_for_modes, zv_shaper, zvd_shaper
from trms.errors import DesignError, InputError
from trms.experiments.plants import design_model


def test_q_zero_loses_integral_action_and_is_refused():
    with pytest.raises(DesignError, match=r"largest \|z\| = .*Q = 0 loses integral action"):
        design_lqg(design_model("1dof"), Q=0.0, R=125.0)
    design = design_lqg(design_model("1dof"), Q=1.0, R=125.0)
    assert np.abs(design.regulator_poles).max() < 1.0


@pytest.mark.parametrize(
    "make",
    [lambda f: zv_shaper(f, 0.05), lambda f: zvd_shaper(f, 0.05), lambda f: shaper_for_modes([(0.1, 0.1), (f, 0.05)])],
)
def test_a_shaper_for_a_mode_above_nyquist_is_refused(make):
    ts = 0.2
    with pytest.raises(InputError, match=r"at or above the Nyquist frequency 2.5 Hz"):
        make(10.0).at(ts)  # would collapse to the identity filter
    with pytest.raises(InputError, match="Nyquist"):
        make(2.5).at(ts)
    taps = make(1.0).at(ts).taps
    assert np.count_nonzero(taps) > 1


@pytest.mark.parametrize("time", [np.linspace(5.0, 0.0, 20), np.r_[0.0, 1.0, 1.0, np.arange(2.0, 19.0)]])
def test_step_metrics_need_increasing_time(time):
    with pytest.raises(InputError, match="time must increase strictly"):
        step_metrics(time, np.linspace(0, 1, 20), np.zeros(20), 0.0, 1.0)
