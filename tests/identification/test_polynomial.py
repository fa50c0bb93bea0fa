"""The polynomial model object: LTI views, modes, predictions and simulation."""

from __future__ import annotations

import control
import numpy as np
import pytest
import scipy.signal

from trms.errors import InputError
from trms.identification.polynomial import PolynomialModel, modes_of_poles
from trms.reference import EQ_3_11_DEN, EQ_3_11_NUM, eq_3_11
from trms.signals import random_binary

TS = 0.2
A = np.array(EQ_3_11_DEN)
B = np.array([0.0, *EQ_3_11_NUM])
C = np.array([1.0, -0.7, 0.2])


@pytest.fixture
def model() -> PolynomialModel:
    return PolynomialModel(A, B, C, TS, noise_variance=4e-4)


def test_structure(model):
    assert model.orders == (4, 4, 2, 1)
    assert model.start == 4
    assert model.parameter_names == ["a1", "a2", "a3", "a4", "b1", "b2", "b3", "b4", "c1", "c2"]
    np.testing.assert_array_equal(model.parameters, np.r_[A[1:], B[1:], C[1:]])
    rebuilt = PolynomialModel.from_parameters(model.parameters, 4, 4, 2, 1, TS)
    np.testing.assert_array_equal(rebuilt.B, B)
    with pytest.raises(InputError, match=r"no parameter covariance"):
        _ = model.std_errors


def test_transfer_function_is_eq_3_11(model):
    g = model.to_tf()
    ref = eq_3_11()
    assert g.dt == TS
    np.testing.assert_allclose(g.num[0][0], ref.num[0][0], atol=1e-15)
    np.testing.assert_allclose(g.den[0][0], ref.den[0][0], atol=1e-15)
    ss = model.to_ss()
    assert ss.dt == TS and ss.nstates == 4 and np.all(np.asarray(ss.D) == 0)
    np.testing.assert_allclose(control.dcgain(ss), control.dcgain(ref), rtol=1e-9)
    h = model.noise_tf()
    np.testing.assert_allclose(h.num[0][0], [1.0, -0.7, 0.2, 0.0, 0.0], atol=1e-15)


def test_poles_zeros_modes_and_gain_match_the_derived_figures(model):
    # TARGETS.md (computed from 3.11): poles 0.8929 +- 0.4095j (0.342 Hz, damping 0.041),
    # 0.7530 and 0.4689 (time constants 0.71 s and 0.26 s); zeros 0.980 +- 1.328j and -1.074;
    # DC gain 1.51 rad/V. Tolerances are the printed rounding.
    poles = np.sort_complex(model.poles())
    np.testing.assert_allclose(poles, np.sort_complex([0.8929 + 0.4095j, 0.8929 - 0.4095j, 0.7530, 0.4689]), atol=6e-4)
    zeros = np.sort_complex(model.zeros())
    np.testing.assert_allclose(zeros, np.sort_complex([0.980 + 1.328j, 0.980 - 1.328j, -1.074]), atol=6e-4)
    modes = model.modes()
    assert len(modes) == 3
    assert [m.frequency_hz for m in modes] == sorted(m.frequency_hz for m in modes)
    (resonance,) = [m for m in modes if m.damping < 1]
    assert resonance.frequency_hz == pytest.approx(0.342, abs=6e-4)
    assert resonance.damping == pytest.approx(0.041, abs=6e-4)
    lags = sorted(1 / (2 * np.pi * m.frequency_hz) for m in modes if m.damping == pytest.approx(1.0))
    np.testing.assert_allclose(lags, [0.26, 0.71], atol=6e-3)
    assert model.dc_gain() == pytest.approx(1.51, abs=6e-3)
    assert model.is_stable()


