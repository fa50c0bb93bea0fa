"""Subspace identification (n4sid) on a hidden 6th-order two-resonance MIMO system."""

from __future__ import annotations

import control
import numpy as np
import pytest
import scipy.signal

from trms.errors import InputError
from trms.identification import n4sid, subspace_singular_values
from trms.identification.polynomial import modes_of_poles
from trms.identification.subspace import UnstableModelWarning
from trms.record import Record

TS = 0.05


def _truth() -> control.StateSpace:
    """TRMS-like: rotor lags (0.8 Hz, 0.5 Hz) drive a pitch (0.45 Hz, zeta 0.06) and a yaw
    (1.3 Hz, zeta 0.1) resonance, cross-coupled; outputs are the two angles."""
    w1, w2, z1, z2 = 2 * np.pi * 0.45, 2 * np.pi * 1.3, 0.06, 0.1
    a1, a2 = 2 * np.pi * 0.8, 2 * np.pi * 0.5
    a = np.array(
        [
            [-a1, 0, 0, 0, 0, 0],
            [0, 0, 1, 0, 0, 0],
            [w1**2, -(w1**2), -2 * z1 * w1, 0.3 * w1**2, 0, 0],
            [0, 0, 0, -a2, 0, 0],
            [0, 0, 0, 0, 0, 1],
            [0.4 * w2**2, 0, 0, w2**2, -(w2**2), -2 * z2 * w2],
        ]
    )
    b = np.zeros((6, 2))
    b[0, 0], b[3, 1] = a1, a2
    c = np.zeros((2, 6))
    c[0, 1] = c[1, 4] = 1.0
    return control.c2d(control.ss(a, b, c, np.zeros((2, 2))), TS)


