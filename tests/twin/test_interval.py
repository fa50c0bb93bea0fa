"""One control interval of the twin in MuJoCo: a located divergence with an exact restore, and end stops
touched between samples (recorded or replayed intervals, bit-identical to a plain step)."""

import mujoco
import numpy as np
import pytest

from trms.errors import DivergenceError
from trms.plant import drive
from trms.twin import Twin, load_spec


def test_divergence_is_reported_and_the_state_restored():
    spec = load_spec()
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST  # explicit in the stiffness (discrete is not)
    for j in spec.joints:
        if "flex" in j.name:
            j.armature = 0.0
            j.stiffness[0] = 5e6  # omega * dt far beyond the integrator's stability limit
    twin = Twin("1dof", 0.05, spec=spec, counts_per_rev=0)
    twin.reset()
    before = twin.data.qpos.copy()
    with pytest.raises(
        DivergenceError, match=r"diverged at t = 0.0\d\d s \(physics step .* last finite state .* qpos = "
    ):
        for _ in range(5):
            twin.step(twin.operating_point.inputs + 8.0)
    assert twin.time == 0.0 and np.array_equal(twin.data.qpos, before)


# ---------------------------------------------------------------- end stops between samples
_YAW_NEAR_STOP = -2.9989  # rad, 1.1 mrad inside the -3 rad stop


def _sensorless_spec():
    spec = load_spec()
    for sensor in list(spec.sensors):
        spec.delete(sensor)
    return spec


def _near_the_yaw_stop(twin, yaw_rate):
    """Put ``twin`` (2-DOF) at the hover trim with yaw 1.1 mrad off its stop, turning at ``yaw_rate`` (rad/s)."""
    twin.reset()
    twin.data.qpos[twin.model.joint("yaw").qposadr[0]] = _YAW_NEAR_STOP
    twin.data.qvel[twin.model.joint("yaw").dofadr[0]] = yaw_rate
    mujoco.mj_forward(twin.model, twin.data)


def _pitch_onto_its_stop(twin, seconds):
    """Hover trim voltages, but 10 V on the main rotor from 0.5 s to 2 s: the beam climbs onto its upper stop."""
    n = int(round(seconds / twin.sample_time))
    u = np.tile(twin.operating_point.inputs, (n, 1))
    u[int(round(0.5 / twin.sample_time)) : int(round(2.0 / twin.sample_time)), 0] = 10.0
    return u


@pytest.mark.parametrize(
    "yaw_rate, ts, sensors",
    [(-1.0, 0.1, True), (-0.2, 0.1, True), (0.3, 0.1, True), (-1.0, 0.5, True), (-1.0, 0.1, False), (-0.2, 0.5, False)],
)
def test_at_stop_flags_every_interval_that_touched_a_stop_between_samples(yaw_rate, ts, sensors):
    # Truth: the same run sampled at every physics step (mj_step(m, d, n) is n mj_step calls),
    # so its positions say at which steps a stop was touched (MuJoCo's rule, margin 0: past the stop). With and
    # without the model's joint-position sensors (what the recording reads), over one and several rollout chunks.
    spec = None if sensors else _sensorless_spec()
    coarse = Twin("2dof", ts, still_air=True, spec=spec)
    fine = Twin("2dof", coarse.model.opt.timestep, still_air=True, spec=spec)
    _near_the_yaw_stop(coarse, yaw_rate)
    _near_the_yaw_stop(fine, yaw_rate)
    fine_angles = [fine.channels()["true_angles"]]
    for u in _pitch_onto_its_stop(fine, 3.0):
        fine.step(u)
        fine_angles.append(fine.channels()["true_angles"])
    q = np.array(fine_angles)
    lo, hi = (np.array([coarse.model.jnt_range[coarse.model.joint(a).id][i] for a in ("pitch", "yaw")]) for i in (0, 1))
    touched = (q < lo) | (q > hi)
    n = coarse._nsub
    got, truth = [], []
    for k, u in enumerate(_pitch_onto_its_stop(coarse, 3.0)):
        coarse.step(u)
        got.append(coarse.channels()["at_stop"])
        truth.append(touched[n * k : n * (k + 1) + 1].any(axis=0))
        assert np.array_equal(coarse.channels()["true_angles"], q[n * (k + 1)])  # the same trajectory, bit for bit
    got, truth = np.array(got), np.array(truth)
    assert np.array_equal(got, truth)
    assert got[:, 0].any() and got[:, 1].any() and not got.all()
    at_samples = touched[::n]
    between = got & ~at_samples[:-1] & ~at_samples[1:]  # touched, yet neither sample of the interval is at a stop
    assert between.any()


