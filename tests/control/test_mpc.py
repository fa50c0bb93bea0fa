"""Constrained MPC: the unconstrained first move is the LQR's, constraints hold on the twin, offset-free tracking,
real-time solves, refusals."""

import sys

import control
import numpy as np
import pytest
import scipy.linalg
import scipy.sparse as sp

from trms.control.loop import closed_loop, deviation_limits
from trms.control.mpc import MPCController, load_osqp, mpc_for_plant
from trms.errors import ConfigurationError, DesignError, InputError, SimulationError
from trms.plant import LinearPlant
from trms.worlds import design_model, make_plant

TS = 0.1


@pytest.fixture(scope="module")
def model():
    return design_model("1dof", TS)


@pytest.mark.parametrize("limited", [False, True])
def test_the_unconstrained_first_move_is_the_lqr(model, limited):
    """Finite horizon with the Riccati terminal cost: u_0 = u_s - K (x_0 - x_s), K from dlqr."""
    far = {"input_limits": (-1e3, 1e3), "rate_limit": 1e3, "output_limits": (-50.0, 50.0)} if limited else {}
    mpc = MPCController(model, horizon=25, Q=np.diag([1.0, 0.5, 0.2, 0.1]), R=0.3, **far)
    K, _, _ = control.dlqr(model.A, model.B, mpc.Q, mpc.R)
    rng = np.random.default_rng(11)
    for _ in range(3):
        x0, d, r = 0.1 * rng.standard_normal(4), 0.2 * rng.standard_normal(1), 0.2 * rng.standard_normal(1)
        xs, us = mpc.target(r, d)
        assert abs((model.C @ xs)[0] - r[0]) < 1e-12
        assert np.max(np.abs(mpc.plan(x0, d, r, previous_input=us)[0] - (us - K @ (x0 - xs)))) < 1e-8


def test_every_constraint_holds_on_the_twin(model):
    plant = make_plant("twin", "1dof", TS)
    ref = np.r_[np.full(150, 0.2), np.full(150, -0.2)]
    free = closed_loop(plant, mpc_for_plant(model, plant, horizon=30), ref, seed=2)
    mpc = mpc_for_plant(model, plant, horizon=30, rate_limit=0.3, output_limits=(-0.22, 0.22))
    rec = closed_loop(plant, mpc, ref, seed=2)
    u = rec.extras["control"][:, 0]
    lo, hi = deviation_limits(plant)
    pitch = plant.operating_point.output_deviation(rec.outputs)[:, 0]
    free_u = free.extras["control"][:, 0]
    free_pitch = plant.operating_point.output_deviation(free.outputs)[:, 0]
    # without the output and rate limits the loop passes both
    assert np.max(np.abs(free_pitch)) > 0.24 and np.max(np.abs(np.diff(free_u))) > 0.4
    assert np.all(u >= lo - 1e-9) and np.all(u <= hi + 1e-9)
    assert np.max(np.abs(np.diff(np.r_[0.0, u]))) <= 0.3 + 1e-9
    assert np.max(np.abs(pitch)) <= 0.22 + 0.005  # soft limit: encoder noise and model error on top
    assert np.max(mpc.solve_times) < TS  # real time at Ts = 0.1 s


def test_an_active_input_limit_clips_the_one_step_optimum(model):
    """Horizon 1, one input: the QP is a scalar parabola on an interval, so its solution is the clipped optimum."""
    free = MPCController(model, horizon=1)
    boxed = MPCController(model, horizon=1, input_limits=(-0.05, 0.05))
    x0, d, r = np.array([0.0, 0.0, 0.0, 0.0]), np.zeros(1), np.array([0.2])
    u_free = free.plan(x0, d, r)[0, 0]
    assert u_free > 0.05
    assert abs(boxed.plan(x0, d, r)[0, 0] - 0.05) < 1e-6


