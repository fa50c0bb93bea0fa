"""The MJCF: loads, locks axes exactly, raises no MuJoCo warning under the full voltage range."""

import mujoco
import numpy as np
import pytest

from trms import reference
from trms.errors import ConfigurationError, ModelFileError
from trms.twin import CONFIGURATIONS, DEFAULT_MODEL_PATH, Twin, load_spec
from trms.twin.model import SCENE_PATH, build_model


def test_shipped_model_has_the_rig_structure():
    m = mujoco.MjModel.from_xml_path(str(DEFAULT_MODEL_PATH))
    joints = {m.joint(i).name for i in range(m.njnt)}
    assert {"yaw", "pitch"} <= joints
    assert sum(n.startswith("main_flex") for n in joints) >= 2 and sum(n.startswith("tail_flex") for n in joints) >= 2
    for name in ("main_shield", "tail_shield", "counterweight", "counterweight_arm", "column"):
        assert m.geom(name).id >= 0
    assert np.all(m.geom_contype == 0) and np.all(m.geom_conaffinity == 0)
    scene = mujoco.MjModel.from_xml_path(str(SCENE_PATH))  # the world (cameras, floor) is the scene's
    assert {scene.camera(i).name for i in range(scene.ncam)} >= {"front", "oblique", "top"}
    assert np.all(scene.geom_contype == 0) and np.all(scene.geom_conaffinity == 0)
    # Main rotor: thrust along the rotor axis and a reaction torque about it (6-D gear).
    assert m.actuator("main_rotor").gear[2] == 1.0 and m.actuator("main_rotor").gear[5] > 0
    assert m.actuator("main_rotor").dyntype == mujoco.mjtDyn.mjDYN_FILTEREXACT


def test_the_joint_ranges_are_the_rigs_end_stops_and_the_configurations_the_rigs():
    spec = load_spec()
    for axis, stop in reference.END_STOPS.items():
        assert list(spec.joint(axis).range) == [-stop, stop]
    assert tuple(CONFIGURATIONS) == reference.CONFIGURATION_NAMES


def test_published_magnitudes():
    """Pitch inertia, gravity moment and rest pitch are those of the published parameter sets."""
    twin = Twin("1dof", 0.1, counts_per_rev=0)
    assert twin.trim.voltages[0] > 0  # the main side is heavier: hover needs positive main thrust
    m, d = twin.model, mujoco.MjData(twin.model)
    mujoco.mj_forward(m, d)
    M = np.zeros((m.nv, m.nv))
    mujoco.mj_fullM(m, d, M)
    pitch = m.joint("pitch").dofadr[0]
    assert 0.05 < M[pitch, pitch] < 0.07  # kg m2 (published 0.059-0.068)
    # Rotors off: the beam settles at the rest pitch (published -0.62 to -0.65 rad).
    slow = Twin("1dof", 1.0, counts_per_rev=0)
    rest = slow.run(np.zeros((150, 1)), seed=0).extras["true_angles"][-1, 0]
    assert -0.75 < rest < -0.5


@pytest.mark.parametrize("config", sorted(CONFIGURATIONS))
def test_no_warnings_under_random_full_range_voltages(config):
    twin = Twin(config, 0.05, counts_per_rev=0)
    rng = np.random.default_rng(11)
    u = rng.uniform(-10, 10, (1200, len(twin.input_names)))  # 60 s
    rec = twin.run(u, seed=1)
    assert all(w.number == 0 for w in twin.data.warning), [w.number for w in twin.data.warning]
    assert np.all(np.isfinite(rec.outputs))


@pytest.mark.parametrize("config, child, parent", [("1dof", "yaw_frame", "tower"), ("yaw", "beam_hub", "yaw_frame")])
def test_locked_axis_stays_exactly_fixed(config, child, parent):
    """The locked joint is gone: the child body turns exactly with its parent, whatever the voltages."""
    twin = Twin(config, 0.1, counts_per_rev=0)
    assert {"1dof": "yaw", "yaw": "pitch"}[config] not in {twin.model.joint(i).name for i in range(twin.model.njnt)}
    twin.reset()
    rng = np.random.default_rng(2)
    for _ in range(100):
        twin.step(rng.uniform(-10, 10, len(twin.input_names)))
        c, p = twin.data.xquat[twin.model.body(child).id], twin.data.xquat[twin.model.body(parent).id]
        assert np.array_equal(c, p)