def test_modes_of_poles_conventions():
    # z = exp(s Ts) with s = -zeta wn +- j wn sqrt(1 - zeta^2): recover wn and zeta exactly
    wn, zeta = 2 * np.pi * 0.5, 0.1
    s = -zeta * wn + 1j * wn * np.sqrt(1 - zeta**2)
    z = np.exp(np.array([s, np.conj(s), 0.0]) * TS)
    (m,) = modes_of_poles(np.r_[z[:2], 0.0], TS)  # the pole at the origin (a delay) is skipped
    assert m.frequency_hz == pytest.approx(0.5) and m.damping == pytest.approx(0.1)
    assert PolynomialModel([1.0, -1.0], [0.0, 1.0], [1.0], TS).dc_gain() == np.inf


def test_free_run_simulation_matches_python_control(model):
    u = random_binary(60.0, TS, 5.0, 1.0, seed=3)
    sim = model.simulate(u)
    ref = control.forced_response(eq_3_11(), T=np.arange(u.size) * TS, U=u).outputs
    np.testing.assert_allclose(sim, ref, atol=1e-12)


def test_simulation_from_measured_initial_conditions(model):
    # Data that start away from rest: the free run seeded with the first `start` measured
    # samples reproduces the noise-free output exactly, while a run from rest does not.
    u = random_binary(80.0, TS, 5.0, 1.0, seed=3)
    y_full = scipy.signal.lfilter(B, A, u)
    y, uu = y_full[100:], u[100:]
    np.testing.assert_allclose(model.simulate(uu, y), y, atol=1e-12)
    assert np.max(np.abs(model.simulate(uu) - y)) > 0.1


def test_predictions_one_step_k_step_and_infinite_horizon(model):
    rng = np.random.default_rng(0)
    u = random_binary(100.0, TS, 5.0, 1.0, seed=4)
    e = rng.standard_normal(u.size) * 0.02
    y = scipy.signal.lfilter(B, A, u) + scipy.signal.lfilter(C, A, e)
    eps = model.residuals(y, u)
    np.testing.assert_array_equal(eps[: model.start], 0.0)
    # from rest, the conditional one-step errors of the true model are the innovations after
    # the C-filter transient (|roots of C| = 0.45: 0.45^40 ~ 1e-14)
    np.testing.assert_allclose(eps[40:], e[40:], atol=1e-12)
    np.testing.assert_allclose(model.predict(y, u, 1), y - eps, atol=1e-15)
    # a horizon longer than the record is the free run from the measured initial conditions
    np.testing.assert_allclose(model.predict(y, u, u.size), model.simulate(u, y), atol=1e-10)


def test_k_step_prediction_of_an_ar1_is_a_power():
    # y(t) = 0.8 y(t-1) + 0.5 u(t-1) + e(t): yhat(t|t-3) = 0.8^3 y(t-3) + 0.5 (0.8^2 u(t-3) + 0.8 u(t-2) + u(t-1))
    m = PolynomialModel([1.0, -0.8], [0.0, 0.5], [1.0], TS)
    rng = np.random.default_rng(1)
    u, y = rng.standard_normal(50), rng.standard_normal(50)
    pred = m.predict(y, u, 3)
    t = np.arange(4, 50)
    expected = 0.8**3 * y[t - 3] + 0.5 * (0.8**2 * u[t - 3] + 0.8 * u[t - 2] + u[t - 1])
    np.testing.assert_allclose(pred[t], expected, atol=1e-12)


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda: PolynomialModel([2.0, 1.0], [0.0, 1.0], [1.0], TS), r"A must be monic"),
        (lambda: PolynomialModel([1.0, np.nan], [0.0, 1.0], [1.0], TS), r"A must be finite"),
        (lambda: PolynomialModel([1.0], [1.0], [1.0], 0.0), r"sample_time = 0\.0 s is outside"),
        (lambda: PolynomialModel(A, B, C, TS).predict(np.ones(10), np.ones(10), 0), r"horizon = 0 samples is outside"),
        (lambda: PolynomialModel(A, B, C, TS).residuals(np.ones(10), np.ones(9)), r"same length, got 10 and 9"),
        (lambda: PolynomialModel(A, B, C, TS).residuals(np.ones(3), np.ones(3)), r"needs more than start = 4"),
    ],
)
def test_bad_input(call, match):
    with pytest.raises(InputError, match=match):
        call()
