"""Step responses read on known truth: a first-order lag behind a dead time."""

import numpy as np
import pytest

from trms.measurement.step_response import crossing_figures, step_fit_percent, tangent_figures

TS = 0.01


def _lag(dead: float, tau: float, duration: float = 60.0) -> tuple[np.ndarray, np.ndarray]:
    t = np.arange(0.0, duration, TS)
    return t, np.where(t > dead, 1.0 - np.exp(-(t - dead) / tau), 0.0)


@pytest.mark.parametrize("dead, tau", [(0.3, 2.0), (1.0, 5.0)])
def test_the_tangent_reads_a_first_order_lags_dead_time_and_time_constant(dead, tau):
    t, y = _lag(dead, tau)
    got_dead, got_tau = tangent_figures(t, y)
    assert got_dead == pytest.approx(dead, abs=2 * TS) and got_tau == pytest.approx(tau, rel=0.01)


def test_the_crossings_are_at_5_and_63_percent():
    t, y = _lag(0.5, 3.0)
    delay, tau = crossing_figures(t, y, final=1.0)
    assert delay == pytest.approx(0.5 - 3.0 * np.log(0.95), abs=TS)
    assert delay + tau == pytest.approx(0.5 - 3.0 * np.log(0.37), abs=TS)


def test_the_step_fit_is_100_for_the_same_step_and_drops_with_a_gain_error():
    t, y = _lag(0.5, 3.0)
    assert step_fit_percent(t, y, y) == 100.0 and step_fit_percent(t, 0.8 * y, y) < step_fit_percent(t, 0.9 * y, y)
