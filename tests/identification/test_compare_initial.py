"""compare(initial=...): least-squares initial state (MATLAB's default) against zero and measured."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.signal

from trms.errors import InputError
from trms.identification import compare, narx_rbf, oe

TS = 0.05
# A 6th-order plant: three lightly damped resonances (poles at radius 0.97, 0.95, 0.9).
POLES = [0.97 * np.exp(1j * 0.12), 0.95 * np.exp(1j * 0.35), 0.9 * np.exp(1j * 0.8)]
F = np.real(np.poly(np.concatenate([POLES, np.conj(POLES)])))
B = np.array([0.0, 0.02, 0.01, -0.01, 0.005])


def _data(n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    u = np.repeat(np.sign(rng.standard_normal(n // 4 + 1)), 4)[:n]
    return scipy.signal.lfilter(B, F, u) + 0.01 * rng.standard_normal(n), u


def test_estimated_initial_state_beats_zero_and_measured_on_a_short_window():
    y, u = _data(3000, 1)
    model = oe(y[:2000], u[:2000], 4, 6, 1, sample_time=TS)
    # a 300-sample window from the middle of unseen data: the plant is far from rest
    yv, uv = y[2400:2700], u[2400:2700]
    est, zero, meas = (compare(model, yv, uv, initial=i) for i in ("estimate", "zero", "measured"))
    assert est.initial == "estimate" and compare(model, yv, uv).fit == est.fit  # the default
    assert est.fit > zero.fit + 10.0
    assert est.fit >= meas.fit
    assert est.fit > 90.0
    assert est.start == zero.start == meas.start == model.start
    np.testing.assert_array_equal(zero.yhat, model.simulate(uv))
    np.testing.assert_array_equal(meas.yhat, model.simulate(uv, yv))


def test_predictions_ignore_initial_and_say_so():
    y, u = _data(1500, 2)
    model = oe(y, u, 4, 6, 1, sample_time=TS)
    c = compare(model, y, u, horizon=5, initial="zero")
    assert c.initial == "measured" and c.horizon == 5
    np.testing.assert_array_equal(c.yhat, model.predict(y, u, 5))


def test_narx_rbf_initial_conditions_are_fitted_too():
    rng = np.random.default_rng(3)
    u = rng.uniform(-1, 1, 600)
    y = scipy.signal.lfilter([0.0, 0.3], [1.0, -0.8], u + 0.3 * u**2) + 0.01 * rng.standard_normal(600)
    model = narx_rbf(y[:400], u[:400], 2, 2, 1, sample_time=TS, max_centres=15)
    yv, uv = y[450:], u[450:]
    est, meas = compare(model, yv, uv), compare(model, yv, uv, initial="measured")
    assert est.fit >= meas.fit


def test_unknown_initial_is_refused():
    y, u = _data(300, 4)
    with pytest.raises(InputError, match=r"unknown initial 'rest'; allowed: 'estimate', 'zero', 'measured'"):
        compare(oe(y, u, 2, 2, 1, sample_time=TS), y, u, initial="rest")