def test_tracking_is_offset_free_under_a_model_error(model):
    wrong = control.ss(model.A, 1.3 * np.asarray(model.B), model.C, model.D, TS)  # 30 % more gain than designed
    plant = LinearPlant(wrong, noise_std=0.0)
    rec = closed_loop(plant, MPCController(model, horizon=30), np.full(400, 0.2), seed=0)
    assert abs(rec.outputs[-1, 0] - 0.2) < 1e-4
    assert abs(rec.extras["estimate"][-1, -1] - 0.3 * rec.extras["control"][-1, 0]) < 1e-3  # d_hat = 0.3 u


def test_hard_limits_that_no_input_can_meet_raise_one_line(model):
    mpc = MPCController(model, horizon=10, input_limits=(-10.0, 10.0), output_limits=(-1.1, 1.1), soft=False)
    with pytest.raises(SimulationError, match="infeasible") as err:
        mpc.plan([1.5, 0.0, 0.0, 0.0], [0.0], [0.0])
    assert "\n" not in str(err.value)


def test_a_missing_solver_names_the_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "osqp", None)
    with pytest.raises(ConfigurationError, match=r"pip install 'trms\[control\]'") as err:
        load_osqp()
    assert "\n" not in str(err.value)


@pytest.mark.parametrize(
    ("kwargs", "error", "text"),
    [
        ({"input_limits": (1.0, 2.0)}, InputError, "lower <= 0 <= upper"),
        ({"rate_limit": 0.0}, InputError, "rate_limit must be > 0"),
        ({"rate_limit": [1.0, 2.0]}, InputError, "rate_limit must be a scalar"),
        ({"output_limits": (0.5, 0.2)}, InputError, "lower < upper"),
        ({"horizon": 0}, InputError, "horizon = 0"),
        ({"R": 0.0}, DesignError, "R must be positive definite"),
    ],
)
def test_bad_settings_are_refused_in_one_line(model, kwargs, error, text):
    with pytest.raises(error, match=text) as err:
        MPCController(model, **kwargs)
    assert "\n" not in str(err.value)


# ---------------------------------------------------------------------------------------------- 2-DOF (2 x 2)
@pytest.fixture(scope="module")
def model_2dof():
    return design_model("2dof")


def test_the_unconstrained_first_move_is_the_lqr_on_the_two_by_two_model(model_2dof):
    m = model_2dof
    limits = {"input_limits": (-1e3, 1e3), "rate_limit": 1e3, "output_limits": (-50.0, 50.0)}
    mpc = MPCController(m, horizon=25, Q=np.diag(np.r_[1.0, 2.0, np.full(14, 0.1)]), R=np.diag([0.3, 0.5]), **limits)
    K, _, _ = control.dlqr(m.A, m.B, mpc.Q, mpc.R)
    rng = np.random.default_rng(5)
    for _ in range(3):
        x0, d, r = 0.1 * rng.standard_normal(16), 0.2 * rng.standard_normal(2), 0.2 * rng.standard_normal(2)
        xs, us = mpc.target(r, d)
        assert np.max(np.abs(m.C @ xs - r)) < 1e-12  # both outputs at their references: offset-free on both
        assert np.max(np.abs(mpc.plan(x0, d, r, previous_input=us)[0] - (us - K @ (x0 - xs)))) < 1e-8


