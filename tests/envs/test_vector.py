"""The vector environment: Gymnasium's SyncVectorEnv of the single environments, bit for bit, stepped in processes."""

import os
import signal
import subprocess
import sys

import gymnasium
import numpy as np
import psutil
import pytest

import trms.envs.gym  # noqa: F401  (registers the environments and their vector entry point)
from trms.envs.gym import InvalidActionError, InvalidSeedError, TwinTaskEnv
from trms.envs.shares import WorkerError
from trms.envs.tasks import TaskRunner
from trms.envs.vector import TwinVectorEnv
from trms.errors import DivergenceError, InputError


def _pair(task, n, normalised=False):
    sync = gymnasium.vector.SyncVectorEnv([lambda: TwinTaskEnv(task, normalised=normalised) for _ in range(n)])
    return sync, TwinVectorEnv(task, n, normalised=normalised, workers=2)  # two shares, whatever the machine


def _assert_same(a, b):
    for x, y in zip(a[:-1], b[:-1]):
        assert x.dtype == y.dtype and x.tobytes() == y.tobytes()
    assert set(a[-1]) == set(b[-1])
    for key, value in a[-1].items():
        assert np.array_equal(value, b[-1][key]), key


@pytest.mark.parametrize("task, steps", [("HoverGusts", 305), ("PitchTracking", 60), ("AttitudeTracking", 30)])
def test_each_environment_is_the_single_one_through_autoresets(task, steps):
    sync, vec = _pair(task, 3)
    _assert_same(sync.reset(seed=11), vec.reset(seed=11))
    trim = vec.operating_inputs
    rng = np.random.default_rng(0)
    for _ in range(steps):  # HoverGusts' 300-step episodes end and restart on the next step
        actions = trim + rng.uniform(-0.4, 0.4, (3, trim.size))
        _assert_same(sync.step(actions), vec.step(actions))
    assert vec.metadata["autoreset_mode"] == gymnasium.vector.AutoresetMode.NEXT_STEP
    vec.close()


def test_normalised_spaces_and_seeds_per_environment():
    sync, vec = _pair("PitchTracking", 2, normalised=True)
    assert vec.single_action_space == sync.single_action_space and vec.observation_space == sync.observation_space
    _assert_same(sync.reset(seed=[5, None]), vec.reset(seed=[5, None]))
    actions = np.array([[0.2], [-0.1]], np.float32)
    _assert_same(sync.step(actions), vec.step(actions))
    mask = np.array([False, True])
    _assert_same(sync.reset(seed=3, options={"reset_mask": mask}), vec.reset(seed=3, options={"reset_mask": mask}))


def test_make_vec_builds_it_from_the_registry():
    envs = gymnasium.make_vec("trms/HoverGusts-v0", num_envs=2)
    assert isinstance(envs.unwrapped, TwinVectorEnv) and envs.num_envs == 2
    obs, _ = envs.reset(seed=0)
    assert obs.shape == (2, len(envs.unwrapped.observation_names))
    envs.close()


def test_a_diverged_environment_ends_its_episode_and_restarts_on_the_next_step(monkeypatch):
    """Environment 1 (a worker process's, forked from this one with the patch) diverges at its first step."""
    probe = TaskRunner("PitchTracking")
    probe.reset(1)
    doomed, original = probe.reference.copy(), TaskRunner.step_volts

    def step_volts(self, volts):
        if np.array_equal(self.reference, doomed) and self.twin.time == 0.0:
            return self.diverged(DivergenceError("simulation diverged (forced)"))
        return original(self, volts)

    monkeypatch.setattr(TaskRunner, "step_volts", step_volts)
    vec = TwinVectorEnv("PitchTracking", 2, workers=2, start_method="fork")
    vec.reset(seed=0)
    trim = np.tile(vec.operating_inputs, (2, 1))
    obs, reward, terminated, truncated, info = vec.step(trim)
    assert terminated.tolist() == [False, True] and reward[1] == 0.0 and info["_diverged"].tolist() == [False, True]
    assert info["diverged"][1] == "simulation diverged (forced)" and info["time"][1] == 0.0
    obs, reward, terminated, truncated, info = vec.step(trim)  # the next step resets it: its action is ignored
    assert reward[1] == 0.0 and not terminated.any() and info["time"][1] == 0.0 and info["_reference"][1]
    vec.close()


def test_an_interrupted_step_asks_for_a_reset_and_the_workers_carry_on(monkeypatch):
    sync, vec = _pair("AttitudeTracking", 2)
    _assert_same(sync.reset(seed=4), vec.reset(seed=4))
    trim = np.tile(vec.operating_inputs, (2, 1))

    def interrupted(volts):
        raise KeyboardInterrupt

    monkeypatch.setattr(vec.runners[0], "step_volts", interrupted)
    with pytest.raises(KeyboardInterrupt):
        vec.step(trim)  # Ctrl-C in this process's share, while the worker steps its own
    monkeypatch.undo()
    with pytest.raises(gymnasium.error.ResetNeeded, match="interrupted"):
        vec.step(trim)
    _assert_same(sync.reset(seed=5), vec.reset(seed=5))
    for _ in range(3):
        _assert_same(sync.step(trim), vec.step(trim))
    vec.close()


