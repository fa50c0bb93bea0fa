"""The vector environment's shares: the shared rows, a share stepping as the single environments, a worker process."""

import multiprocessing
import pickle

import numpy as np
import pytest

from trms.envs.shares import DIVERGED, RESET, STEP, STEPPED, Assignment, Share, Slots, Worker, WorkerError
from trms.envs.tasks import TaskRunner
from trms.errors import DivergenceError


def _slots(n=3, dims=(2, 2, 8)):
    return Slots(multiprocessing.RawArray("b", Slots.size(n, *dims)), n, *dims)


def test_every_field_has_its_own_aligned_rows():
    slots = _slots()
    fields = {name: getattr(slots, name) for name in vars(slots)}
    assert {f.shape for f in (fields["actions"], fields["applied"], fields["saturated"])} == {(3, 2)}
    assert fields["observations"].shape == (3, 8) and fields["kind"].shape == (3,)
    written: set[str] = set()
    for name, array in fields.items():
        assert array.ctypes.data % array.dtype.itemsize == 0, name
        array[...] = 1  # every field written in turn: no other field changes
        written.add(name)
        assert all((other != 0).all() == (key in written) for key, other in fields.items()), name
    assert sum(a.nbytes for a in fields.values()) == Slots.size(3, 2, 2, 8)


def test_a_share_steps_each_environment_as_the_single_one_through_an_autoreset():
    slots = _slots(2, (2, 2, 8))
    share = Share({0: TaskRunner("HoverGusts"), 1: TaskRunner("HoverGusts")}, slots)
    singles = [TaskRunner("HoverGusts"), TaskRunner("HoverGusts")]
    share.reset({0: 4, 1: 5})
    first = [r.reset(seed) for r, seed in zip(singles, (4, 5))]
    assert slots.observations.tobytes() == np.array(first).tobytes() and slots.kind.tolist() == [RESET, RESET]
    rng = np.random.default_rng(1)
    for k in range(singles[0].task.n_steps + 1):
        slots.actions[:] = singles[0].twin.operating_point.inputs + rng.uniform(-0.5, 0.5, (2, 2))
        assert share.step() == {}
        for i, single in enumerate(singles):
            if k < single.task.n_steps:
                obs, reward, terminated, truncated, info = single.step_volts(slots.actions[i].copy())
                assert slots.kind[i] == STEPPED and slots.rewards[i] == reward and slots.truncated[i] == truncated
                assert slots.applied[i].tobytes() == info["applied_volts"].tobytes() and slots.time[i] == info["time"]
            else:  # the episode ended at the last step: this one resets it
                obs = single.reset()
                assert slots.kind[i] == RESET and slots.reference[i].tobytes() == single.current_reference.tobytes()
            assert slots.observations[i].tobytes() == obs.tobytes()
        slots.autoreset[:] = slots.terminated | slots.truncated


def test_a_share_reports_a_diverged_environment(monkeypatch):
    slots = _slots(1, (1, 1, 4))
    share = Share({0: TaskRunner("PitchTracking")}, slots)
    share.reset({0: 0})
    runner = share.runners[0]

    def blow_up(u):
        raise DivergenceError("simulation diverged (forced)")

    monkeypatch.setattr(runner.twin, "step_checked", blow_up)
    slots.actions[:] = runner.twin.operating_point.inputs
    assert share.step() == {0: "simulation diverged (forced)"}
    assert slots.kind[0] == DIVERGED and slots.terminated[0] and slots.rewards[0] == 0.0


def test_a_worker_steps_its_share_and_reports_an_error_in_one_line():
    dims = (2, 1, 1, 4)
    block = multiprocessing.RawArray("b", Slots.size(*dims))
    slots = Slots(block, *dims)
    worker = Worker(multiprocessing.get_context("fork"), Assignment("PitchTracking", [1], block, dims))
    assert worker.receive() == {}  # ready
    worker.send(STEP)  # no episode started: the runner refuses, the worker says so
    with pytest.raises(WorkerError, match=r"^environments \[1\]: InputError: no episode is running") as info:
        worker.receive()
    assert "\n" not in str(info.value)
    worker.send(pickle.dumps({1: 3}))
    worker.receive()
    single = TaskRunner("PitchTracking")
    assert slots.observations[1].tobytes() == single.reset(3).tobytes() and slots.observations[0].tolist() == [0] * 4
    slots.actions[1] = 1.0
    worker.send(STEP)
    assert worker.receive() == {} and slots.observations[1].tobytes() == single.step_volts(np.ones(1))[0].tobytes()
    worker.stop()
    assert not worker.process.is_alive() and worker.process.exitcode == 0
