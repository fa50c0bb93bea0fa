"""A whole open-loop record as native rollouts: the same bits as stepping it, the same twin after, the same refusals."""

import mujoco
import numpy as np
import pytest

from trms.errors import DivergenceError, InputError
from trms.plant import drive
from trms.twin import Gust, Push, Twin
from trms.twin import open_loop as open_loop_module
from trms.twin.disturbances import MOVING_AIR

_INTEGRATION = mujoco.mjtState.mjSTATE_INTEGRATION


def _prbs(twin, n, amplitude, seed):
    rng = np.random.default_rng(seed)
    return twin.operating_point.inputs + amplitude * rng.choice([-1.0, 1.0], size=(n, len(twin.input_names)))


def _state(twin):
    buf = np.empty(mujoco.mj_stateSize(twin.model, _INTEGRATION))
    mujoco.mj_getState(twin.model, twin.data, buf, _INTEGRATION)
    return buf


def _assert_same_record(native, stepped):
    assert native.equals(stepped)  # every array bit, name and metadata entry


CASES = {
    # config, sample time, twin options, samples, amplitude (V)
    "2dof, the benchmark's run": ("2dof", 0.1, {}, 600, 0.5),
    "2dof, gusts and overlapping pushes": (
        "2dof",
        0.1,
        {"gust": MOVING_AIR, "pushes": [Push(3.0, 0.2, (0.02, 0.01)), Push(3.1, 0.3, (0.0, -0.02))]},
        80,
        0.5,
    ),
    "1dof, onto the stops": ("1dof", 0.2, {}, 150, 1.0),
    "1dof, still air": ("1dof", 0.05, {"still_air": True}, 100, 0.3),
    "1dof, a finer physics step, noise without counts": (
        "1dof",
        0.012,
        {"counts_per_rev": 0, "noise_std": 0.001},
        150,
        0.3,
    ),
    "yaw rig, gusts, against its stops": ("yaw", 0.1, {"gust": Gust(0.002, 0.5)}, 150, 2.0),
    "2dof, slammed into both stops": ("2dof", 0.1, {}, 120, 6.0),
    "1dof, a push, nothing else moving": ("1dof", 0.1, {"pushes": [Push.impulse(2.0, 0.05, 0.2)]}, 60, 0.0),
}


@pytest.mark.parametrize("case", list(CASES))
def test_a_native_run_is_the_stepped_run_bit_for_bit_and_leaves_the_same_twin(case):
    config, ts, options, n, amplitude = CASES[case]
    native, stepped = (Twin(config, ts, seed=3, **options) for _ in range(2))
    u = _prbs(native, n, amplitude, seed=n)
    record = native.run(u)
    reference = drive(stepped, n, lambda k, y: u[k], 3, dict(record.metadata))
    _assert_same_record(record, reference)
    # the data's every field (not only the state), the warm start and the random generators: the same from here on
    for field in ("qpos", "qvel", "act", "qacc_warmstart", "ctrl", "qfrc_applied", "xpos", "sensordata"):
        assert getattr(native.data, field).tobytes() == getattr(stepped.data, field).tobytes(), field
    assert native.data.warning.number.tolist() == stepped.data.warning.number.tolist()
    assert all(np.array_equal(native.channels()[k], v) for k, v in stepped.channels().items())
    assert [native.step(x).tolist() for x in u[:5]] == [stepped.step(x).tolist() for x in u[:5]]
    assert _state(native).tobytes() == _state(stepped).tobytes()


def test_a_long_record_runs_in_chunks_with_the_same_bits(monkeypatch):
    twin = Twin("2dof", 0.1, seed=1, gust=MOVING_AIR, pushes=[Push(1.23, 0.5, (0.01, -0.01))])
    u = _prbs(twin, 90, 0.5, seed=5)
    whole = twin.run(u)
    calls = []
    roll = open_loop_module.rollout.Rollout.rollout
    monkeypatch.setattr(open_loop_module, "CHUNK_STEPS", 7 * twin._nsub)  # 13 chunks, the last one short
    monkeypatch.setattr(
        open_loop_module.rollout.Rollout,
        "rollout",
        lambda self, *a, **k: calls.append(k["nstep"]) or roll(self, *a, **k),
    )
    _assert_same_record(twin.run(u), whole)
    assert calls == [7 * twin._nsub] * 12 + [6 * twin._nsub]


def test_run_takes_the_native_path_and_an_empty_run_is_a_reset(monkeypatch):
    twin = Twin("1dof", 0.1, seed=2)
    steps = []
    monkeypatch.setattr(twin, "step", lambda u: steps.append(u))
    record = twin.run(_prbs(twin, 40, 0.3, seed=0))
    assert len(record) == 40 and steps == []  # no Python step per interval
    empty = twin.run(np.empty((0, 1)))
    assert len(empty) == 0 and empty.extras["qpos"].shape == (0, twin.model.nq) and twin.time == 0.0


def test_a_model_whose_sensors_no_longer_hold_its_state_is_stepped():
    native, stepped = Twin("1dof", 0.1, seed=4), Twin("1dof", 0.1, seed=4)
    for twin in (native, stepped):
        twin.model.actuator_gainprm[0, 0] = 1.0 + 2**-40  # the thrust's force is no longer its activation
    u = _prbs(native, 30, 0.3, seed=1)
    assert native.open_loop(u) is None
    _assert_same_record(native.run(u), drive(stepped, 30, lambda k, y: u[k], 4, native.run(u).metadata))


def test_a_diverging_run_raises_as_stepping_does_and_leaves_the_same_twin(runaway_spec):
    native, stepped = (Twin("1dof", 0.1, spec=runaway_spec(), counts_per_rev=0) for _ in range(2))
    u = np.tile(native.operating_point.inputs, (12, 1))
    u[4:, 0] = 10.0
    errors = []
    for run in (native.run, lambda x: drive(stepped, len(x), lambda k, y: x[k], None)):
        with pytest.raises(DivergenceError) as info:
            run(u)
        errors.append(str(info.value))
    assert errors[0] == errors[1] and "diverged at t = 0.4" in errors[0]
    assert native.time == stepped.time == pytest.approx(0.4)
    assert _state(native).tobytes() == _state(stepped).tobytes()


@pytest.mark.parametrize(
    "inputs, match",
    [
        (np.full((5, 2), 1.0), r"inputs \(u1\) in V must have shape"),
        (np.array([[1.0], [np.nan]]), r"inputs \(u1\) in V"),
    ],
)
def test_bad_inputs_are_refused_before_the_twin_moves(inputs, match):
    twin = Twin("1dof", 0.1)
    twin.step(twin.operating_point.inputs + 0.5)
    before = _state(twin)
    with pytest.raises(InputError, match=match):
        twin.open_loop(inputs)
    assert _state(twin).tobytes() == before.tobytes() and twin.time == pytest.approx(0.1)
