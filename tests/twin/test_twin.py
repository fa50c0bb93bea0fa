"""The Twin as a Plant: trim, sampling, saturation, sensors, disturbances, determinism, bad input."""

import mujoco
import numpy as np
import pytest

from trms.errors import ConfigurationError, InputError
from trms.plant import Plant
from trms.twin import Gust, Push, Twin, check_sample_time, load_spec


def test_twin_is_a_plant_and_resets_to_flat_hover(twin_factory):
    twin = twin_factory("2dof", still_air=True)  # the noiseless twin: no turbulence, no electronics noise
    assert isinstance(twin, Plant)
    assert twin.input_names == ("u1", "u2") and twin.output_names == ("pitch", "yaw")
    y0 = twin.reset()
    assert np.array_equal(y0, [0.0, 0.0])
    assert twin.trim.residual < 1e-10
    # Holding the trim voltages keeps the beam flat (no drift beyond a count in 20 s).
    rec = twin.run(np.tile(twin.operating_point.inputs, (200, 1)))
    assert np.max(np.abs(rec.extras["true_angles"])) < 1e-6
    # The tail rotor cancels the main rotor's reaction torque: u2 trims away from 0 V.
    assert abs(twin.operating_point.inputs[1]) > 0.05


@pytest.mark.parametrize("ts", [0.001, 0.2, 1.5, 32.767])
def test_sample_times_accepted(ts):
    twin = Twin("1dof", ts)
    assert twin.sample_time == pytest.approx(ts)


@pytest.mark.parametrize(
    "ts, match",
    [
        (0.0005, "outside the allowed range"),
        (33.0, "outside the allowed range"),
        (0.0105, "0.001 s resolution"),
        (float("nan"), "outside"),
        ("fast", "must be a real number"),
    ],
)
def test_sample_times_refused(ts, match):
    with pytest.raises(ConfigurationError, match=match):
        Twin("1dof", ts)


def test_an_odd_millisecond_sample_time_runs_at_a_finer_physics_step():
    spec = load_spec()
    spec.option.timestep = 0.002
    odd, even = Twin("1dof", 0.003, spec=spec), Twin("1dof", 0.004, spec=spec)
    assert (odd.model.opt.timestep, odd._nsub, odd.sample_time) == (0.0015, 2, pytest.approx(0.003))
    assert (even.model.opt.timestep, even._nsub) == (0.002, 2)
    # the delay lines are sized for the step the twin runs at: the same transport delay either way
    assert odd.model.actuator_history[0, 0] > even.model.actuator_history[0, 0]
    np.testing.assert_array_equal(odd.model.actuator_delay, even.model.actuator_delay)
    with pytest.raises(ConfigurationError, match="multiple of the physics time step 0.002"):
        check_sample_time(0.003, 0.002)


def test_saturation_is_applied_and_recorded(twin_factory):
    twin = twin_factory("2dof")
    u = np.tile(twin.operating_point.inputs, (20, 1))
    u[5:8, 0] = 14.0
    u[6, 1] = -11.0
    rec = twin.run(u)
    sat = rec.extras["saturated"]
    assert sat[5:8, 0].all() and sat[6, 1] and sat.sum() == 4
    assert np.all(rec.extras["applied_inputs"][5:8, 0] == 10.0) and rec.extras["applied_inputs"][6, 1] == -10.0
    assert np.array_equal(rec.inputs, u)  # the command is kept as given


@pytest.mark.parametrize(
    "bad, match",
    [
        ([np.nan, 0.0], "finite"),
        ([1.0], r"shape \(2,\)"),
        ([[1.0, 2.0]], "shape"),
        ([np.inf, 1.0], "finite"),
        ("volts", "real numbers"),
    ],
)
def test_bad_voltages_leave_the_state_unchanged(twin_factory, bad, match):
    twin = twin_factory("2dof")
    twin.reset()
    twin.step(twin.operating_point.inputs + [0.5, 0.0])
    before = (twin.time, twin.data.qpos.copy(), twin.data.qvel.copy(), twin.data.act.copy())
    with pytest.raises(InputError, match=match):
        twin.step(bad)
    after = (twin.time, twin.data.qpos, twin.data.qvel, twin.data.act)
    assert before[0] == after[0] and all(np.array_equal(a, b) for a, b in zip(before[1:], after[1:]))


