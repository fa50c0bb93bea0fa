"""Faults in the twin: each starts when stated, does what it says, and leaves the healthy rig on reset."""

from __future__ import annotations

import math

import numpy as np
import pytest

from trms.errors import InputError
from trms.plant import simulate
from trms.twin import Twin
from trms.twin.faults import EncoderDropout, FaultyTwin, StuckRotor, ThrustLoss


@pytest.fixture(scope="module")
def twin2():
    return Twin("2dof", 0.1)


def _square(plant, n=120):
    op = plant.operating_point.inputs
    wave = np.where((np.arange(n) // 30) % 2 == 0, 0.3, -0.3)
    return op + np.column_stack([wave, -wave])[:, : len(op)]


def test_a_thrust_loss_starts_at_its_time_and_reset_restores_the_healthy_rig(twin2):
    healthy = simulate(twin2, _square(twin2), seed=3)
    gear = twin2.model.actuator_gear.copy()
    plant = FaultyTwin(twin2, [ThrustLoss("u1", 0.4, at=6.0)])
    faulty = simulate(plant, _square(twin2), seed=3)
    # bit-identical before the fault (samples 0..60 depend on intervals before t = 6 s), different after
    np.testing.assert_array_equal(faulty.outputs[:61], healthy.outputs[:61])
    assert np.max(np.abs(faulty.outputs[70:, 0] - healthy.outputs[70:, 0])) > 0.05
    # row k's flag: the interval held from t_k is faulty (the record's timing convention)
    assert faulty.extras["faults"][:60].sum() == 0 and faulty.extras["faults"][60:].all()
    main = twin2.model.actuator("main_rotor").id
    np.testing.assert_allclose(twin2.model.actuator_gear[main], 0.6 * gear[main])
    plant.reset(seed=3)
    np.testing.assert_array_equal(twin2.model.actuator_gear, gear)
    again = simulate(plant, _square(twin2), seed=3)
    np.testing.assert_array_equal(again.outputs, faulty.outputs)  # the same seed, the same bits
    twin2.reset()


def test_a_stuck_rotor_keeps_its_voltage_whatever_the_command(twin2):
    plant = FaultyTwin(twin2, [StuckRotor("u2", at=2.0)])
    command = twin2.operating_point.inputs + np.random.default_rng(4).uniform(-0.5, 0.5, (60, 2))
    held = []
    plant.reset(seed=1)
    for u in command:
        plant.step(u)
        held.append(plant.applied_input[1])
    held = np.array(held)
    assert np.ptp(held[20:]) == 0.0 and held[20] == held[19]  # stuck at the voltage it had when the fault began
    np.testing.assert_array_equal(held[:20], command[:20, 1])  # the command moves it until then
    fixed = FaultyTwin(twin2, [StuckRotor("u2", at=0.0, volts=0.0)])
    fixed.reset(seed=1)
    fixed.step(_square(twin2)[0])
    assert fixed.applied_input[1] == 0.0
    twin2.reset()


def test_an_encoder_dropout_freezes_the_reading_for_its_duration_while_the_beam_moves(twin2):
    plant = FaultyTwin(twin2, [EncoderDropout("pitch", at=3.0, duration=4.0)])
    rec = simulate(plant, _square(twin2), seed=2)
    pitch, true_pitch = rec.outputs[:, 0], rec.extras["true_angles"][:, 0]
    frozen = pitch[31:71]
    assert np.ptp(frozen) == 0.0 and np.ptp(true_pitch[31:71]) > 0.05
    assert np.ptp(pitch[72:]) > 0.0  # the reading resumes
    flags = rec.extras["faults"][:, 0]
    assert not flags[:30].any() and flags[30:70].all() and not flags[70:].any()
    twin2.reset()


@pytest.mark.parametrize(
    "fault, match",
    [
        (ThrustLoss("u1", 0.4, at=-1.0), r"faults\[0\].at = -1.0 s is outside the allowed range \[0.0 s, "),
        (ThrustLoss("u1", 0.4, at=math.inf), r"faults\[0\].at = inf s is outside the allowed range \[0.0 s, "),
        (ThrustLoss("u1", 1.0, at=1.0), r"faults\[0\].loss = 1.0 is outside the allowed range \(0, 1\)"),
        (ThrustLoss("u1", 0.0, at=1.0), r"faults\[0\].loss = 0.0 is outside the allowed range \(0, 1\)"),
        (ThrustLoss("u1", "big", at=1.0), r"faults\[0\].loss = 'big' is outside the allowed range \(0, 1\)"),
        (ThrustLoss("u3", 0.4, at=1.0), r"faults\[0\].input 'u3' is not driven; allowed: \('u1', 'u2'\)"),
        (StuckRotor("u2", at=1.0, volts=12.0), r"faults\[0\].volts = 12.0 V is outside the allowed range"),
        (EncoderDropout("roll", at=1.0), r"faults\[0\].output 'roll' is not measured"),
        (EncoderDropout("pitch", at=1.0, duration=0.0), r"faults\[0\].duration = 0.0 s is outside"),
        ("stuck", r"faults\[0\] must be a ThrustLoss, StuckRotor or EncoderDropout, got 'stuck'"),
    ],
)
def test_impossible_faults_are_refused_in_one_line(twin2, fault, match):
    with pytest.raises(InputError, match=match):
        FaultyTwin(twin2, [fault])


def test_the_twin_gets_its_healthy_gears_back_whoever_wraps_it_next(twin2):
    gear = twin2.model.actuator_gear.copy()
    simulate(FaultyTwin(twin2, [ThrustLoss("u1", 0.4, at=0.0)]), _square(twin2, 10), seed=1)
    assert not np.array_equal(twin2.model.actuator_gear, gear)  # damaged after the run, until restored
    again = FaultyTwin(twin2, [])  # a new wrapper does not take the damaged gears for healthy ones
    again.restore()
    np.testing.assert_array_equal(twin2.model.actuator_gear, gear)
    twin2.reset()


def test_a_twin_is_required_and_a_one_dof_twin_has_no_tail_rotor():
    with pytest.raises(InputError, match="twin must be a Twin, got str"):
        FaultyTwin("twin", [])  # type: ignore[arg-type]
    with pytest.raises(InputError, match="faults must be a list or tuple of faults, got ThrustLoss"):
        FaultyTwin(Twin("1dof", 0.1), ThrustLoss("u1", 0.4, at=1.0))  # type: ignore[arg-type]
    with pytest.raises(InputError, match=r"input 'u2' is not driven; allowed: \('u1',\)"):
        FaultyTwin(Twin("1dof", 0.1), [StuckRotor("u2", at=1.0)])
    assert math.isinf(EncoderDropout("pitch", 1.0).duration)