def test_a_worker_that_ends_is_reported_and_close_stops_the_others():
    vec = TwinVectorEnv("PitchTracking", 3, workers=3)
    vec.reset(seed=0)
    first, second = vec.processes
    os.kill(first, signal.SIGKILL)
    psutil.Process(first).wait(timeout=10)
    with pytest.raises(WorkerError, match=r"environments \[1\] ended"):
        vec.step(np.tile(vec.operating_inputs, (3, 1)))
    vec.close()
    assert not psutil.pid_exists(second) or psutil.Process(second).status() == psutil.STATUS_ZOMBIE


@pytest.mark.parametrize(
    "actions, match",
    [
        (np.zeros((3, 1)), r"actions must have shape \(2, 1\)"),
        (np.array([[0.0], [np.nan]]), r"action \(u1\) in V"),
        (np.array([["a"], ["b"]]), r"action \(u1\) in V"),
        (np.array([[1j], [0.0]]), r"action \(u1\) in V"),
    ],
)
def test_malformed_actions_are_refused_in_one_line_and_change_nothing(actions, match):
    vec = TwinVectorEnv("PitchTracking", 2, workers=1)
    vec.reset(seed=0)
    with pytest.raises(InvalidActionError, match=match):
        vec.step(actions)
    assert [r.twin.time for r in vec.runners] == [0.0, 0.0]


def test_misuse_is_refused():
    vec = TwinVectorEnv("PitchTracking", 2, workers=1)
    with pytest.raises(gymnasium.error.ResetNeeded):
        vec.step(np.zeros((2, 1)))
    for kwargs, match in (
        ({"options": {"foo": 1}}, r"unknown reset option 'foo'"),
        ({"options": {"reset_mask": np.zeros(2, bool)}}, r"reset_mask = .* must be a numpy bool array"),
    ):
        with pytest.raises(InputError, match=match):
            vec.reset(**kwargs)
    for kwargs, match in (
        ({"num_envs": 0}, r"num_envs = 0 must be a whole number >= 1"),
        ({"num_envs": 2, "workers": 1.5}, r"workers = 1\.5 must be a whole number >= 1"),
        ({"num_envs": 2, "start_method": "thread"}, r"unknown start_method 'thread'; allowed: "),
        ({"num_envs": 2, "max_episode_steps": 10}, r"a PitchTracking episode is 200 steps"),
    ):
        with pytest.raises(InputError, match=match):
            TwinVectorEnv("PitchTracking", **kwargs)


@pytest.mark.parametrize(
    "seed, match",
    [
        ([1], r"reset seed = \[1\] has 1 seeds; allowed: one per environment \(2\)"),
        ([3, -1], r"reset seed\[1\] = -1 \(int\); allowed: None or a whole number >= 0"),
        ([3, 1.5], r"reset seed\[1\] = 1\.5 \(float\)"),
        ((True, 3), r"reset seed\[0\] = True \(bool\)"),
        ([None, "a"], r"reset seed\[1\] = 'a' \(str\)"),
        (-5, r"reset seed = -5 \(int\); allowed: None or a whole number >= 0 \(int\), or a list of 2 of them"),
        (np.int64(-1), r"reset seed = np\.int64\(-1\) \(int64\)"),
        ("x", r"reset seed = 'x' \(str\)"),
        (2.0, r"reset seed = 2\.0 \(float\)"),
    ],
)
def test_a_bad_seed_is_refused_in_one_line_before_any_environment_resets(seed, match):
    vec = TwinVectorEnv("PitchTracking", 2, workers=1)
    vec.reset(seed=0)
    vec.step(np.tile(vec.operating_inputs, (2, 1)))
    before = [(r.twin.time, r.reference.tobytes()) for r in vec.runners]
    with pytest.raises(InvalidSeedError, match=match) as info:
        vec.reset(seed=seed)
    assert isinstance(info.value, gymnasium.error.Error) and isinstance(info.value, InputError)
    assert "\n" not in str(info.value)
    assert [(r.twin.time, r.reference.tobytes()) for r in vec.runners] == before  # no environment reset


