"""Known-truth data shared by the identification tests."""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest
import scipy.signal

from trms.reference import EQ_3_11_DEN, EQ_3_11_NUM, SAMPLE_TIME_1DOF
from trms.signals import random_binary

#: True polynomials of eq. (3.11) in q^-1: A y = B u + C e, nk = 1.
TRUE_A = np.array(EQ_3_11_DEN)
TRUE_B = np.array([0.0, *EQ_3_11_NUM])
#: A coloured-noise polynomial (roots 0.35 +- 0.28j, |r| = 0.45) chosen for the known-truth tests.
TRUE_C = np.array([1.0, -0.7, 0.2])
#: Innovations standard deviation (rad): about 4 % of the output's standard deviation.
NOISE_STD = 0.02


@cache
def eq_3_11_data(n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """``n`` samples of y = B/A u + C/A e from (3.11), a 5 Hz PRBS of 1 V at Ts = 0.2 s."""
    u = random_binary(n * SAMPLE_TIME_1DOF, SAMPLE_TIME_1DOF, 5.0, 1.0, seed=seed)
    e = np.random.default_rng(seed + 1000).standard_normal(n) * NOISE_STD
    y = scipy.signal.lfilter(TRUE_B, TRUE_A, u) + scipy.signal.lfilter(TRUE_C, TRUE_A, e)
    y.flags.writeable = False
    u.flags.writeable = False
    return y, u


class Truth:
    """The known-truth ARMAX system as a fixture: polynomials and a cached data generator."""

    A = TRUE_A
    B = TRUE_B
    C = TRUE_C
    noise_std = NOISE_STD
    sample_time = SAMPLE_TIME_1DOF
    data = staticmethod(eq_3_11_data)


@pytest.fixture(scope="session")
def truth() -> Truth:
    """Eq. (3.11) with coloured ARMAX noise."""
    return Truth()


class Nonlinear:
    """A known nonlinear NARX system with an even input nonlinearity and a bilinear term:

    ``y(t) = 0.9 y(t-1) - 0.3 y(t-2) + 0.5 u(t-1) + 0.4 u(t-1)^2 - 0.2 y(t-1) u(t-1) + e(t)``

    with white Gaussian ``e`` of standard deviation 0.01 (about 2 % of the output's).
    """

    noise_std = 0.01
    start = 2

    @staticmethod
    def one_step(y: np.ndarray, u: np.ndarray) -> np.ndarray:
        """The true one-step predictor (0 for the first two samples)."""
        pred = np.zeros(y.size)
        y1, y2, u1 = y[1:-1], y[:-2], u[1:-1]
        pred[2:] = 0.9 * y1 - 0.3 * y2 + 0.5 * u1 + 0.4 * u1**2 - 0.2 * y1 * u1
        return pred

    def simulate(self, u: np.ndarray, seed: int) -> np.ndarray:
        e = np.random.default_rng(seed).standard_normal(u.size) * self.noise_std
        y = np.zeros(u.size)
        for t in range(2, u.size):
            y[t] = (
                0.9 * y[t - 1]
                - 0.3 * y[t - 2]
                + 0.5 * u[t - 1]
                + 0.4 * u[t - 1] ** 2
                - 0.2 * y[t - 1] * u[t - 1]
                + e[t]
            )
        return y

    def residuals(self, y: object, u: object) -> np.ndarray:
        """The true model's one-step errors (the innovations after the first two samples)."""
        ya, ua = np.asarray(y, float), np.asarray(u, float)
        out = ya - self.one_step(ya, ua)
        out[:2] = 0.0
        return out


@pytest.fixture(scope="session")
def nonlinear() -> Nonlinear:
    """The known nonlinear system."""
    return Nonlinear()
