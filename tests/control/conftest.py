"""Shared models for the control tests."""

import control
import numpy as np
import pytest

from trms.control.realization import observer_canonical
from trms.reference import eq_3_11


@pytest.fixture(scope="session")
def pitch_model() -> control.StateSpace:
    """Eq. (3.11) in the observer canonical form of eq. (6.33) (D = 0)."""
    return observer_canonical(eq_3_11())


@pytest.fixture(scope="session")
def mimo_model() -> control.StateSpace:
    """A seeded, stable 2-input 2-output 5-state discrete model (no zero at z = 1)."""
    rng = np.random.default_rng(7)
    A = rng.standard_normal((5, 5))
    A *= 0.9 / np.max(np.abs(np.linalg.eigvals(A)))
    B = rng.standard_normal((5, 2))
    C = rng.standard_normal((2, 5))
    return control.ss(A, B, C, np.zeros((2, 2)), 0.1, inputs=["u1", "u2"], outputs=["y1", "y2"])