def _data(n: int, seed: int, noise: float = 0.02) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    u = np.repeat(np.sign(rng.standard_normal((n // 2 + 1, 2))), 2, axis=0)[:n]  # both inputs at once
    y = control.forced_response(_truth(), U=u.T).outputs.T
    return y + noise * y.std(axis=0) * rng.standard_normal(y.shape), u


def _resonances(sys: control.StateSpace) -> np.ndarray:
    return np.array([m.frequency_hz for m in modes_of_poles(sys.poles(), TS) if m.damping < 0.5])


def test_n4sid_recovers_the_two_resonances_within_one_percent_and_picks_the_order():
    y, u = _data(4000, 1)
    est = n4sid(y, u, sample_time=TS)
    assert isinstance(est, control.StateSpace) and est.nstates == 6
    assert est.ninputs == 2 and est.noutputs == 2 and est.dt == TS
    true_f, est_f = _resonances(_truth()), _resonances(est)
    assert est_f.size == 2
    np.testing.assert_allclose(est_f, true_f, rtol=0.01)
    # out of sample: the model's free run on a fresh input reproduces the truth
    y2, u2 = _data(1000, 2, noise=0.0)
    sim = control.forced_response(est, U=u2.T).outputs.T
    fit = 100 * (1 - np.linalg.norm(y2 - sim, axis=0) / np.linalg.norm(y2 - y2.mean(axis=0), axis=0))
    assert np.all(fit > 90)


def test_the_singular_values_show_the_order_above_the_noise_floor():
    y, u = _data(3000, 3)
    sv = subspace_singular_values(y, u, sample_time=TS)
    assert sv.order == 6
    assert sv.singular_values[5] > 3 * sv.noise_floor > sv.singular_values[6]


def test_siso_exact_data_and_a_given_order():
    rng = np.random.default_rng(0)
    u = np.sign(rng.standard_normal(800))
    y = scipy.signal.lfilter([0.0, 0.5, 0.2], [1.0, -1.5, 0.7], u)
    est = n4sid(y, u, 2, sample_time=0.1)
    np.testing.assert_allclose(np.sort_complex(est.poles()), np.sort_complex(np.roots([1.0, -1.5, 0.7])), atol=1e-8)
    np.testing.assert_allclose(est.dcgain(), 0.7 / 0.2, rtol=1e-8)


def test_a_record_gives_all_its_channels():
    y, u = _data(2000, 4)
    rec = Record(
        time=np.arange(2000) * TS,
        inputs=u,
        outputs=y,
        input_names=("u1", "u2"),
        output_names=("pitch", "yaw"),
        metadata={"sample_time": TS},
    )
    est = n4sid(rec, order=6)
    assert est.ninputs == est.noutputs == 2
    np.testing.assert_allclose(_resonances(est), _resonances(_truth()), rtol=0.01)


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda y, u: n4sid(y, u), r"sample_time \(s\) is required"),
        (
            lambda y, u: n4sid(y[:100], u[:100], sample_time=TS),
            r"horizon = 11 samples needs at least 109 samples for 2 inputs and 2 outputs; the data have 100",
        ),
        (lambda y, u: n4sid(y, u, 2.0, sample_time=TS), r"order must be an int, got 2\.0"),
        (lambda y, u: n4sid(y, u, -1, sample_time=TS), r"order = -1"),
        (
            lambda y, u: n4sid(y, u, 8, sample_time=TS, horizon=3),
            r"horizon = 3 samples with 2 outputs reveals at most order 5",
        ),
        (lambda y, u: n4sid(y, np.column_stack([u[:, 0], np.ones(len(u))]), sample_time=TS), r"input 1 is constant"),
        (lambda y, u: n4sid(y + 1j, u, sample_time=TS), r"must be real"),
        (lambda y, u: n4sid(y[:-1], u, sample_time=TS), r"same N"),
        (lambda y, u: n4sid(y, u, sample_time=TS, weighting="n4"), r"unknown weighting .n4.; allowed: 'moesp', 'cva'"),
        (lambda y, u: n4sid(y, u, sample_time=TS, refine=True), r"unknown refine True; allowed: 'simulation', 'none'"),
    ],
)
def test_bad_input(call, match):
    y, u = _data(600, 5)
    with pytest.raises(InputError, match=match):
        call(y, u)


# ---------------------------------------------------------------- slow modes: the default horizon
TS_SLOW = 0.1


def _slow_truth() -> control.StateSpace:
    """Two lightly damped modes (0.1 Hz and 0.34 Hz, zeta 0.05), both inputs drive both, both outputs see both."""
    a = np.zeros((4, 4))
    for k, f in enumerate((0.1, 0.34)):
        w = 2 * np.pi * f
        a[2 * k : 2 * k + 2, 2 * k : 2 * k + 2] = [[0, 1], [-(w**2), -0.1 * w]]
    b = np.array([[0, 0], [1.0, 0.5], [0, 0], [0.6, 1.0]]) * np.array(
        [[1], [(0.2 * np.pi) ** 2], [1], [(0.68 * np.pi) ** 2]]
    )
    c = np.array([[1.0, 0, 0.7, 0], [0.4, 0, 1.0, 0]])
    return control.c2d(control.ss(a, b, c, np.zeros((2, 2))), TS_SLOW)


def _slow_data(n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    u = np.repeat(np.sign(rng.standard_normal((n // 5 + 1, 2))), 5, axis=0)[:n]
    y = control.forced_response(_slow_truth(), U=u.T).outputs.T
    return y + 0.1 * y.std(axis=0) * rng.standard_normal(y.shape), u


# Seeds whose fixed 11-sample horizon (the former default) gave a pole outside the unit circle.
@pytest.mark.parametrize("seed", [1033, 1040, 1085])
def test_the_default_horizon_covers_a_third_of_the_slowest_period_and_gives_a_stable_model(seed):
    y, u = _slow_data(2000, seed)
    with pytest.warns(UnstableModelWarning, match=r"pole at z = .* \(\|z\| = 1\.00"):
        n4sid(y, u, sample_time=TS_SLOW, horizon=11)
    est = n4sid(y, u, sample_time=TS_SLOW)
    assert abs(est.horizon - 100 / 3) <= 3  # a third of the 100 samples per period of the 0.1 Hz mode, as estimated
    assert est.nstates == 4 and np.max(np.abs(est.poles())) < 1
    modes = sorted(
        (m for m in modes_of_poles(est.poles(), TS_SLOW) if m.frequency_hz > 0), key=lambda m: m.frequency_hz
    )
    np.testing.assert_allclose([m.frequency_hz for m in modes], [0.1, 0.34], rtol=0.01)
    np.testing.assert_allclose([m.damping for m in modes], [0.05, 0.05], rtol=0.1)


def test_the_default_horizon_is_bounded_by_the_data_and_kept_for_fast_modes():
    y, u = _slow_data(600, 7)
    assert n4sid(y, u, sample_time=TS_SLOW).horizon == 601 // 42  # 5 Hankel columns per stacked row
    rng = np.random.default_rng(0)
    u1 = np.sign(rng.standard_normal(800))
    y1 = scipy.signal.lfilter([0.0, 1.0], [1.0, -1.5, 0.7], u1)  # period 13.6 samples: a third is below 21
    assert n4sid(y1, u1, sample_time=0.1).horizon == 21  # max(10, 2 max_order / p + 1)
    assert n4sid(y1, u1, sample_time=0.1, horizon=25).horizon == 25


# ---------------------------------------------------------------- order 0 and unstable models
def test_a_static_gain_has_order_zero():
    rng = np.random.default_rng(3)
    u = rng.standard_normal((2000, 2))
    d = np.array([[1.0, -0.5], [0.3, 2.0]])
    y = u @ d.T + rng.standard_normal((2000, 2)) * [0.1, 0.3]
    assert subspace_singular_values(y, u, sample_time=0.1).order == 0
    est = n4sid(y, u, sample_time=0.1)
    assert est.nstates == 0 and est.kalman_gain.shape == (0, 2)
    np.testing.assert_allclose(est.D, d, atol=0.03)  # 6 standard errors of 0.3 / sqrt(2000)
    np.testing.assert_allclose(est.innovation_covariance, np.diag([0.01, 0.09]), atol=0.01)
    assert n4sid(y, u, 0, sample_time=0.1).nstates == 0


def test_an_unstable_model_is_returned_with_a_warning_that_names_the_pole():
    rng = np.random.default_rng(4)
    u = np.sign(rng.standard_normal(300))
    y = scipy.signal.lfilter([0.0, 1.0], [1.0, -1.02], u)
    with pytest.warns(UnstableModelWarning, match=r"pole at z = 1\.02.*\(\|z\| = 1\.0200\) outside the unit circle"):
        est = n4sid(y, u, 1, sample_time=0.1)
    np.testing.assert_allclose(est.poles(), [1.02], atol=1e-6)


# ---------------------------------------------------------------- the noise model
A_K = np.array([[0.9, 0.25, 0.0], [-0.25, 0.9, 0.0], [0.0, 0.0, 0.6]])
B_K = np.array([[1.0, 0.0], [0.0, 0.5], [0.5, 1.0]])
C_K = np.array([[1.0, 0.0, 1.0], [0.0, 1.0, -0.5]])
K_K = np.array([[0.6, 0.1], [-0.2, 0.5], [0.3, 0.3]])
L_E = np.array([[0.2, 0.0], [0.05, 0.1]])  # innovation covariance L_E L_E^T


def test_the_kalman_gain_and_innovation_covariance_of_an_innovations_form_system():
    """x(t+1) = A x + B u + K e, y = C x + e. K depends on the state basis: compare C A^k K (basis-free).

    Tolerances: |bias| + 4 standard deviations of 100 seeded realisations of N = 4000 (largest
    |bias| 0.039 and std 0.041 for C K; 0.0009 and 0.0011 for the innovation covariance).
    """
    n = 4000
    rng = np.random.default_rng(11)
    u, e = np.sign(rng.standard_normal((n, 2))), rng.standard_normal((n, 2)) @ L_E.T
    plant = control.ss(A_K, np.hstack([B_K, K_K]), C_K, np.hstack([np.zeros((2, 2)), np.eye(2)]), 1.0)
    y = control.forced_response(plant, U=np.hstack([u, e]).T).outputs.T
    est = n4sid(y, u, sample_time=1.0)
    assert est.nstates == 3 and est.kalman_gain.shape == (3, 2)
    a, c = np.asarray(est.A), np.asarray(est.C)
    np.testing.assert_allclose(c @ est.kalman_gain, C_K @ K_K, atol=0.2)
    np.testing.assert_allclose(c @ a @ est.kalman_gain, C_K @ A_K @ K_K, atol=0.2)
    np.testing.assert_allclose(est.innovation_covariance, L_E @ L_E.T, atol=0.005)
    predictor = np.sort(np.abs(np.linalg.eigvals(a - est.kalman_gain @ c)))
    np.testing.assert_allclose(predictor[1:], np.abs(np.linalg.eigvals(A_K - K_K @ C_K)).max(), atol=0.15)


def test_a_negative_real_pole_sets_the_default_horizon_without_a_warning():
    import warnings

    u = np.sign(np.random.default_rng(0).standard_normal(1000))
    y = scipy.signal.lfilter([0, 1.0], [1, 0.5], u)  # the pole at z = -0.5
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sys = n4sid(y, u, sample_time=0.1)
    assert sys.nstates == 1 and float(np.real(sys.poles()[0])) == pytest.approx(-0.5, abs=1e-6)


# ---------------------------------------------------------------- coloured output noise: the refinement
def _coloured_data(seed: int) -> tuple[np.ndarray, np.ndarray]:
    """The slow-mode system under AR(1) output noise (pole 0.9), each output's noise a tenth of its power."""
    rng = np.random.default_rng(seed)
    u = np.repeat(np.sign(rng.standard_normal((401, 2))), 5, axis=0)[:2000]
    y = control.forced_response(_slow_truth(), U=u.T).outputs.T
    v = scipy.signal.lfilter([1.0], [1.0, -0.9], rng.standard_normal((2500, 2)), axis=0)[500:]
    return y + v / v.std(axis=0) * y.std(axis=0) / np.sqrt(10.0), u


def _slow_damping_error(model: control.StateSpace) -> float:
    modes = [m for m in modes_of_poles(model.poles(), TS_SLOW) if 0 < m.frequency_hz and m.damping < 0.5]
    return abs(min(modes, key=lambda m: abs(m.frequency_hz - 0.1)).damping / 0.05 - 1)


def test_the_simulation_refinement_finds_the_slow_modes_damping_under_coloured_noise():
    """The subspace model's 0.1 Hz damping is off by more than half on every seed; refined, the median error is
    within 25 % (the benchmark's Monte Carlo: about 10 %), and the refined model simulates the data better."""
    refined, subspace = [], []
    for seed in (3101, 3102, 3103):
        y, u = _coloured_data(seed)
        plain, model = n4sid(y, u, 4, sample_time=TS_SLOW, refine="none"), n4sid(y, u, 4, sample_time=TS_SLOW)
        assert model.info["refined"] and not plain.info["refined"]
        assert model.info["simulation_loss"] < model.info["subspace_simulation_loss"]
        assert np.all(model.fit > plain.fit)
        refined.append(_slow_damping_error(model))
        subspace.append(_slow_damping_error(plain))
    assert min(subspace) > 0.5 and np.median(refined) < 0.25


def test_cva_weighting_recovers_exact_data_as_moesp_does():
    u = np.sign(np.random.default_rng(7).standard_normal(1000))
    y = scipy.signal.lfilter([0, 1.0, 0.5], [1, -1.5, 0.7], u)
    for weighting in ("moesp", "cva"):
        sys = n4sid(y, u, sample_time=0.1, weighting=weighting, refine="none")
        assert sys.nstates == 2 and sys.info["weighting"] == weighting
        np.testing.assert_allclose(np.sort(np.abs(sys.poles())), np.sqrt(0.7), rtol=1e-8)
