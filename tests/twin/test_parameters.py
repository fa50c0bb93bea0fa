"""Named physical parameters: read, set on copies, written back into the MJCF with its comments."""

import shutil

import mujoco
import numpy as np
import pytest

from trms.errors import InputError
from trms.twin import DEFAULT_MODEL_PATH, Twin, load_spec
from trms.twin.parameters import PARAMETERS, published_parameters, read_parameters, with_parameters, write_parameters


def test_with_parameters_changes_a_copy_only():
    spec = load_spec()
    before = read_parameters(spec)
    new = with_parameters(spec, {"counterweight_mass": 0.1, "beam_stiffness": 300.0, "main_rotor_tilt": -0.05})
    assert read_parameters(spec) == before
    after = read_parameters(new)
    assert after["counterweight_mass"] == 0.1 and after["main_rotor_tilt"] == -0.05
    m = new.compile()
    flex = [m.joint(i) for i in range(m.njnt) if "flex" in m.joint(i).name]
    assert all(j.stiffness[0] == 300.0 for j in flex)


#: The parameters of the rig's ambient excitation: they act on its records, not on its linearisation.
AMBIENT = ("main_turbulence", "tail_turbulence", "turbulence_time", "pitch_encoder_noise", "yaw_encoder_noise")


def _changed(name: str, value: float) -> float:
    """``value`` moved by 10 % (inwards at a bound), or a tenth of the upper bound from 0."""
    lo, hi = PARAMETERS[name].bounds
    if not value:
        return 0.1 * hi
    return value * 1.1 if lo <= value * 1.1 <= hi else value * 0.9


def test_every_parameter_acts_on_the_dynamics():
    """Changing any parameter by 10 % changes the 2-DOF linearisation, or for the ambient excitation the hover
    record at the same seed (no parameter is a dead knob)."""
    spec = load_spec()
    base = Twin("2dof", 0.1, spec=spec)
    base_lin = base.linearise()
    hover = np.tile(base.operating_point.inputs, (100, 1))
    base_rec = base.run(hover, seed=3)
    for name, value in read_parameters(spec).items():
        twin = Twin("2dof", 0.1, spec=with_parameters(spec, {name: _changed(name, value)}))
        if name in AMBIENT:
            assert not np.array_equal(twin.run(hover, seed=3).outputs, base_rec.outputs), name
            continue
        lin = twin.linearise()
        assert not (
            np.allclose(lin.continuous.A, base_lin.continuous.A)
            and np.allclose(lin.continuous.B, base_lin.continuous.B)
            and lin.input_delay == base_lin.input_delay
        ), name


@pytest.mark.parametrize(
    "values, match",
    [
        ({"counterweight_mass": 5.0}, r"counterweight_mass = 5.0 kg is outside the allowed range \[0.02 kg, 0.3 kg\]"),
        ({"wingspan": 1.0}, "unknown parameter 'wingspan'"),
        ({"main_motor_lag": float("nan")}, "main_motor_lag"),
    ],
)
def test_bad_values_are_refused_before_anything_changes(values, match):
    spec = load_spec()
    with pytest.raises(InputError, match=match):
        with_parameters(spec, {"pitch_damping": 0.02, **values})


def test_write_parameters_keeps_comments_and_round_trips(tmp_path):
    path = tmp_path / "trms.xml"
    shutil.copy(DEFAULT_MODEL_PATH, path)
    text_before = path.read_text()
    values = {"counterweight_mass": 0.0812345, "input_delay": 0.375, "beam_damping": 0.2, "main_motor_gain": 2.5}
    write_parameters(path, values)
    text_after = path.read_text()
    assert text_after.count("<!--") == text_before.count("<!--")
    assert len(text_after.splitlines()) == len(text_before.splitlines())
    got = read_parameters(load_spec(path), values)
    assert got == pytest.approx(values, rel=1e-6)
    mujoco.MjModel.from_xml_path(str(path))


def test_published_values_are_the_documented_starting_point():
    pub = published_parameters()
    assert set(pub) == set(PARAMETERS)
    assert pub["counterweight_mass"] == 0.068 and pub["main_motor_lag"] == 1.1  # [F] and [S] in the MJCF
    for name, value in pub.items():
        PARAMETERS[name].check(value)


def test_every_parameter_is_physical_or_says_what_it_stands_for():
    from trms.twin.parameters import ROLES, SOURCES, Parameter

    for p in PARAMETERS.values():
        assert p.role in ROLES and p.source in SOURCES, p.name
        assert (p.role == "lumped") == bool(p.stands_for), p.name
    # the knobs that carry what the model has no element for: Feedback's Kgy, the amplifier, the rig's dead time
    assert {"main_rotor_tilt", "main_motor_gain", "input_delay"} <= {
        n for n, p in PARAMETERS.items() if p.role == "lumped"
    }
    gain = PARAMETERS["main_motor_gain"]
    assert gain.departure(3.3) == pytest.approx(2.0) and np.isnan(PARAMETERS["main_rotor_tilt"].departure(0.3))
    with pytest.raises(ValueError, match="stands for"):
        Parameter("x", "kg", (0.0, 1.0), "a mass", "geom", "g", "mass", role="lumped")
    with pytest.raises(ValueError, match="role 'fudge'"):
        Parameter("x", "kg", (0.0, 1.0), "a mass", "geom", "g", "mass", role="fudge")
