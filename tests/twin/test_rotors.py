"""Thrust curves: asymmetric, monotone, invertible, with the slope the linearisation uses."""

import numpy as np
import pytest

from trms.errors import ModelFileError
from trms.twin import ThrustCurve, load_spec
from trms.twin.model import thrust_curves


@pytest.fixture(scope="module")
def curves():
    return thrust_curves(load_spec())


def test_curves_are_monotone_and_asymmetric(curves):
    v = np.linspace(-10, 10, 2001)
    for c in curves:
        f = c.thrust(v)
        assert np.all(np.diff(f) > 0)
        assert c.thrust(0.0) == 0.0
        assert abs(c.thrust(-5.0)) < 0.7 * c.thrust(5.0)  # reverse thrust is weaker


def test_inverse_and_slope(curves):
    v = np.linspace(-10, 10, 101)
    for c in curves:
        assert np.allclose(c.voltage(c.thrust(v)), v, atol=1e-12)
        h = 1e-6
        fd = (c.thrust(v + h) - c.thrust(v - h)) / (2 * h)
        away = np.abs(v) > 1e-3  # the slope is one-sided at 0 V
        assert np.allclose(c.slope(v)[away], fd[away], rtol=1e-6)


@pytest.mark.parametrize("data", [[1.0, 2.0], [1.0, -1.0, 1.0, 1.0, 1.0], [0.0, 1.0, 1.0, 1.0, 1.0], [np.nan, 1, 1, 1, 1]])
def test_bad_coefficients_are_refused(data):
    with pytest.raises(ModelFileError):
        ThrustCurve.from_array(np.array(data, float))


def test_scalar_path_equals_array_path(curves):
    v = np.linspace(-10, 10, 41)
    for c in curves:
        assert np.array_equal([c.thrust(x) for x in v], c.thrust(v))
        f = c.thrust(v)
        assert np.allclose([c.rotor_state(x) for x in f], c.rotor_state(f), rtol=1e-14, atol=1e-14)
