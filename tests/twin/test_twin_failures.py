"""The twin under hostile input: exact restores, located divergences, end stops, refused models."""

import re

import mujoco
import numpy as np
import pytest

from trms.batch.rollouts import run_open_loop_batch
from trms.errors import ConfigurationError, DesignError, DivergenceError, InputError, ModelFileError
from trms.twin import DEFAULT_MODEL_PATH, Twin, load_spec

_FULL = mujoco.mjtState.mjSTATE_INTEGRATION


def _state(twin):
    buf = np.empty(mujoco.mj_stateSize(twin.model, _FULL))
    mujoco.mj_getState(twin.model, twin.data, buf, _FULL)
    return buf


def test_a_refused_diverging_step_leaves_the_twin_bit_identical_to_one_that_never_tried_it(runaway_spec):
    spec = runaway_spec()
    tried, never = (Twin("1dof", 0.1, spec=spec, counts_per_rev=0) for _ in range(2))
    hover = tried.operating_point.inputs
    for twin in (tried, never):
        for _ in range(3):
            twin.step(hover + 0.005)
    with pytest.raises(DivergenceError) as info:
        tried.step([10.0])
    msg = str(info.value)
    assert "\n" not in msg
    t_bad = float(re.search(r"diverged at t = ([\d.]+) s", msg).group(1))
    assert 0.3 < t_bad <= 0.4  # located inside the interval, to the physics step
    last = re.search(r"last finite state at t = ([\d.]+) s: qpos = \[([^\]]*)\] rad, qvel = \[([^\]]*)\]", msg)
    assert float(last.group(1)) == pytest.approx(t_bad - tried.model.opt.timestep)
    qvel = np.array(last.group(3).split(", "), float)
    assert np.all(np.isfinite(qvel)) and np.abs(qvel).max() > 10.0  # the blow-up, not MuJoCo's reset state
    assert tried.time == never.time
    assert _state(tried).tobytes() == _state(never).tobytes()  # warmstart included
    for twin in (tried, never):
        for _ in range(5):
            twin.step(hover + 0.005)
    assert _state(tried).tobytes() == _state(never).tobytes()


def test_the_batch_checks_every_warning(runaway_spec):
    twins = [Twin("1dof", 0.1, spec=runaway_spec()) for _ in range(2)]
    u = np.tile(twins[0].operating_point.inputs, (20, 1))
    assert run_open_loop_batch(twins, u).shape == (2, 20, 1)
    u[3:, 0] = 10.0
    with pytest.raises(DivergenceError, match=r"diverged at t = 0\.\d+ s"):
        run_open_loop_batch(twins, u)


def test_pitch_holds_at_its_stop_and_the_record_says_so():
    twin = Twin("1dof", 0.1, counts_per_rev=0)
    rec = twin.run(np.full((100, 1), twin.voltage_limit))
    pitch = rec.extras["true_angles"][:, 0]
    stop = twin.model.jnt_range[twin.model.joint("pitch").id][1]
    at_stop = rec.extras["at_stop"]
    assert at_stop.shape == (100, 2) and at_stop.dtype == bool and not at_stop[:, 1].any()  # yaw is locked
    assert at_stop[-20:, 0].all()  # resting on the stop at +10 V held
    assert np.abs(pitch[-20:] - stop).max() < 3e-3  # resting within a few mrad of it, overshoot too
    # a flag marks an interval that touched the stop, so a sample after a bounce may read well below it;
    # an unflagged interval never came near it, and the beam starts away from it
    margin = twin.model.jnt_margin[twin.model.joint("pitch").id]
    assert not at_stop[0, 0] and (pitch[~at_stop[:, 0]] < stop - margin).all()
    assert (np.abs(pitch - stop) > 0.05)[at_stop[:, 0]].any()  # the first contact bounces off between samples


def test_float32_sample_time_and_numpy_seeds_are_accepted():
    twin = Twin("1dof", np.float32(0.1), seed=np.int64(4))
    assert twin.sample_time == pytest.approx(0.1) and twin.seed == 4


