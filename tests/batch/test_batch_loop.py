"""The batched closed loop reproduces closed_loop on each twin alone, bit for bit."""

import numpy as np
import pytest

from trms.batch import batch_closed_loop, stack_controllers
from trms.control.loop import closed_loop, deviation_limits
from trms.errors import ConfigurationError, InputError
from trms.experiments.ch8_mimo_lqg import controllers, scenario_reference
from trms.experiments.ch67_lqg import case_setup
from trms.twin import Gust, Push, Twin, load_spec
from trms.twin.parameters import with_parameters
from trms.worlds import GUST, design_model


def _twins(config, ts, masses, pushes=()):
    spec = load_spec()
    return [
        Twin(
            config,
            ts,
            seed=10 + i,
            spec=with_parameters(spec, {"counterweight_mass": m}),
            noise_std=1e-3,
            gust=Gust(*GUST),
            pushes=pushes,
        )
        for i, m in enumerate(masses)
    ]


def _assert_same(a, b):
    assert a.input_names == b.input_names and a.output_names == b.output_names
    assert np.array_equal(a.time, b.time) and np.array_equal(a.inputs, b.inputs)
    assert np.array_equal(a.outputs, b.outputs)
    assert a.extras.keys() == b.extras.keys()
    for key in a.extras:
        assert np.array_equal(a.extras[key], b.extras[key]), key
    assert a.metadata == b.metadata


@pytest.mark.parametrize("kind", ["MIMO LQG", "two SISO loops"])
def test_two_dof_batch_is_bit_identical_to_serial_closed_loops(kind):
    masses = (0.07, 0.08, 0.09)
    push = (Push.impulse(3.0, 0.02, 0.15, "yaw"),)
    twins = _twins("2dof", 0.1, masses, push)
    ref = scenario_reference("pitch step", 0.1)[:120]
    make = lambda t: controllers(design_model("2dof"), limits=deviation_limits(t))[kind]  # noqa: E731
    batch = batch_closed_loop(twins, [make(t) for t in twins], ref, threads=2, metadata={"run": "x"})
    serial = [closed_loop(t, make(t), ref, metadata={"run": "x"}) for t in _twins("2dof", 0.1, masses, push)]
    assert all(e is None for e in batch.errors)
    for a, b in zip(batch.records, serial):
        _assert_same(a, b)
    assert not np.array_equal(batch.records[0].outputs, batch.records[2].outputs)


def test_one_dof_csas_batch_with_per_loop_seeds_is_bit_identical():
    twins = _twins("1dof", 0.2, (0.07, 0.09))
    setups = [case_setup(t, 125.0, "CSAS LPF 0.2 Hz", duration=30.0, model=design_model("1dof")) for t in twins]
    batch = batch_closed_loop(
        twins, [s[0] for s in setups], setups[0][1], prefilters=[s[2] for s in setups], seeds=[5, 6], threads=1
    )
    for rec, t, (c, r, p, _meta), seed in zip(batch.records, _twins("1dof", 0.2, (0.07, 0.09)), setups, (5, 6)):
        _assert_same(rec, closed_loop(t, c, r, prefilter=p, seed=seed))


def test_a_diverging_loop_stops_alone():
    twins = _twins("1dof", 0.2, (0.08, 0.08))
    good = case_setup(twins[0], 125.0, "SAS", duration=20.0, model=design_model("1dof"))[0]
    bad = case_setup(twins[1], 125.0, "SAS", duration=20.0, model=design_model("1dof"))[0]
    twins[1].model.dof_damping[:] = -1e6  # an unstable plant: the simulation blows up
    res = batch_closed_loop(twins, [good, bad], np.full(100, 0.1), threads=2)
    assert res.errors[0] is None and res.records[0] is not None
    assert res.records[1] is None and "diverged" in str(res.errors[1])


def test_bad_batches_are_refused():
    t1, t2 = Twin("1dof", 0.2), Twin("2dof", 0.1)
    c1 = case_setup(t1, 125.0, "SAS", model=design_model("1dof"))[0]
    with pytest.raises(InputError, match="share one configuration"):
        batch_closed_loop([t1, t2], [c1, c1], np.zeros(10))
    with pytest.raises(InputError, match="one per loop"):
        batch_closed_loop([t1], [c1, c1], np.zeros(10))
    with pytest.raises(ConfigurationError, match="sequence of controllers"):
        stack_controllers([object()])
    with pytest.raises(InputError, match="reference"):
        batch_closed_loop([t1], [c1], np.full(10, np.nan))


def test_actuator_delay_travels_in_the_full_physics_state():
    def twins():
        out = []
        for i, delay in enumerate((0.02, 0.05)):
            spec = load_spec()
            for act in spec.actuators:
                act.nsample, act.delay = 128, delay
            out.append(Twin("1dof", 0.2, seed=i, spec=spec, noise_std=1e-3))
        return out

    first = twins()
    assert first[0].model.nhistory > 0
    make = lambda t: case_setup(t, 125.0, "SAS", duration=20.0, model=design_model("1dof"))  # noqa: E731
    setups = [make(t) for t in first]
    batch = batch_closed_loop(first, [s[0] for s in setups], setups[0][1], threads=2)
    for rec, t, s in zip(batch.records, twins(), setups):
        _assert_same(rec, closed_loop(t, make(t)[0], s[1]))
