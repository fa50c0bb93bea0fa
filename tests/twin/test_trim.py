"""The hover trim, and the static equilibrium a voltage holds at a held pitch."""

import pytest

from trms.errors import InputError
from trms.twin import Twin, load_spec
from trms.twin.model import CONFIGURATIONS, build_model, thrust_curves
from trms.twin.trim import solve_trim


@pytest.fixture(scope="module")
def rig():
    spec = load_spec()
    return build_model(spec, CONFIGURATIONS["1dof"], delay=False, scene=False), thrust_curves(spec)


def test_a_held_pitch_is_held_by_the_voltage_a_run_settles_at(rig):
    model, curves = rig
    held = solve_trim(model, curves, (0,), ("pitch",), axis_angles={"pitch": -0.4})
    assert held.residual <= 1e-10 and held.qpos[model.joint("pitch").qposadr[0]] == -0.4
    twin = Twin("1dof", 1.0, still_air=True, counts_per_rev=0)
    flat = solve_trim(model, curves, (0,), ("pitch",))
    assert flat.voltages[0] == pytest.approx(twin.operating_point.inputs[0], abs=1e-9)
    rec = twin.run([[held.voltages[0]]] * 150)  # 150 s at that voltage
    assert rec.extras["true_angles"][-1, 0] == pytest.approx(-0.4, abs=1e-5)


def test_an_angle_for_an_axis_that_is_not_held_is_refused(rig):
    model, curves = rig
    with pytest.raises(InputError, match="axis_angles names 'yaw'"):
        solve_trim(model, curves, (0,), ("pitch",), axis_angles={"yaw": 0.1})
