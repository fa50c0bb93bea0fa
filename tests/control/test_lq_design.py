"""LQ building blocks: weights, stabilisability, the integral augmentation and the current Kalman gain."""

import numpy as np
import pytest

from trms.control.lq_design import (
    WEIGHT_RANGE,
    augment_with_integrators,
    current_estimator_gain,
    unreachable_unstable_modes,
    weight_matrix,
)
from trms.errors import DesignError


def test_current_estimator_is_the_optimal_filter_on_noisy_data(pitch_model):
    # Known truth: with process and measurement noise of covariances Qe and Re, the a-posteriori
    # error covariance of the current estimate is (I - Lc C) Pe and the a-priori one is Pe.
    A, B, C = (np.asarray(m) for m in (pitch_model.A, pitch_model.B, pitch_model.C))
    Qe, Re = 0.01 * np.eye(4), np.array([[0.04]])
    Lc, _, Pe = current_estimator_gain(A, C, np.eye(4), Qe, Re)
    rng = np.random.default_rng(11)
    n = 40000
    w = rng.standard_normal((n, 4)) * 0.1
    v = rng.standard_normal(n) * 0.2
    x, x_bar = np.zeros(4), np.zeros(4)
    post = np.empty((n, 4))
    prior = np.empty((n, 4))
    for k in range(n):
        y = C @ x + v[k]
        prior[k] = x - x_bar
        x_hat = x_bar + Lc @ (y - C @ x_bar)
        post[k] = x - x_hat
        x_bar = A @ x_hat
        x = A @ x + w[k]
    # 40000 correlated samples: the empirical variances are within ~3 % (1-sigma ~1 %); 6 % is safe.
    assert np.diag(np.cov(prior[100:].T)) == pytest.approx(np.diag(Pe), rel=0.06)
    assert np.diag(np.cov(post[100:].T)) == pytest.approx(np.diag((np.eye(4) - Lc @ C) @ Pe), rel=0.06)


def test_augmented_pair_layout():
    A, B, C = np.diag([0.5, 0.6]), np.array([[1.0], [2.0]]), np.array([[1.0, 3.0]])
    Aa, Ba = augment_with_integrators(A, B, C)
    assert Aa.tolist() == [[0.5, 0, 0], [0, 0.6, 0], [-1.0, -3.0, 1.0]]
    assert Ba.ravel().tolist() == [1.0, 2.0, 0.0]


def test_the_scalar_kalman_gain_of_a_random_walk_is_the_inverse_golden_ratio():
    # Pe = Pe + q - Pe^2 / (Pe + r): with q = r = 1, Pe^2 = Pe + 1
    golden = (1.0 + np.sqrt(5.0)) / 2.0
    Lc, Lp, Pe = current_estimator_gain(np.eye(1), np.eye(1), np.eye(1), np.eye(1), np.eye(1))
    assert Pe[0, 0] == pytest.approx(golden, abs=1e-12)
    assert Lc[0, 0] == pytest.approx(1.0 / golden, abs=1e-12) and Lp[0, 0] == pytest.approx(1.0 / golden, abs=1e-12)


@pytest.mark.parametrize(
    "value, expected",
    [(2.0, [[2.0, 0.0], [0.0, 2.0]]), ([1.0, 3.0], [[1.0, 0.0], [0.0, 3.0]]), ([[2.0, 1.0], [1.0, 2.0]], None)],
)
def test_weights_come_from_a_scalar_a_diagonal_or_a_matrix(value, expected):
    w = weight_matrix("Q", value, 2, definite=True)
    assert w.tolist() == (expected if expected is not None else value)


@pytest.mark.parametrize(
    "value, definite, match",
    [
        ([[1.0, 2.0], [0.0, 1.0]], False, r"Q must be symmetric"),
        ([[1.0, 2.0], [2.0, 1.0]], False, r"Q must be positive semi-definite; its smallest eigenvalue is -1"),
        ([1.0, 0.0], True, r"Q must be positive definite; its smallest eigenvalue is 0"),
        (2 * WEIGHT_RANGE[1], False, r"Q has an entry of magnitude 2e\+12"),
        ([1.0, 0.5 * WEIGHT_RANGE[0]], False, r"Q has an entry of magnitude 5e-13"),
    ],
)
def test_bad_weights_are_refused_in_one_line(value, definite, match):
    with pytest.raises(DesignError, match=match) as info:
        weight_matrix("Q", value, 2, definite=definite)
    assert "\n" not in str(info.value)


def test_the_pbh_test_finds_exactly_the_unreachable_unstable_modes():
    A = np.diag([1.0, 0.5, 1.2])
    assert unreachable_unstable_modes(A, np.array([[1.0], [1.0], [1.0]])) == []
    assert unreachable_unstable_modes(A, np.array([[1.0], [1.0], [0.0]])) == [pytest.approx(1.2)]
    assert unreachable_unstable_modes(A, np.array([[0.0], [1.0], [1.0]])) == [pytest.approx(1.0)]
    assert unreachable_unstable_modes(A, np.array([[1.0], [0.0], [1.0]])) == []  # 0.5 is stable: not counted
