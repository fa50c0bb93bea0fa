"""Known-truth data shared by the identification tests."""

from __future__ import annotations

from functools import lru_cache

import numpy as np
import pytest
import scipy.signal

from trms.identification.signals import prbs
from trms.reference import EQ_3_11_DEN, EQ_3_11_NUM, SAMPLE_TIME_1DOF

#: True polynomials of eq. (3.11) in q^-1: A y = B u + C e, nk = 1.
TRUE_A = np.array(EQ_3_11_DEN)
TRUE_B = np.array([0.0, *EQ_3_11_NUM])
#: A coloured-noise polynomial (roots 0.35 +- 0.28j, |r| = 0.45) chosen for the known-truth tests.
TRUE_C = np.array([1.0, -0.7, 0.2])
#: Innovations standard deviation (rad): about 4 % of the output's standard deviation.
NOISE_STD = 0.02


@lru_cache(maxsize=None)
def eq_3_11_data(n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """``n`` samples of y = B/A u + C/A e from (3.11), a 5 Hz PRBS of 1 V at Ts = 0.2 s."""
    u = prbs(n * SAMPLE_TIME_1DOF, SAMPLE_TIME_1DOF, 5.0, 1.0, seed=seed)
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