def test_every_constraint_of_both_inputs_and_both_outputs_holds_on_the_two_dof_twin(model_2dof):
    """Both axes stepped at once (pitch 0.2 rad, yaw 0.3 rad): unconstrained, the loop passes a 0.25 rad pitch limit,
    a 0.2 V per sample rate and a -0.4 V tail-rotor limit; constrained, the hard input and rate limits hold exactly,
    and the soft output limits to within the twin's model error (the design model is its linearisation)."""
    plant = make_plant("twin", "2dof", seed=2)
    ref = np.tile([0.2, 0.3], (80, 1))
    limits = {"input_limits": ([-0.5, -0.4], [0.5, 0.4]), "output_limits": ([-0.25, -0.33], [0.25, 0.33])}
    runs = [mpc_for_plant(model_2dof, plant, horizon=20, Qd=1e-5, **kw) for kw in ({}, {"rate_limit": 0.2, **limits})]
    (_, free_u, free_y), (rec, u, y) = (
        (r, r.extras["control"], plant.operating_point.output_deviation(r.outputs))
        for r in (closed_loop(plant, c, ref, seed=2) for c in runs)
    )
    moves, free_moves = (np.abs(np.diff(np.r_[np.zeros((1, 2)), v], axis=0)) for v in (u, free_u))  # u_{-1} = 0
    assert free_y[:, 0].max() > 0.28 and free_moves.max() > 0.4 and free_u[:, 1].min() < -0.45
    assert np.all(u >= np.array(limits["input_limits"][0]) - 1e-9) and np.all(u <= np.array(limits["input_limits"][1]))
    assert moves.max() <= 0.2 + 1e-9
    assert np.any(np.abs(u[:, 1] + 0.4) <= 1e-9) and runs[1].qp_solves > 0  # the limits were active (to round-off)
    assert np.abs(y[:, 0]).max() <= 0.25 + 0.03 and np.abs(y[:, 1]).max() <= 0.33 + 0.005
    assert abs(rec.outputs[-1, 1] - plant.operating_point.outputs[1] - 0.3) < 0.1  # the yaw still goes to its target


@pytest.mark.parametrize(
    ("kwargs", "text"),
    [
        ({"input_limits": ([-1.0, -1.0, -1.0], 1.0)}, r"input_limits lower must be a scalar or have shape \(2,\)"),
        ({"output_limits": (-1.0, [1.0, 2.0, 3.0])}, r"output_limits upper must be a scalar or have shape \(2,\)"),
        ({"tracked_outputs": [2]}, "tracked_outputs"),
        ({"R": np.eye(3)}, "R"),
    ],
)
def test_wrong_sizes_for_the_two_by_two_model_are_refused_in_one_line(model_2dof, kwargs, text):
    with pytest.raises(InputError, match=text) as err:
        MPCController(model_2dof, horizon=5, **kwargs)
    assert "\n" not in str(err.value)


def test_hard_end_stops_no_input_sequence_can_meet_raise_one_line_on_the_two_by_two_model(model_2dof):
    mpc = MPCController(model_2dof, horizon=10, input_limits=(-0.1, 0.1), output_limits=(-0.05, 0.05), soft=False)
    x0 = np.zeros(16)
    x0[1] = 0.5  # the pitch state at 0.5 rad, ten times its hard limit, with 0.1 V to bring it back
    with pytest.raises(SimulationError, match="infeasible") as err:
        mpc.plan(x0, np.zeros(2), np.zeros(2))
    assert "\n" not in str(err.value)


@pytest.mark.parametrize("tracked", [None, (0,)])
def test_the_compensator_is_the_controller_while_no_constraint_acts(model_2dof, tracked):
    """Away from every limit the MPC is its linear law: the same commands as its updates, to rounding."""
    mpc = MPCController(model_2dof, horizon=20, tracked_outputs=tracked)
    K = mpc.compensator()
    rng = np.random.default_rng(7)
    x, worst = np.zeros(K.nstates), 0.0
    for k in range(60):
        r = 0.01 * np.sin(np.arange(len(mpc.tracked)) + k / 7.0)
        y = 0.002 * rng.standard_normal(2)
        w = np.r_[r, y]
        worst = max(worst, float(np.max(np.abs(K.C @ x + K.D @ w - mpc.update(r, y)))))
        x = K.A @ x + K.B @ w
    assert worst <= 1e-9 and mpc.qp_solves == 0
    assert K.ninputs == len(mpc.tracked) + 2 and K.noutputs == 2


