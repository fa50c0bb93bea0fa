"""Stacked controllers of any kind: a batch of PID, H-infinity or MPC loops equals each loop alone, bit for bit."""

import numpy as np
import pytest

from trms.batch import batch_closed_loop, stack_controllers
from trms.batch.controllers import StackedLoops
from trms.control.hinf import HinfController, design_mixsyn, pitch_weights
from trms.control.loop import closed_loop, deviation_limits
from trms.control.mpc import mpc_for_plant
from trms.control.pid import PIDController, PIDGains
from trms.control.pid_tuning import tune_pid
from trms.errors import ConfigurationError
from trms.signals import square_wave
from trms.worlds import design_model, make_plant


def _twins():
    """Two twins with different counterweights, gusts and seeds."""
    return [
        make_plant("twin", "1dof", gusts=True, parameters={"counterweight_mass": m}, seed=s)
        for m, s in ((0.07, 3), (0.09, 4))
    ]


def _pair(plant):
    lo, hi = deviation_limits(plant)
    return float(lo[0]), float(hi[0])


@pytest.fixture(scope="module")
def model():
    return design_model("1dof")


@pytest.fixture(scope="module")
def makers(model):
    pid = tune_pid(model)
    hinf = design_mixsyn(model, *pitch_weights(bandwidth=0.3, effort=0.2))
    return {
        "PID": lambda p: PIDController(pid, p.sample_time, _pair(p)),
        "H-infinity": lambda p: HinfController(hinf, _pair(p)),
        "MPC": lambda p: mpc_for_plant(model, p, horizon=30, rate_limit=1.0),
    }


@pytest.mark.parametrize("kind", ["PID", "H-infinity", "MPC"])
def test_a_batch_of_any_controller_is_bit_identical_to_each_loop_alone(kind, makers):
    make = makers[kind]
    ref = square_wave(10.0, 0.2, 5.0, 0.2)
    twins = _twins()
    batch = batch_closed_loop(twins, [make(t) for t in twins], ref, seeds=[5, 6], threads=2, metadata={"run": kind})
    assert all(e is None for e in batch.errors)
    for rec, twin, seed in zip(batch.records, _twins(), (5, 6)):
        alone = closed_loop(twin, make(twin), ref, seed=seed, metadata={"run": kind})
        assert rec.extras.keys() == alone.extras.keys() and rec.metadata == alone.metadata
        assert np.array_equal(rec.inputs, alone.inputs) and np.array_equal(rec.outputs, alone.outputs)
        for key in alone.extras:
            assert np.array_equal(rec.extras[key], alone.extras[key]), key
    assert ("estimate" in batch.records[0].extras) == (kind == "MPC")
    assert not np.array_equal(batch.records[0].outputs, batch.records[1].outputs)


def test_stacked_loops_refuse_what_cannot_share_a_batch():
    p = PIDController(PIDGains(kp=1.0, ki=0.0, kd=0.0), 0.2)
    assert isinstance(stack_controllers([p, PIDController(p.gains, 0.2)]), StackedLoops)
    with pytest.raises(ConfigurationError, match="its own controller object"):
        stack_controllers([p, p])
    with pytest.raises(ConfigurationError, match="one sample time"):
        stack_controllers([p, PIDController(p.gains, 0.1)])
    with pytest.raises(ConfigurationError, match="sequence of controllers"):
        stack_controllers([object()])
