"""Linearisation and modes: an analytic pendulum, and the twin's linear model against the twin itself."""

import control
import mujoco
import numpy as np
import pytest

from trms.control.realization import continuous_jacobians
from trms.twin import Twin, load_spec
from trms.twin.linearise import oscillatory_modes, state_names, transition_jacobians
from trms.twin.parameters import published_parameters, with_parameters

PENDULUM = """
<mujoco>
  <option timestep="0.001" integrator="{integrator}"/>
  <worldbody>
    <body name="bob">
      <joint name="swing" type="hinge" axis="0 1 0" damping="{c}"/>
      <geom type="sphere" size="0.01" pos="0 0 -{l}" mass="{m}"/>
    </body>
  </worldbody>
</mujoco>
"""


@pytest.mark.parametrize("integrator", ["implicitfast", "discrete"])
@pytest.mark.parametrize("length, damping", [(0.5, 0.0), (0.25, 0.01), (2.0, 0.05)])
def test_pendulum_frequency_and_damping_are_analytic(length, damping, integrator):
    """Whatever the model's integrator (the twin's is ``discrete``), the same continuous pendulum."""
    mass = 0.3
    m = mujoco.MjModel.from_xml_string(PENDULUM.format(l=length, m=mass, c=damping, integrator=integrator))
    own = m.opt.integrator
    d = mujoco.MjData(m)
    A_d, B_d, h = transition_jacobians(m, d)
    A_c, _ = continuous_jacobians(A_d, B_d, h)
    (mode,) = oscillatory_modes(A_c, state_names(m))
    inertia = mass * length**2 + 0.4 * mass * 0.01**2  # point mass plus the sphere's own inertia
    wn = np.sqrt(9.81 * mass * length / inertia)
    # Tolerance: the implicit treatment of damping over the 1e-4 s linearisation step biases |lambda| by
    # O(h c / I) ~ 1e-5 relative for the most damped case.
    assert mode.frequency_hz == pytest.approx(wn / (2 * np.pi), rel=3e-5)
    assert mode.damping == pytest.approx(damping / (2 * inertia * wn), abs=1e-5)
    assert mode.dominant == "swing"
    assert m.opt.timestep == 0.001 and m.opt.integrator == own  # restored


def test_continuous_jacobians_invert_zero_order_hold():
    rng = np.random.default_rng(0)
    A = rng.normal(size=(4, 4)) - 3 * np.eye(4)
    B = rng.normal(size=(4, 2))
    sys_d = control.c2d(control.ss(A, B, np.eye(4), 0), 0.01, method="zoh")
    A_c, B_c = continuous_jacobians(np.asarray(sys_d.A), np.asarray(sys_d.B), 0.01)
    assert np.allclose(A_c, A, atol=1e-9) and np.allclose(B_c, B, atol=1e-9)


@pytest.mark.parametrize("config", ["1dof", "2dof"])
def test_linear_model_predicts_the_twin_for_small_inputs(config):
    """Known truth: for small voltage deviations the nonlinear twin and its linearisation agree."""
    twin = Twin(config, 0.1, counts_per_rev=0, still_air=True)
    lin = twin.linearise()
    assert lin.discrete.dt == pytest.approx(0.1)
    rng = np.random.default_rng(4)
    du = 0.005 * rng.choice([-1.0, 1.0], size=(300, len(twin.input_names)))
    rec = twin.run(twin.operating_point.inputs + du)
    _, y_lin = control.forced_response(lin.discrete, T=rec.time, U=du.T)
    y_twin = rec.extras["true_angles"][:, [("pitch", "yaw").index(o) for o in twin.output_names]]
    err = np.max(np.abs(np.atleast_2d(y_lin).T - y_twin), axis=0)
    scale = np.max(np.abs(y_twin), axis=0)
    assert np.all(err < 0.02 * scale), (err, scale)


def test_modes_of_the_published_parameter_twin():
    """Before calibration, the published parameters give a yaw mode at 0.1 Hz and a pitch pendulum near 0.3 Hz."""
    spec = with_parameters(load_spec(), published_parameters())
    modes2 = Twin("2dof", 0.1, spec=spec).modes()
    yaw = [m for m in modes2 if m.dominant == "yaw"]
    pitch = [m for m in modes2 if m.dominant == "pitch"]
    assert yaw[0].frequency_hz == pytest.approx(0.1, abs=0.01)
    assert 0.25 < pitch[0].frequency_hz < 0.4
    assert all(0 < m.damping < 0.2 for m in modes2[:2])
    # Locking yaw removes the yaw mode and keeps the pitch pendulum.
    modes1 = Twin("1dof", 0.1, spec=spec).modes()
    assert all(m.dominant != "yaw" for m in modes1)
    assert modes1[0].frequency_hz == pytest.approx(pitch[0].frequency_hz, rel=0.02)
    # With the cable uncoupled, u1 drives yaw strongly (reaction torque) and u2 drives pitch weakly.
    g = Twin("2dof", 0.1, spec=spec).linearise().continuous
    dc = np.asarray(control.dcgain(g))
    assert abs(dc[1, 0]) > 0.5 and abs(dc[0, 1]) < 0.1 * abs(dc[0, 0])
