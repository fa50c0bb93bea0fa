"""Chapter 8 future work: the 2-DOF LQG autopilot, two SISO loops, the reduced design model, robustness."""

import control
import numpy as np
import pytest

from trms.control import DiagonalController, residualise
from trms.errors import ConfigurationError, InputError
from trms.experiments import ch8_autopilot_margins as cm
from trms.experiments import ch8_mimo_lqg as c8
from trms.experiments import robustness as rb
from trms.reference import eq_3_11
from trms.worlds import design_model, make_plant, resample


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
    mimo = linear_runs[("MIMO LQG", "pitch step")].measures
    siso = linear_runs[("two SISO loops", "pitch step")].measures
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


# ------------------------------------------------------------------------------ the design and its margins
def test_the_design_has_adequate_margins_on_the_twins_linearisation_and_damps_the_pitch_mode(model):
    from trms.control.damping import mode_damping
    from trms.experiments.ch8_designs import feedback_compensator

    by_scale = {m.scale: m for m in cm.shipped_margin_scan(0.1)}
    assert set(by_scale) == set(c8.R_SCALES) and by_scale[1.0].adequate
    feedback = feedback_compensator(c8.controllers(model)["MIMO LQG"], 2)
    assert mode_damping(model, feedback, frequency_hz=0.34).closed.damping >= 0.12


def test_the_weights_are_per_channel_and_the_two_siso_loops_share_them(model):
    q = np.diag(c8.weights(model))
    names = list(model.state_labels)
    assert q[names.index("pitch")] == c8.STATE_WEIGHTS["pitch"] != q[names.index("yaw")]
    assert all(q[i] == 0.0 for i, n in enumerate(names) if "[k-" in n)
    assert c8.control_weights().tolist() == [[c8.CONTROL_WEIGHTS[0], 0.0], [0.0, c8.CONTROL_WEIGHTS[1]]]
    loops = c8.controllers(model)["two SISO loops"].loops
    assert [float(loop.design.R[0, 0]) for loop in loops] == list(c8.CONTROL_WEIGHTS)


def test_the_autopilot_meets_its_targets_on_the_twin_in_moving_air_at_most_unseen_seeds(model):
    """The targets are the twin's. Its settling time is the last exit from a band of 3 standard deviations of the
    loop's wobble at rest, which a late gust crosses now and then (at about one step in six over 36 unseen seed-steps,
    by a few tenths of a millirad): every target but the settling time holds at every seed, the settling time at most
    (three of four here)."""
    missed = []
    for seed in (912, 913, 914, 915):
        runs = c8.autopilot_runs(make_plant("twin", "2dof", seed=seed), model, seed, names=("MIMO LQG",))
        for scen in c8.SCENARIOS:
            missed += [(seed, scen, m) for m in c8.meets_targets(scen, runs[("MIMO LQG", scen)].measures)]
    assert all(m.startswith("TS ") for _, _, m in missed), missed
    assert len(missed) <= 2, missed


def test_report_tasks_and_robustness_share_the_design(model):
    from trms.envs.tasks import TASKS, TaskRunner
    from trms.experiments import task_baselines as tb

    chosen = c8.controllers(model)["MIMO LQG"]
    task = next(t for t in TASKS.values() if t.config == "2dof")
    baseline = tb._controller(TaskRunner(task))  # behind the prefilter and the inversion
    np.testing.assert_array_equal(baseline.controller.controller.design.K, chosen.design.K)
    _, _, _, meta = rb.loop_setup(next(n for n, c in rb.LOOPS.items() if c == "2dof"), make_plant("twin", "2dof"))
    assert meta["scenario"] == "pitch step"


def test_the_autopilots_mimo_lqg_is_the_scans_run_at_the_design_scale(model, linear_runs):
    # what lets the report take the autopilot's runs as the scan's at scale 1 instead of flying them twice
    scan = c8.scan_runs(make_plant("linear", "2dof"), model, (1.0,))[1.0]
    for scen in c8.SCENARIOS:
        flown, again = linear_runs[("MIMO LQG", scen)], scan[scen]
        np.testing.assert_equal(flown.measures, again.measures)  # the same bits (a nan where it never settled)
        assert np.array_equal(flown.record.outputs, again.record.outputs)
        assert np.array_equal(flown.record.inputs, again.record.inputs)


def test_unknown_scenarios_are_refused_in_one_line():
    with pytest.raises(InputError, match="unknown scenario 'loop'; allowed: 'pitch step', 'yaw step'"):
        c8.scenario_reference("loop", 0.1)