@pytest.mark.parametrize("seed", [None, -1, 1.5, "3", True])
def test_bad_seeds_are_refused(seed):
    with pytest.raises(InputError, match="seed must be a non-negative integer"):
        Twin("1dof", seed=seed)


@pytest.mark.parametrize("seed", [-1, 1.5, "a"])
def test_bad_reset_seeds_are_refused_and_leave_the_twin(twin_factory, seed):
    twin = twin_factory("1dof", 0.2)
    twin.reset(2)
    twin.step(twin.operating_point.inputs + 0.3)
    before = _state(twin)
    with pytest.raises(InputError, match="seed must be a non-negative integer or None"):
        twin.reset(seed)
    assert _state(twin).tobytes() == before.tobytes()


@pytest.mark.parametrize("bad", [[1 + 1j], "1.0", [10**400], [[1.0], [1.0, 2.0]]])
def test_unusable_voltages_are_refused(twin_factory, bad):
    with pytest.raises(InputError, match="must be real numbers"):
        twin_factory("1dof", 0.2).step(bad)


def test_small_voltage_limits_trim_or_say_why():
    for limit in (0.2, 0.5, 0.9):
        try:
            twin = Twin("1dof", voltage_limit=limit)
        except DesignError as exc:
            assert f"+-{limit} V" in str(exc)
        else:
            assert np.all(np.abs(twin.operating_point.inputs) <= limit)
    with pytest.raises(InputError, match="voltage_limit must be a real number"):
        Twin("1dof", voltage_limit=10**400)
    with pytest.raises(InputError, match=r"voltage_limit = 1000 V is outside .*10.0 V\] \(the rig's drives saturate"):
        Twin("1dof", voltage_limit=1000)
    with pytest.raises(ConfigurationError, match="sample_time must be a real number"):
        Twin("1dof", sample_time=10**400)


@pytest.mark.parametrize(
    "element, new, match",
    [
        (
            r'<geom name="counterweight"[^>]*?\bmass="([^"]*)"',
            "nan",
            "<geom name='counterweight'> mass=\"nan\" is not finite",
        ),
        (r'<joint name="pitch"[^>]*?\bdamping="([^"]*)"', "NaN", "<joint name='pitch'> damping=\"NaN\" is not finite"),
        (
            r'<joint name="pitch"[^>]*?\bdamping="([^"]*)"',
            "-0.01",
            r"joint 'pitch' damping = \[-0.01, .*\]; allowed: finite, >= 0",
        ),
    ],
)
def test_non_finite_or_negative_mjcf_values_are_refused(tmp_path, element, new, match):
    text = DEFAULT_MODEL_PATH.read_text()
    found = re.search(element, text)
    assert found is not None
    (tmp_path / "m.xml").write_text(text[: found.start(1)] + new + text[found.end(1) :])
    with pytest.raises(ModelFileError, match=match):
        Twin("1dof", model_path=tmp_path / "m.xml")


@pytest.mark.parametrize("lag", ["-1", "0"])
def test_a_non_positive_motor_lag_is_refused(tmp_path, lag):
    text = re.sub(r'(<general name="main_rotor"[^>]*dynprm=")[^" ]+', rf"\g<1>{lag}", DEFAULT_MODEL_PATH.read_text())
    (tmp_path / "m.xml").write_text(text)
    with pytest.raises(
        ModelFileError, match=r"actuator 'main_rotor' motor lag dynprm\[0\] = .* allowed: finite, > 0 s"
    ):
        Twin("1dof", model_path=tmp_path / "m.xml")