def test_encoder_quantisation(twin_factory):
    twin = twin_factory("2dof", counts_per_rev=4096, noise_std=0.0)
    u = twin.operating_point.inputs + np.array([0.3, 0.2])
    rec = twin.run(np.tile(u, (100, 1)))
    counts = rec.outputs / (2 * np.pi / 4096)
    assert np.allclose(counts, np.round(counts), atol=1e-9)
    err = rec.outputs - rec.extras["true_angles"]
    assert np.max(np.abs(err)) <= np.pi / 4096 + 1e-12
    assert np.unique(rec.outputs[:, 0]).size > 10  # it moves, in counts


def test_same_seed_same_bits_and_seeds_matter():
    twin = Twin("2dof", 0.1, noise_std=1e-3, gust=Gust(0.005, 1.0))
    u = twin.operating_point.inputs + np.random.default_rng(0).uniform(-0.5, 0.5, (150, 2))
    a, b = twin.run(u, seed=7), twin.run(u, seed=7)
    assert a.equals(b)
    c = twin.run(u, seed=8)
    assert not np.array_equal(a.outputs, c.outputs)
    assert not np.array_equal(a.extras["disturbance"], c.extras["disturbance"])
    assert a.metadata["seed"] == 7 and a.metadata["config"] == "2dof"


def test_gust_statistics_follow_their_parameters():
    twin = Twin("1dof", 0.1, counts_per_rev=0, gust=Gust(0.02, 0.5))
    rec = twin.run(np.tile(twin.operating_point.inputs, (3000, 1)), seed=3)
    g = rec.extras["disturbance"][:, 0]
    assert np.std(g) == pytest.approx(0.02, rel=0.15)  # 3000 samples, ~300 correlation times
    lag1 = np.corrcoef(g[:-1], g[1:])[0, 1]
    assert lag1 == pytest.approx(np.exp(-0.1 / 0.5), abs=0.05)


def test_push_moves_the_beam_only_after_it_happens():
    push = Push(time=2.05, duration=0.1, torque=(0.2, 0.0))
    quiet = Twin("1dof", 0.1, counts_per_rev=0)  # the same turbulence in both runs (same seed)
    pushed = Twin("1dof", 0.1, counts_per_rev=0, pushes=[push])
    u = np.tile(quiet.operating_point.inputs, (60, 1))
    a, b = quiet.run(u), pushed.run(u)
    diff = np.abs(b.extras["true_angles"][:, 0] - a.extras["true_angles"][:, 0])
    assert np.all(diff[:21] == 0.0)  # samples up to t = 2.0 s
    assert diff[22] > 1e-4
    assert b.extras["disturbance"][20, 0] == 0.0 and b.extras["disturbance"][21, 0] == 0.2  # active at t = 2.1 s
    # Angular impulse 0.02 N m s on ~0.06 kg m2: the pitch rate jumps by about 0.3 rad/s.
    assert np.max(b.extras["rates"][:, 0]) == pytest.approx(0.02 / 0.0586, rel=0.25)
    assert Push.impulse(1.0, 0.02, 0.1).torque == pytest.approx((0.2, 0.0))


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(time=-1.0, duration=0.1, torque=(1, 0)), "push time"),
        (dict(time=1.0, duration=0.0, torque=(1, 0)), "push duration"),
        (dict(time=1.0, duration=0.1, torque=(1, 0, 0)), "shape"),
        (dict(time=1.0, duration=0.1, torque=(1e3, 0)), "outside"),
    ],
)
def test_bad_pushes(kwargs, match):
    with pytest.raises(InputError, match=match):
        Push(**kwargs)


def test_channels_and_record_metadata(twin_factory):
    twin = twin_factory("1dof")
    rec = twin.run(np.tile(twin.operating_point.inputs + 1.0, (50, 1)))
    assert set(rec.extras) >= {
        "true_angles",
        "rates",
        "rotor_thrust",
        "rotor_speed",
        "disturbance",
        "qpos",
        "applied_inputs",
        "saturated",
    }
    # After the transport delay the main rotor spins up with the motor lag: 1 - exp(-(t - delay) / T) at t = 1.1 s.
    speed = rec.extras["rotor_speed"][:, 0]
    v0, v1 = twin.operating_point.inputs[0], twin.operating_point.inputs[0] + 1.0
    tau0, tau1 = twin.curves[0].k * v0, twin.curves[0].k * v1
    thrust = rec.extras["rotor_thrust"][:, 0]
    f0, f1 = twin.curves[0].thrust(v0), twin.curves[0].thrust(v1)
    lag = float(twin.model.actuator_dynprm[0, 0])
    dt = twin.model.opt.timestep  # the delay acts in whole physics steps
    delay = np.ceil(twin.input_delay / dt - 1e-9) * dt
    assert (thrust[11] - f0) / (f1 - f0) == pytest.approx(1 - np.exp(-(1.1 - delay) / lag), abs=1e-6)
    assert speed[0] == pytest.approx(tau0) and speed[-1] == pytest.approx(tau1, rel=0.02)
    assert rec.metadata["operating_point"]["inputs"] == twin.operating_point.inputs.tolist()
    assert mujoco.mj_stateSize(twin.model, mujoco.mjtState.mjSTATE_QPOS) == rec.extras["qpos"].shape[1]