def test_missing_and_malformed_model_files(tmp_path):
    with pytest.raises(ModelFileError, match="does not exist"):
        load_spec(tmp_path / "nope.xml")
    bad = tmp_path / "bad.xml"
    bad.write_text("<mujoco><worldbody><body></mujoco>")
    with pytest.raises(ModelFileError, match="not valid MJCF"):
        load_spec(bad)
    partial = tmp_path / "partial.xml"
    partial.write_text(DEFAULT_MODEL_PATH.read_text().replace('name="yaw" type="hinge"', 'name="swivel" type="hinge"'))
    with pytest.raises(ModelFileError, match=r"lacks required joint\(s\) \['yaw'\]"):
        load_spec(partial)


def test_unknown_configuration():
    with pytest.raises(ConfigurationError, match="unknown configuration '3dof'; allowed: '1dof', '2dof', 'yaw'"):
        Twin("3dof")
    spec = load_spec()
    m = build_model(spec, CONFIGURATIONS["2dof"])
    # thrust, spin motor and turbulence per rotor; the caller's spec is untouched
    assert m.nu == 6 and spec.joint("yaw") is not None


def _variant(tmp_path, old, new, name="variant.xml", count=1):
    text = DEFAULT_MODEL_PATH.read_text()
    assert text.count(old) >= count, old
    path = tmp_path / name
    path.write_text(text.replace(old, new, count))
    return path


@pytest.mark.parametrize(
    "old, new, message",
    [
        (
            'name="pitch" type="hinge"',
            'name="pitch" type="slide"',
            r"joint 'pitch' is a slide joint; allowed: a hinge",
        ),
        (
            'name="main_rotor" class="rotor" site="main_hub"',
            'name="main_rotor" class="rotor" site="tail_hub"',
            r"actuator 'main_rotor' acts on 'tail_hub'; allowed: the site 'main_hub'",
        ),
        (
            '<joint name="main_spin"',
            '<joint name="main_spinner"',
            r"no joint 'main_spin'; the actuator or axis of that name needs one",
        ),
    ],
)
def test_a_user_model_the_twin_would_drive_wrongly_is_refused(tmp_path, old, new, message):
    with pytest.raises(ModelFileError, match=message):
        load_spec(_variant(tmp_path, old, new))


def test_rotors_with_swapped_hubs_are_refused_by_what_their_thrust_turns(tmp_path):
    text = DEFAULT_MODEL_PATH.read_text()
    swapped = text.replace('name="main_hub"', 'name="@@"').replace('name="tail_hub"', 'name="main_hub"')
    swapped = swapped.replace('name="@@"', 'name="tail_hub"')
    assert swapped != text
    path = tmp_path / "swapped.xml"
    path.write_text(swapped)
    with pytest.raises(ModelFileError, match=r"actuator 'main_rotor' turns yaw .* more than pitch"):
        load_spec(path)


def test_entities_and_includes_outside_the_folder_are_refused(tmp_path):
    laughs = (
        '<?xml version="1.0"?>\n<!DOCTYPE lolz [<!ENTITY lol "lol"><!ENTITY lol2 "&lol;&lol;&lol;&lol;">]>\n'
        + DEFAULT_MODEL_PATH.read_text().replace('<mujoco model="trms"', '<mujoco model="&lol2;"', 1)
    )
    bomb = tmp_path / "bomb.xml"
    bomb.write_text(laughs)
    with pytest.raises(ModelFileError, match="declares a DTD or entities"):
        load_spec(bomb)
    outside = tmp_path / "elsewhere"
    outside.mkdir()
    (outside / "extra.xml").write_text('<mujoco><custom><text name="owner" data="lab"/></custom></mujoco>')
    folder = tmp_path / "model"
    folder.mkdir()
    rig = _variant(folder, "</mujoco>", f'  <include file="{outside / "extra.xml"}"/>\n</mujoco>', "rig.xml")
    with pytest.raises(ModelFileError, match=r"includes '.*extra.xml', outside the model's folder"):
        load_spec(rig)
    assert load_spec(rig, allow_outside_includes=True).actuator("main_rotor") is not None
    relative = _variant(folder, "</mujoco>", '  <include file="../elsewhere/extra.xml"/>\n</mujoco>', "rel.xml")
    with pytest.raises(ModelFileError, match="outside the model's folder"):
        load_spec(relative)