def test_seeds_set_each_environments_episodes_as_the_single_environments():
    """An int seeds environment i with seed + i, a list one each; later resets without a seed (and autoresets) draw
    each environment's next episode from its own sequence; numpy integers are seeds too."""
    sync, vec = _pair("PitchTracking", 3)
    for seed in (7, [np.int64(4), None, 9], None, None):
        _assert_same(sync.reset(seed=seed), vec.reset(seed=seed))
    first = vec.reset(seed=7)[0]
    assert not np.array_equal(first[0], first[1])  # different seeds: different references
    again = TwinVectorEnv("PitchTracking", 3, workers=2)
    assert again.reset(seed=7)[0].tobytes() == first.tobytes()  # same seed, same bits
    assert again.reset(seed=[8, 9, 7])[0][2].tobytes() == first[0].tobytes()  # environment 0's seed 7, anywhere


def test_against_a_stop_each_environment_is_still_the_single_one():
    sync, vec = _pair("PitchTracking", 2)
    _assert_same(sync.reset(seed=1), vec.reset(seed=1))
    touched = 0
    for _ in range(60):  # full thrust: the beam climbs onto its stop and rests there
        _assert_same(sync.step(np.full((2, 1), 10.0)), vec.step(np.full((2, 1), 10.0)))
        touched += sum(env.runner.twin.channels()["at_stop"][0] for env in sync.envs)
    assert touched > 40  # the solver's warm start kept in each twin's own data: the same bits on the stop too


def test_a_closed_environment_refuses_to_step():
    with TwinVectorEnv("PitchTracking", 2, workers=2) as vec:
        vec.reset(seed=0)
    assert vec.closed and vec.processes == []
    for call in (lambda: vec.step(np.zeros((2, 1))), lambda: vec.reset(seed=0)):
        with pytest.raises(gymnasium.error.ClosedEnvironmentError, match="this vector environment is closed"):
            call()
    vec.close()  # again: nothing to do


def test_an_environment_a_masked_reset_left_out_is_refused_a_step_until_it_is_reset():
    vec = TwinVectorEnv("PitchTracking", 3, workers=2)
    vec.reset(seed=0, options={"reset_mask": np.array([True, False, False])})
    with pytest.raises(gymnasium.error.ResetNeeded, match=r"environments \[1, 2\] were never reset"):
        vec.step(np.tile(vec.operating_inputs, (3, 1)))
    vec.reset(seed=1, options={"reset_mask": np.array([False, True, True])})
    assert vec.step(np.tile(vec.operating_inputs, (3, 1)))[4]["_time"].all()
    vec.close()


def test_seeds_as_an_integer_array_are_one_each_and_bad_options_or_rows_are_named():
    sync, vec = _pair("PitchTracking", 2)
    _assert_same(sync.reset(seed=[3, 4]), vec.reset(seed=np.array([3, 4])))
    with pytest.raises(InputError, match=r"^reset options = 'x' must be a dict or None$"):
        vec.reset(options="x")
    with pytest.raises(InvalidActionError, match=r"^actions\[1\]: action \(u1\) in V"):
        vec.step(np.array([[0.0], [np.nan]]))
    with pytest.raises(InputError, match=r"render_mode = 'rgb_array': the vector environment draws nothing"):
        gymnasium.make_vec("trms/PitchTracking-v0", num_envs=2, render_mode="rgb_array")
    assert vec.metadata["render_modes"] == []
    vec.close()


_ORPHAN = """
import os, sys
import trms.envs.gym
from trms.envs.vector import TwinVectorEnv
vec = TwinVectorEnv("PitchTracking", 3, workers=3, start_method=sys.argv[1])
print(*vec.processes, flush=True)
os._exit(0)  # no close, no exit handlers: as a crash or a kill would leave them
"""


def test_workers_end_when_their_parent_dies_without_closing(tmp_path):
    script = tmp_path / "orphan.py"
    script.write_text(_ORPHAN)
    out = subprocess.run([sys.executable, str(script), "fork"], capture_output=True, text=True, check=True).stdout
    pids = [int(p) for p in out.split()]
    assert len(pids) == 2
    gone, alive = psutil.wait_procs([psutil.Process(p) for p in pids if psutil.pid_exists(p)], timeout=10)
    assert not alive


def test_close_ends_a_worker_that_does_not_answer():
    vec = TwinVectorEnv("PitchTracking", 2, workers=2)
    vec.reset(seed=0)
    (pid,) = vec.processes
    os.kill(pid, signal.SIGSTOP)
    vec.close()
    assert not psutil.pid_exists(pid) or psutil.Process(pid).status() == psutil.STATUS_ZOMBIE


def test_a_spawned_worker_without_the_main_guard_is_reported_with_the_cause(tmp_path):
    script = tmp_path / "unguarded.py"
    script.write_text(
        "import numpy\nimport trms.envs.gym\nfrom trms.envs.vector import TwinVectorEnv\n"
        'TwinVectorEnv("PitchTracking", 2, workers=2, start_method="spawn")\n'
    )
    run = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=120)
    last = run.stderr.strip().splitlines()[-1]
    assert run.returncode != 0 and last.startswith("trms.envs.shares.WorkerError: the worker process of environments")
    assert 'build the vector environment under if __name__ == "__main__":' in last
