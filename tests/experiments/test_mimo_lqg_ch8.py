"""Chapter 8 future work: the 2-DOF LQG autopilot, two SISO loops, the reduced design model, robustness."""

import control
import numpy as np
import pytest

from trms.control import DiagonalController, residualise
from trms.errors import ConfigurationError, InputError
from trms.experiments import mimo_lqg_ch8 as c8
from trms.experiments import robustness as rb
from trms.experiments.plants import design_model, make_plant, resample
from trms.reference import eq_3_11


@pytest.fixture(scope="module")
def model():
    return design_model("2dof")


@pytest.fixture(scope="module")
def linear_runs(model):
    return c8.autopilot_runs(make_plant("linear", "2dof"), model)


def test_reduced_design_model_keeps_the_rigid_and_motor_states_and_the_dc_gain(model):
    from trms.twin import Twin

    rigid = ["yaw", "pitch", "yaw_rate", "pitch_rate", "main_rotor_activation", "tail_rotor_activation"]
    assert list(model.state_labels)[:6] == rigid
    twin = Twin("2dof", 0.1)
    # the transport delay's past inputs follow: whole samples of delay, plus one when it ends inside a sample
    delay_samples = int(np.ceil(twin.input_delay / 0.1 - 1e-9))
    assert model.nstates == 6 + 2 * delay_samples
    full = twin.linearise().discrete
    # residualisation keeps the DC gain exactly (up to the linear solve's rounding)
    np.testing.assert_allclose(control.dcgain(model), control.dcgain(full), rtol=1e-8)


def test_residualise_refuses_bad_input():
    sys = control.ss([[-1.0, 0.0], [0.0, 0.0]], [[1.0], [1.0]], [[1.0, 1.0]], 0)
    with pytest.raises(InputError, match="A22 is singular"):
        residualise(sys, [0])
    with pytest.raises(InputError, match="distinct state indices"):
        residualise(sys, [0, 0])
    with pytest.raises(InputError, match="continuous-time"):
        residualise(control.c2d(control.ss(-1.0, 1.0, 1.0, 0.0), 0.1), [0])


def test_resampling_eq_3_11_keeps_its_continuous_dynamics():
    from trms.control.realization import observer_canonical

    fast = resample(observer_canonical(eq_3_11()), 0.1)
    assert fast.dt == 0.1
    assert control.dcgain(fast) == pytest.approx(float(control.dcgain(eq_3_11())), rel=1e-9)
    # poles map as z_fast = z_slow ** (0.1 / 0.2)
    slow = np.sort_complex(np.asarray(eq_3_11().poles()) ** 0.5)
    np.testing.assert_allclose(np.sort_complex(fast.poles()), slow, atol=1e-9)


def test_the_mimo_design_cuts_the_yaw_coupling_of_the_pitch_command(linear_runs):
    mimo = linear_runs[("MIMO LQG", "pitch square wave")].measures
    siso = linear_runs[("two SISO loops", "pitch square wave")].measures
    # the two SISO loops cannot use u2 against u1's reaction torque on the yaw; the MIMO design can
    assert mimo["cross"] < 0.8 * siso["cross"]
    for run in linear_runs.values():
        assert run.status == "ran" and np.isfinite(run.measures["TR"])


def test_diagonal_controller_keeps_each_loop_on_its_own_channel(model):
    ctrl = c8.controllers(model)["two SISO loops"]
    ctrl.reset()
    u = ctrl.update([0.0, 0.1], [0.0, 0.0])  # a yaw error only
    assert u[0] == 0.0 and u[1] != 0.0
    with pytest.raises(InputError, match="one output and one input per loop"):
        DiagonalController(ctrl.loops, (0,), (0, 1), 2)


def test_linear_world_refuses_disturbances():
    with pytest.raises(ConfigurationError, match="twin only"):
        make_plant("linear", "1dof", gusts=True)


def test_parameter_draw_is_seeded_and_within_the_spread():
    a, b = rb.draw_parameters(5, seed=3), rb.draw_parameters(5, seed=3)
    assert a == b and a != rb.draw_parameters(5, seed=4)
    from trms.twin import load_spec
    from trms.twin.parameters import read_parameters

    nominal = read_parameters(load_spec(), rb.SPREAD_PARAMETERS)
    for sample in a:
        for k, v in sample.items():
            assert abs(v / nominal[k] - 1.0) <= rb.SPREAD


def test_monte_carlo_table_is_complete():
    batch = rb.monte_carlo(2, seed=1, processes=False, progress=False)
    t = rb.table(batch, rb.nominal(), seed=1)
    assert t.missing() == []
    assert all(len(v) == 2 for v in batch.values())
    assert t.rows[0][4].endswith("/2")


def test_section_is_complete(model, linear_runs, tmp_path):
    twin = c8.autopilot_runs(make_plant("twin", "2dof", gusts=True), model)
    sec = c8.section({"linear": linear_runs, "twin": twin}, tmp_path)
    assert sec.tables[0].missing() == []
    assert all(f.path.is_file() for f in sec.figures)
