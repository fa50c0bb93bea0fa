"""The plant seam: LinearPlant behaviour, saturation, simulate's timing convention and seeding."""

import json

import control
import numpy as np
import pytest

from trms import reference
from trms.errors import ConfigurationError, InputError
from trms.plant import LinearPlant, simulate
from trms.record import OperatingPoint


def test_linear_plant_matches_python_control_and_timing_convention():
    g = reference.eq_3_11()
    plant = LinearPlant(g)
    u = np.random.default_rng(0).uniform(-1, 1, 50)
    rec = simulate(plant, u)
    _, y_ref = control.forced_response(g, T=np.arange(50) * 0.2, U=u)
    # Row k holds y_k, measured before u_k acts: the same sequence as control.forced_response.
    assert np.allclose(rec.outputs[:, 0], np.ravel(y_ref), atol=1e-12)
    assert rec.outputs[0, 0] == 0.0


def test_linear_plant_operating_point_and_saturation():
    op = OperatingPoint(np.array([2.0]), np.array([0.5]), ("u1",), ("y1",))
    plant = LinearPlant(reference.eq_3_11(), op, input_limits=(-10.0, 10.0))
    rec = simulate(plant, np.full(1000, 12.0))  # 10 V above trim in deviation, but clipped at 10 V absolute
    assert np.all(rec.extras["saturated"])
    assert np.all(rec.extras["applied_inputs"] == 10.0)
    assert rec.outputs[-1, 0] == pytest.approx(0.5 + 8.0 * reference.eq_3_11().dcgain(), rel=1e-3)


def test_linear_plant_refuses_direct_term_and_continuous_systems():
    with pytest.raises(ConfigurationError, match="direct term"):
        LinearPlant(reference.eq_6_33())
    with pytest.raises(ConfigurationError, match="discrete-time"):
        LinearPlant(control.tf([1], [1, 1]))


def test_linear_plant_bad_input_leaves_state_unchanged():
    plant = LinearPlant(reference.eq_3_11())
    plant.reset()
    plant.step(1.0)
    before = plant.state
    for bad in (np.nan, [1.0, 2.0], "x"):
        with pytest.raises(InputError):
            plant.step(bad)
    assert np.array_equal(plant.state, before)


def test_linear_plant_noise_is_seeded():
    plant = LinearPlant(reference.eq_3_11(), noise_std=0.01)
    a = simulate(plant, np.ones(30), seed=5)
    b = simulate(plant, np.ones(30), seed=5)
    c = simulate(plant, np.ones(30), seed=6)
    assert a.equals(b) and not np.array_equal(a.outputs, c.outputs)
    json.dumps(a.metadata)


@pytest.mark.parametrize("dt", [None, True, 0, float("nan"), float("inf")])
def test_a_linear_plant_needs_a_finite_positive_sample_time(dt):
    with pytest.raises(ConfigurationError, match="must be discrete-time with a numeric dt > 0"):
        LinearPlant(control.ss(0.5, 1.0, 1.0, 0.0, dt))