@pytest.mark.parametrize("delay", ["-1", "100"])
def test_an_actuator_delay_out_of_range_is_refused_and_one_the_numeric_overrides_is_said(tmp_path, delay):
    """The input_delay numeric sets every rotor's delay: an actuator's own value is never silently dropped."""
    text = re.sub(r'(<general name="main_rotor"[^>]*delay=")[^"]+', rf"\g<1>{delay}", DEFAULT_MODEL_PATH.read_text())
    (tmp_path / "m.xml").write_text(text)
    with pytest.raises(ModelFileError, match=rf"actuator 'main_rotor' delay = {delay} s; allowed: 0 to 5 s \(the"):
        Twin("1dof", model_path=tmp_path / "m.xml")
    (tmp_path / "m.xml").write_text(text.replace(f'delay="{delay}"', 'delay="0.3"', 1))
    with pytest.warns(UserWarning, match=r"actuator 'main_rotor' delay = 0.3 s differs from the input_delay numeric"):
        assert Twin("1dof", model_path=tmp_path / "m.xml").input_delay == Twin("1dof").input_delay


@pytest.mark.parametrize("gravity", [[0.0, 0.0, 0.0], [0.0, 0.0, 9.81], [0.0, 0.0, float("nan")]])
def test_gravity_that_does_not_point_down_is_refused(gravity):
    spec = load_spec()
    spec.option.gravity = gravity
    with pytest.raises(ModelFileError, match=r"gravity = \[.*\] m/s\^2; allowed: finite and pointing down"):
        Twin("1dof", spec=spec)


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"gust": "strong"}, r"gust = 'strong' must be a trms.twin.Gust"),
        ({"pushes": 5}, r"pushes = 5 must be a sequence of trms.twin.Push"),
        ({"pushes": "push"}, r"pushes = 'push' must be a sequence"),
        ({"pushes": [5]}, r"pushes must hold trms.twin.Push instances, got 5"),
        ({"spec": "str"}, r"spec = 'str' must be a mujoco.MjSpec"),
        ({"model_path": 5}, r"model_path = 5 must be a path to an MJCF file"),
        ({"spec": "SPEC", "model_path": "x.xml"}, r"either spec or model_path, not both"),
    ],
)
def test_constructor_arguments_of_the_wrong_kind_are_one_line_refusals(kwargs, match):
    if kwargs.get("spec") == "SPEC":
        kwargs = {**kwargs, "spec": load_spec()}
    with pytest.raises(InputError, match=match) as info:
        Twin("1dof", **kwargs)
    assert "\n" not in str(info.value)


@pytest.mark.parametrize(
    "joint, new_range, config, match",
    [
        ("pitch", "0 0", "1dof", r"joint 'pitch' has no end stops \(range=\"0 0\" rad, limited: False\)"),
        ("pitch", "0 0", "2dof", r"joint 'pitch' has no end stops"),
        ("pitch", "0.2 1.1", "1dof", r"joint 'pitch' has no end stops \(range=\"0.2 1.1\" rad, limited: True\)"),
        ("yaw", "0 0", "yaw", r"joint 'yaw' has no end stops"),
    ],
)
def test_a_free_axis_without_end_stops_is_refused(tmp_path, joint, new_range, config, match):
    text = DEFAULT_MODEL_PATH.read_text()
    found = re.search(rf'<joint name="{joint}"[^>]*?\brange="([^"]*)"', text)
    assert found is not None
    (tmp_path / "m.xml").write_text(text[: found.start(1)] + new_range + text[found.end(1) :])
    with pytest.raises(ModelFileError, match=match) as exc:
        Twin(config, model_path=tmp_path / "m.xml")
    assert "\n" not in str(exc.value)


def test_narrower_end_stops_are_flown_and_hit(tmp_path):
    text = DEFAULT_MODEL_PATH.read_text().replace('range="-1.1 1.1"', 'range="-0.3 0.3"')
    (tmp_path / "m.xml").write_text(text)
    twin = Twin("1dof", 0.2, model_path=tmp_path / "m.xml")
    rec = twin.run(np.full((40, 1), 10.0))  # full thrust: the beam rises onto its upper stop
    assert rec.outputs[:, 0].max() == pytest.approx(0.3, abs=0.05)
    assert rec.extras["at_stop"][:, 0].any()


@pytest.mark.parametrize("bad", [None, [None]])
def test_none_is_not_a_voltage(twin_factory, bad):
    twin = twin_factory("1dof", 0.2)
    with pytest.raises(InputError, match=r"None is not a voltage; give 1 number \(V\)"):
        twin.step(bad)
