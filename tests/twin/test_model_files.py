"""The MJCF split (rig and scene), the derived values in the file and the generated README."""

import shutil

import mujoco
import numpy as np
import pytest

from trms.calibration.model_file import shipped_readme
from trms.twin import CONFIGURATIONS, Twin, load_spec
from trms.twin.model import DEFAULT_MODEL_PATH, SCENE_PATH, build_model
from trms.twin.model_files import KEYFRAME, README_PATH, derived_values, write_model
from trms.twin.parameters import write_parameters


@pytest.mark.parametrize("config", ["1dof", "2dof", "yaw"])
def test_the_scene_changes_nothing_in_the_physics(config):
    spec = load_spec()
    models = [build_model(spec, CONFIGURATIONS[config], scene=s) for s in (False, True)]
    assert models[0].ncam == 0 and {models[1].camera(i).name for i in range(models[1].ncam)} >= {"front", "top"}
    rng = np.random.default_rng(0)
    ctrls = rng.uniform(models[0].actuator_ctrlrange[:, 0], models[0].actuator_ctrlrange[:, 1], (20, models[0].nu))
    traj = []
    for m in models:
        d = mujoco.MjData(m)
        out = []
        for c in ctrls:
            d.ctrl[:] = c
            mujoco.mj_step(m, d, 50)
            out.append(np.concatenate([d.qpos, d.qvel, d.act]))
        traj.append(np.array(out))
    assert np.array_equal(traj[0], traj[1])


def test_scene_file_includes_the_rig_and_the_rig_has_no_world():
    scene = mujoco.MjModel.from_xml_path(str(SCENE_PATH))
    rig = mujoco.MjModel.from_xml_path(str(DEFAULT_MODEL_PATH))
    assert scene.nq == rig.nq and scene.nu == rig.nu and scene.nbody == rig.nbody
    assert rig.ncam == 0 and rig.nlight == 0 and scene.ncam == 3 and scene.nlight == 1


def test_the_files_ctrlranges_and_hover_keyframe_match_a_fresh_trim():
    fresh = derived_values()
    model = mujoco.MjModel.from_xml_path(str(DEFAULT_MODEL_PATH))
    for name, rng in fresh["ctrlrange"].items():
        a = model.actuator(name).id
        assert model.actuator_ctrllimited[a]
        np.testing.assert_allclose(model.actuator_ctrlrange[a], rng, rtol=1e-9)
    key = model.key(KEYFRAME)
    for field in ("qpos", "qvel", "act", "ctrl"):
        np.testing.assert_allclose(getattr(key, field), fresh["keyframe"][field], rtol=1e-8, atol=1e-12)


def test_the_hover_keyframe_holds_the_beam_in_plain_mujoco():
    model = mujoco.MjModel.from_xml_path(str(SCENE_PATH))
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key(KEYFRAME).id)
    for i in range(model.nu):  # the delay lines, which a keyframe does not hold
        if model.actuator_history[i, 0]:
            mujoco.mj_initCtrlHistory(model, data, i, None, np.full((model.actuator_history[i, 0], 1), data.ctrl[i]))
    mujoco.mj_step(model, data, 2000)  # 2 s with the keyframe's controls held
    for axis in ("pitch", "yaw"):
        assert abs(data.joint(axis).qpos[0]) < 1e-4


def test_the_file_alone_has_the_twins_delays_and_spin_gains():
    plain = mujoco.MjModel.from_xml_path(str(DEFAULT_MODEL_PATH))
    twin = Twin("2dof").model
    assert plain.nu == twin.nu and plain.actuator_delay.max() > 0.4
    for i in range(plain.nu):
        name = plain.actuator(i).name
        j = twin.actuator(name).id
        assert plain.actuator_delay[i] == pytest.approx(twin.actuator_delay[j], rel=1e-9), name
        assert plain.actuator_history[i, 0] == twin.actuator_history[j, 0], name
        np.testing.assert_allclose(plain.actuator_gainprm[i, :3], twin.actuator_gainprm[j, :3], rtol=1e-9)
        np.testing.assert_allclose(plain.actuator_biasprm[i, :3], twin.actuator_biasprm[j, :3], rtol=1e-9)


def test_the_model_readme_is_generated_from_the_model_and_the_parameters():
    assert README_PATH.read_text() == shipped_readme()


def test_writing_the_model_refreshes_the_keyframe_and_writing_parameters_alone_does_not(tmp_path):
    path = tmp_path / "rig.xml"
    shutil.copy(DEFAULT_MODEL_PATH, path)
    before = derived_values(path)["keyframe"]["ctrl"]
    written = mujoco.MjModel.from_xml_path(str(path)).key(KEYFRAME).ctrl.copy()
    write_parameters(path, {"main_reaction": 0.05})
    stale = mujoco.MjModel.from_xml_path(str(path)).key(KEYFRAME).ctrl
    np.testing.assert_array_equal(stale, written)  # the parameters alone leave the keyframe as it was
    write_model(path, {"main_reaction": 0.05})
    model = mujoco.MjModel.from_xml_path(str(path))
    fresh = Twin("2dof", model_path=path).trim
    assert not np.allclose(before, fresh.ctrl)
    np.testing.assert_allclose(model.key(KEYFRAME).ctrl, fresh.ctrl, rtol=1e-8)
    assert README_PATH.read_text() == shipped_readme()  # the shipped README untouched by writing another file
