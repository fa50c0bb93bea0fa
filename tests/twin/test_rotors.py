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
        inside = ~c.at_full_speed(v)
        assert np.all(np.diff(f) >= 0) and np.all(np.diff(f[inside]) > 0)
        assert c.thrust(0.0) == 0.0
        assert abs(c.thrust(-1.0)) < 0.7 * c.thrust(1.0)  # reverse thrust is weaker
        assert c.thrust(10.0) == pytest.approx(c.max_thrust[0]) and c.thrust(-10.0) == pytest.approx(c.max_thrust[1])


def test_full_speed_is_the_published_rotors():
    """Whatever the calibrated input gain, full thrust is the published rotor's (11.04 N main at 10 V, k1 = 1.1)."""
    main = thrust_curves(load_spec())[0]
    published = ThrustCurve(1.1, main.a_pos, main.b_pos, main.a_neg, main.b_neg)
    assert main.max_thrust[0] == pytest.approx(published.thrust(10.0), rel=1e-12)
    assert main.max_thrust[1] == pytest.approx(published.thrust(-10.0), rel=1e-12)


def test_inverse_and_slope(curves):
    for c in curves:
        v = np.linspace(-10, 10, 101)
        v = v[~c.at_full_speed(v)]
        assert np.allclose(c.voltage(c.thrust(v)), v, atol=1e-12)
        h = 1e-6
        fd = (c.thrust(v + h) - c.thrust(v - h)) / (2 * h)
        away = (np.abs(v) > 1e-3) & (np.abs(np.abs(c.k * v) - c.tau_max) > 1e-3)  # one-sided at 0 V and at full speed
        assert np.allclose(c.slope(v)[away], fd[away], rtol=1e-6)


@pytest.mark.parametrize(
    "data", [[1.0, 2.0], [1.0, -1.0, 1.0, 1.0, 1.0], [0.0, 1.0, 1.0, 1.0, 1.0], [np.nan, 1, 1, 1, 1]]
)
def test_bad_coefficients_are_refused(data):
    with pytest.raises(ModelFileError):
        ThrustCurve.from_array(np.array(data, float))


def test_scalar_path_equals_array_path(curves):
    v = np.linspace(-10, 10, 41)
    for c in curves:
        assert np.array_equal([c.thrust(x) for x in v], c.thrust(v))
        f = c.thrust(v)
        assert np.allclose([c.rotor_state(x) for x in f], c.rotor_state(f), rtol=1e-14, atol=1e-14)


def test_one_samples_controls_and_a_records_are_the_same_bits(curves):
    from trms.twin.rotors import rotor_control_values, rotor_controls

    rng = np.random.default_rng(0)
    volts = np.concatenate([rng.uniform(-12.0, 12.0, (2000, 2)), [[0.0, -0.0], [10.0, -10.0], [1e-300, -1e-300]]])
    batch = rotor_controls(curves, volts, 6)
    rows = np.array([rotor_control_values(curves, v.tolist(), 6) for v in volts])
    assert batch.tobytes() == rows.tobytes()
    assert rotor_controls(curves, volts[0], 6).tobytes() == rows[0].tobytes()


def test_the_tachometer_of_a_record_is_each_samples_to_the_sign_of_zero(curves):
    rng = np.random.default_rng(1)
    thrust = np.concatenate([rng.uniform(-12.0, 12.0, 5000), [0.0, -0.0, 1e-300, -1e-300]])
    for c in curves:
        assert c.rotor_state(thrust).tobytes() == np.array([c.rotor_state(f) for f in thrust.tolist()]).tobytes()
