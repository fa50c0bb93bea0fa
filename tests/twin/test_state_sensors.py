"""The state sensors every twin model carries: where they sit, that they hold the state exactly, when they do not."""

import mujoco
import numpy as np
import pytest

from trms.twin import Twin
from trms.twin.state_sensors import PREFIX, state_columns


@pytest.mark.parametrize("config", ["1dof", "2dof", "yaw"])
def test_the_sensors_hold_every_position_rate_and_activation_bit_for_bit(config):
    twin = Twin(config, 0.1, seed=0)
    cols = state_columns(twin.model)
    assert cols is not None and (cols.qpos.size, cols.qvel.size, cols.act.size) == (
        twin.model.nq,
        twin.model.nv,
        twin.model.na,
    )
    rng = np.random.default_rng(0)
    data = mujoco.MjData(twin.model)
    for _ in range(20):
        twin.step(twin.operating_point.inputs + rng.uniform(-1.0, 1.0, len(twin.input_names)))
        state = twin.data.qpos.copy(), twin.data.qvel.copy(), twin.data.act.copy()
        data.qpos[:], data.qvel[:], data.act[:] = state
        mujoco.mj_forward(twin.model, data)  # what the next step's start computes
        for c, value in zip((cols.qpos, cols.qvel, cols.act), state):
            assert data.sensordata[c].tobytes() == value.tobytes()


def test_the_models_own_plain_sensors_are_used_and_named_ones_added():
    model = Twin("2dof", 0.1).model
    names = [model.sensor(i).name for i in range(model.nsensor)]
    assert names[:4] == ["pitch", "yaw", "pitch_rate", "yaw_rate"]  # the MJCF's own, first and kept
    assert all(n.startswith(PREFIX) for n in names[4:]) and len(names) == 4 + 2 * (model.nq - 2) + model.na
    cols = state_columns(model)
    assert cols.qpos[model.joint("pitch").qposadr[0]] == model.sensor("pitch").adr[0]


@pytest.mark.parametrize(
    "change",
    [
        lambda m: m.actuator_gainprm.__setitem__((0, 0), 2.0),  # a force twice the activation
        lambda m: m.actuator_biastype.__setitem__(1, mujoco.mjtBias.mjBIAS_AFFINE),
        lambda m: m.actuator_forcelimited.__setitem__(0, 1),
        lambda m: m.sensor_cutoff.__setitem__(m.sensor(f"{PREFIX}qpos_main_spin").id, 1.0),
        lambda m: m.sensor_delay.__setitem__(0, 0.01),
    ],
)
def test_a_model_changed_so_its_sensors_no_longer_hold_its_state_has_no_columns(change):
    model = Twin("2dof", 0.1).model
    change(model)
    assert state_columns(model) is None