@pytest.mark.parametrize("path", ["recorded", "replayed"])
def test_finding_a_touch_between_samples_leaves_the_twin_bit_identical_to_a_plain_step(path, monkeypatch):
    twin = Twin("2dof", 0.1, still_air=True)
    _near_the_yaw_stop(twin, -1.0)  # bounces off the yaw stop within the first 2 ms, away by the next sample
    if path == "replayed":  # as if the start looked far from the stop: the end's check replays on scratch data
        monkeypatch.setattr(twin, "_stop_ahead", lambda start: False)
    u = twin.operating_point.inputs
    controls, _, _ = twin.interval_controls(u)  # what the step feeds MuJoCo
    plain = mujoco.MjData(twin.model)
    spec = mujoco.mjtState.mjSTATE_INTEGRATION
    state = np.empty(mujoco.mj_stateSize(twin.model, spec))
    mujoco.mj_getState(twin.model, twin.data, state, spec)
    mujoco.mj_setState(twin.model, plain, state, spec)
    plain.ctrl[:] = controls[0, : twin.model.nu]
    mujoco.mj_step(twin.model, plain, twin._nsub)
    twin.step(u)
    assert twin.channels()["at_stop"].tolist() == [False, True]  # both samples are off the stop
    assert twin.channels()["true_angles"][1] > _YAW_NEAR_STOP
    assert (twin._replay_data is not None) == (path == "replayed")
    after = np.empty_like(state)
    mujoco.mj_getState(twin.model, twin.data, after, spec)
    mujoco.mj_getState(twin.model, plain, state, spec)
    assert np.array_equal(after, state)
    assert np.array_equal(twin.data.warning.number, plain.warning.number)


def test_the_batched_interval_reports_the_same_stops_as_step():
    from mujoco import rollout

    stepped, batched = Twin("2dof", 0.1, still_air=True), Twin("2dof", 0.1, still_air=True)
    _near_the_yaw_stop(stepped, -1.0)
    _near_the_yaw_stop(batched, -1.0)
    data = mujoco.MjData(batched.model)
    spec = mujoco.mjtState.mjSTATE_CTRL | mujoco.mjtState.mjSTATE_QFRC_APPLIED
    flags = []
    for u in _pitch_onto_its_stop(stepped, 3.0):
        stepped.step(u)
        controls, start, warm = batched.interval_controls(u)
        states, _ = rollout.rollout(
            batched.model, data, start[None], controls[None], control_spec=spec, initial_warmstart=warm[None]
        )
        batched.finish_interval(states[0, -1], start)
        flags.append(stepped.channels()["at_stop"])
        assert np.array_equal(batched.channels()["at_stop"], flags[-1])
    assert np.array(flags)[:, 0].any() and np.array(flags)[:, 1].any()


def test_intervals_far_from_the_stops_run_as_before(monkeypatch):
    twin = Twin("2dof", 0.1, seed=0)  # turbulence and noise on, as in the speed benchmark
    runs = {"recorded": 0, "replayed": 0}
    record = twin._run_recorded

    def count(data, volts):
        runs["recorded" if data is twin.data else "replayed"] += 1
        return record(data, volts)

    monkeypatch.setattr(twin, "_run_recorded", count)
    rng = np.random.default_rng(0)
    trim = twin.operating_point.inputs

    def stepped(u):  # interval by interval, as a closed loop steps it (Twin.run rolls the whole record out)
        return drive(twin, len(u), lambda k, y: u[k], 0)

    assert not stepped(trim + 0.1 * rng.choice([-1.0, 1.0], size=(600, 2))).extras["at_stop"].any()
    assert runs == {"recorded": 0, "replayed": 0}  # hovering: one native mj_step per interval, nothing else
    rec = stepped(trim + 0.5 * rng.choice([-1.0, 1.0], size=(1200, 2)))  # the speed benchmark's inputs
    assert rec.extras["at_stop"].any()  # it drifts onto the stops now and then ...
    assert runs["recorded"] < 0.25 * 1200 and runs["replayed"] < 0.02 * 1200  # ... and only then is recorded
    locked = Twin("1dof", 0.1)  # a locked axis has no stop to touch
    assert not locked.run(np.full((30, 1), 10.0)).extras["at_stop"][:, 1].any()