# --------------------------------------------------------------------------- the plan is the QP's optimum
def _independent_plan(mpc, x0, d, r, up, softness=(1e4, 1e5)):
    """The MPC problem written afresh (the predictions simulated input by input, the cost summed over the horizon)
    and solved by a fresh OSQP at tight tolerances: first move, predicted outputs and the largest slack."""
    A, B, C = (np.asarray(v, float) for v in (mpc.model.A, mpc.model.B, mpc.model.C))
    n, m, p, N = A.shape[0], B.shape[1], C.shape[0], mpc.horizon
    xs, us = mpc.target(r, d)
    (lo, hi), rate, (ylo, yhi) = mpc.input_limits, mpc.rate_limit, mpc.output_limits

    def states(inputs, start, disturbance):  # x_1 .. x_N stacked
        x, out = start, []
        for u in inputs.reshape(N, m):
            x = A @ x + B @ (u + disturbance)
            out.append(x)
        return np.concatenate(out)

    free = states(np.zeros(N * m), x0, d)
    G = np.column_stack([states(e, np.zeros(n), np.zeros(m)) for e in np.eye(N * m)])
    weights = [mpc.Q] * (N - 1) + [mpc.P]
    Qb = scipy.linalg.block_diag(*weights)
    Rb = np.kron(np.eye(N), mpc.R)
    ns = N * p if mpc.soft else 0
    H = scipy.linalg.block_diag(G.T @ Qb @ G + Rb, softness[1] * np.eye(ns))
    q = np.r_[G.T @ Qb @ (free - np.tile(xs, N)) - Rb @ np.tile(us, N), np.full(ns, 0.5 * softness[0])]
    Cb = np.kron(np.eye(N), C)
    y_free, y_in = Cb @ free, Cb @ G
    slack = np.eye(ns) if ns else np.zeros((N * p, 0))
    step = np.eye(N * m) - np.eye(N * m, k=-m)
    rows = [
        (np.hstack([np.eye(N * m), np.zeros((N * m, ns))]), np.tile(lo, N), np.tile(hi, N)),
        (
            np.hstack([step, np.zeros((N * m, ns))]),
            np.r_[up - rate, np.tile(-rate, N - 1)],
            np.r_[up + rate, np.tile(rate, N - 1)],
        ),
        (np.hstack([y_in, -slack]), np.full(N * p, -np.inf), np.tile(yhi, N) - y_free),
        (np.hstack([y_in, slack]), np.tile(ylo, N) - y_free, np.full(N * p, np.inf)),
        (np.hstack([np.zeros((ns, N * m)), np.eye(ns)]), np.zeros(ns), np.full(ns, np.inf)),
    ]
    solver = load_osqp().OSQP()
    solver.setup(
        sp.csc_matrix(np.triu(H)),
        q,
        sp.csc_matrix(np.vstack([r_[0] for r_ in rows])),
        np.concatenate([r_[1] for r_ in rows]),
        np.concatenate([r_[2] for r_ in rows]),
        verbose=False,
        eps_abs=1e-11,
        eps_rel=1e-11,
        max_iter=200_000,
        polish_refine_iter=20,
    )
    res = solver.solve(raise_error=True)
    assert res.info.status == "solved"
    plan = res.x[: N * m]
    return plan[:m], (y_free + y_in @ plan).reshape(N, p), float(np.max(res.x[N * m :], initial=0.0))