# ------------------------------------------------------------------ the rig's ambient excitation
def test_the_default_twin_is_never_still_and_each_seed_is_its_own_bits():
    """The rig's rotor-wash turbulence and electronics noise are on by default: constant inputs leave the beam
    moving by a few milliradians, the same seed gives the same bits, another seed another realisation."""
    twin = Twin("2dof", 0.1)
    hover = np.tile(twin.operating_point.inputs, (600, 1))
    a, b, c = twin.run(hover, seed=5), twin.run(hover, seed=5), twin.run(hover, seed=6)
    assert a.equals(b) and not np.array_equal(a.outputs, c.outputs)
    pitch = a.extras["true_angles"][:, 0]
    assert 1e-3 < np.std(pitch) < 2e-2  # it moves by milliradians, not by counts or radians
    assert np.std(a.extras["turbulence"][:, 0]) == pytest.approx(twin.turbulence.std[0], rel=0.5)
    assert a.metadata["turbulence"]["std"] == list(twin.turbulence.std) and not a.metadata["still_air"]


def test_still_air_switches_off_turbulence_and_electronics_noise_only():
    still = Twin("1dof", 0.1, still_air=True)
    assert not still.turbulence.active and still.encoder.noise_std == 0.0
    assert Twin("1dof", 0.1, still_air=True, noise_std=2e-3).encoder.noise_std == 2e-3  # an explicit noise stays
    rec = still.run(np.tile(still.operating_point.inputs, (100, 1)), seed=9)
    assert np.all(rec.outputs == 0.0) and np.all(rec.extras["turbulence"] == 0.0)
    with pytest.raises(InputError, match="still_air = 'yes' must be True or False"):
        Twin("1dof", 0.1, still_air="yes")


def test_turbulence_statistics_follow_the_model_parameters():
    """Each rotor's thrust fluctuation is the MJCF's Ornstein-Uhlenbeck process: its standard deviation and its
    lag-one correlation exp(-Ts / T) at the control rate."""
    from trms.twin.parameters import with_parameters

    spec = with_parameters(load_spec(), {"main_turbulence": 0.01, "tail_turbulence": 0.004, "turbulence_time": 0.5})
    twin = Twin("2dof", 0.1, spec=spec, counts_per_rev=0)
    turb = twin.run(np.tile(twin.operating_point.inputs, (4000, 1)), seed=2).extras["turbulence"]
    assert np.std(turb, axis=0) == pytest.approx([0.01, 0.004], rel=0.15)  # 4000 samples, ~800 correlation times
    for k in range(2):
        assert np.corrcoef(turb[:-1, k], turb[1:, k])[0, 1] == pytest.approx(np.exp(-0.1 / 0.5), abs=0.05)


def test_turbulence_acts_along_each_rotor_axis_without_the_command_delay():
    """A thrust fluctuation is the air, not the motor: it acts at once, along the hub's axis (pitch for the main
    rotor, yaw for the tail rotor), while the motor commands wait for the transport delay."""
    twin = Twin("2dof", 0.1, still_air=True, counts_per_rev=0)
    m = twin.model
    for wash, hub in (("main_wash", "main_hub"), ("tail_wash", "tail_hub")):
        a = m.actuator(wash).id
        assert m.actuator_delay[a] == 0 and m.actuator_dyntype[a] == mujoco.mjtDyn.mjDYN_NONE
        assert m.actuator_trnid[a, 0] == m.site(hub).id and np.array_equal(m.actuator_gear[a], [0, 0, 1, 0, 0, 0])
    twin.reset()
    twin._turbulence = np.array([0.05, 0.0])  # one interval of a strong main-rotor gust, set by hand
    twin.step(twin.operating_point.inputs)
    assert twin.channels()["true_angles"][0] > 1e-4  # the pitch rose within the first interval
