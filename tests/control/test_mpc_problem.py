"""The MPC's problem: the condensed prediction equals a simulation, the constraint rows bound what they say, the
estimator tracks a constant input disturbance."""

import numpy as np
import pytest

from trms.control.mpc_problem import condensed_prediction, constraint_rows, disturbance_estimator
from trms.errors import InputError


def test_the_condensed_prediction_equals_a_simulation():
    rng = np.random.default_rng(0)
    A, B = 0.5 * rng.standard_normal((3, 3)), rng.standard_normal((3, 2))
    x0, U = rng.standard_normal(3), rng.standard_normal((6, 2))
    Phi, Gam = condensed_prediction(A, B, 6)
    x, xs = x0, []
    for u in U:
        x = A @ x + B @ u
        xs.append(x)
    assert np.allclose(Phi @ x0 + Gam @ U.ravel(), np.concatenate(xs), atol=1e-12)


def test_the_constraint_rows_bound_the_moves_the_rates_the_outputs_and_the_slacks():
    CyGam = np.array([[1.0, 0.0], [2.0, 1.0]])
    rows = constraint_rows(2, 1, CyGam, 2)
    z = np.array([0.3, 0.5, 0.1, 0.2])  # two moves, two slacks
    got = rows @ z
    assert got[:2].tolist() == [0.3, 0.5] and got[2:4] == pytest.approx([0.3, 0.2])
    assert got[4:6] == pytest.approx(CyGam @ z[:2] - z[2:]) and got[6:8] == pytest.approx(CyGam @ z[:2] + z[2:])
    assert got[8:].tolist() == [0.1, 0.2]


def test_the_estimator_finds_a_constant_input_disturbance():
    A, B, C = np.array([[0.9]]), np.array([[0.1]]), np.array([[1.0]])
    Ae, Be, Ce, Lc = disturbance_estimator(A, B, C, 1e-4, 1e-2, 1e-4)
    x, xhat, d = np.zeros(1), np.zeros(2), 0.5
    for _ in range(300):
        x = A @ x + B @ np.array([d])
        xhat = Ae @ xhat  # prediction (u = 0), then the current measurement update
        xhat = xhat + Lc @ (C @ x - Ce @ xhat)
    assert xhat[1] == pytest.approx(d, abs=1e-3)
    with pytest.raises(InputError, match="Qd"):
        disturbance_estimator(A, B, C, 1e-4, 0.0, 1e-4)