@pytest.mark.parametrize("case", ["soft, limits met", "soft, limits missed", "hard"])
@pytest.mark.parametrize("config", ["1dof", "2dof"])
@pytest.mark.parametrize("seed", [0, 1])
def test_the_first_move_is_an_independent_solvers_and_the_hard_limits_hold(config, case, seed):
    model = design_model(config, TS)
    n, m, p = model.nstates, model.ninputs, model.noutputs
    rng = np.random.default_rng([4321, seed, len(case), m])
    ulim, rate, ylim = rng.uniform(0.5, 3.0, m), rng.uniform(0.05, 0.4), rng.uniform(0.1, 0.3, p)
    mpc = MPCController(
        model,
        horizon=int(rng.integers(10, 26)),
        input_limits=(-ulim, ulim),
        rate_limit=rate,
        output_limits=(-ylim, ylim),
        soft=case != "hard",
    )
    r, d = rng.uniform(-0.5, 0.5, p) * ylim, 0.05 * rng.standard_normal(m)
    # a state the loop reaches: 15 samples of a random admissible input from rest, the last move held before
    x0, up = np.zeros(n), np.zeros(m)
    for _ in range(15):
        up = np.clip(up + rng.uniform(-rate, rate, m), -ulim, ulim)
        x0 = model.A @ x0 + model.B @ (up + d)
    x, held = x0, []
    for _ in range(mpc.horizon):  # holding u_{-1}: an admissible plan
        x = model.A @ x + model.B @ (up + d)
        held.append(model.C @ x)
    ylim = np.maximum(ylim, 1.2 * np.abs(np.array(held)).max(axis=0))  # it meets the output limits: feasible
    if case == "soft, limits missed":  # the outputs start twice their limits away: no plan brings them back at once
        x0 = x0 + np.linalg.lstsq(np.asarray(model.C), 2.0 * ylim * rng.choice([-1.0, 1.0], p), rcond=None)[0]
    mpc = MPCController(
        model,
        horizon=mpc.horizon,
        input_limits=(-ulim, ulim),
        rate_limit=rate,
        output_limits=(-ylim, ylim),
        soft=case != "hard",
    )
    plan = mpc.plan(x0, d, r, previous_input=up)
    first, outputs, slack = _independent_plan(mpc, x0, d, r, up)
    assert (slack > 1e-3) == (case == "soft, limits missed")
    assert np.max(np.abs(plan[0] - first)) <= 1e-5
    assert mpc.info["converged"] and mpc.info["kkt_residual"] <= 1e-9
    assert np.all(plan >= -ulim) and np.all(plan <= ulim)  # hard limits exactly, not to a tolerance
    moves = np.abs(np.diff(np.vstack([up, plan]), axis=0))
    assert np.all(moves <= rate * (1 + 1e-12))
    if case == "hard":
        x, predicted = x0, []
        for u in plan:
            x = model.A @ x + model.B @ (u + d)
            predicted.append(model.C @ x)
        assert np.all(np.abs(predicted) <= ylim + 1e-9) and np.allclose(predicted, outputs, atol=1e-5)


def test_a_plan_osqp_leaves_unconverged_is_solved_exactly(model, monkeypatch):
    import trms.control.mpc as mpc_module

    monkeypatch.setattr(mpc_module, "_MAX_ITER", 10)
    mpc = MPCController(model, horizon=20, input_limits=(-1.0, 1.0), rate_limit=0.1, output_limits=(-0.05, 0.05))
    x0 = np.array([0.0, 0.2, 0.0, 0.0])  # pitch 0.2 rad, four times the soft limit
    plan = mpc.plan(x0, np.zeros(1), np.zeros(1), previous_input=np.zeros(1))
    assert mpc.info["solver"] == "exact" and mpc.info["osqp_status"] == "maximum iterations reached"
    assert mpc.info["converged"] and mpc.exact_solves == 1 and mpc.unconverged == 0
    first = _independent_plan(mpc, x0, np.zeros(1), np.zeros(1), np.zeros(1))[0]
    assert np.max(np.abs(plan[0] - first)) <= 1e-5


def test_a_plan_no_solver_certifies_is_flagged_and_kept_within_the_hard_limits(model, monkeypatch):
    import trms.control.mpc as mpc_module
    import trms.control.qp as qp

    monkeypatch.setattr(mpc_module, "_MAX_ITER", 10)
    monkeypatch.setattr(qp, "solve_exact", lambda *a: (_ for _ in ()).throw(RuntimeError("maximum iterations")))
    mpc = MPCController(model, horizon=20, input_limits=(-1.0, 1.0), rate_limit=0.1, output_limits=(-0.05, 0.05))
    with pytest.warns(mpc_module.UnconvergedPlanWarning, match="not certified optimal") as caught:
        plan = mpc.plan(np.array([0.0, 0.2, 0.0, 0.0]), np.zeros(1), np.zeros(1), previous_input=np.zeros(1))
    assert "\n" not in str(caught[0].message)
    assert not mpc.info["converged"] and mpc.unconverged == 1 and mpc.info["kkt_residual"] > 1e-9
    assert np.all(np.abs(plan) <= 1.0) and np.all(np.abs(np.diff(np.r_[0.0, plan[:, 0]])) <= 0.1 * (1 + 1e-12))
