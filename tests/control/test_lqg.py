"""Integral LQG: separation principle, optimal cost, current vs predictor gain, tracking, refusals."""

import control
import numpy as np
import pytest

from trms.control.loop import closed_loop
from trms.control.lqg import LQGController, design_lqg
from trms.errors import ConfigurationError, DesignError, InputError
from trms.plant import LinearPlant
from trms.reference import LQG_WEIGHTS_R, eq_3_11, eq_6_33

# Poles are eigenvalues of well-conditioned matrices of size <= 12: 1e-7 is far above rounding
# and far below any design change (a 1 % change of R moves them by ~1e-4).
POLE_TOL = 1e-7


def _match_poles(a, b):
    a, b = list(np.asarray(a, complex)), list(np.asarray(b, complex))
    assert len(a) == len(b)
    for z in a:
        k = int(np.argmin([abs(z - w) for w in b]))
        assert abs(z - b.pop(k)) < POLE_TOL


def _closed_loop_poles(model, controller):
    comp = controller.compensator()
    n_ref = controller.n_references
    comp_y = comp[:, n_ref:]  # from y to u; the plant is in positive feedback through it
    loop = control.feedback(model, comp_y, sign=1)
    return loop.poles()


@pytest.mark.parametrize("r", LQG_WEIGHTS_R)
@pytest.mark.parametrize("injection", ["error", "integrator"])
def test_closed_loop_poles_are_regulator_plus_estimator_poles(pitch_model, r, injection):
    d = design_lqg(pitch_model, Q=1.0, R=r, reference_injection=injection)
    _match_poles(_closed_loop_poles(pitch_model, LQGController(d)), np.r_[d.regulator_poles, d.estimator_poles])
    assert np.all(np.abs(d.regulator_poles) < 1) and np.all(np.abs(d.estimator_poles) < 1)


def test_separation_holds_for_a_mimo_design(mimo_model):
    d = design_lqg(mimo_model, Q=np.diag([1, 1, 1, 1, 1, 10, 10]), R=np.diag([1.0, 2.0]), Qe=0.5, Re=[0.1, 0.2])
    assert d.K.shape == (2, 7) and d.Lc.shape == (5, 2)
    _match_poles(_closed_loop_poles(mimo_model, LQGController(d)), np.r_[d.regulator_poles, d.estimator_poles])


@pytest.mark.parametrize("r", [1.0, 75.0])
def test_regulator_cost_equals_riccati_value_and_is_minimal(pitch_model, r):
    d = design_lqg(pitch_model, Q=1.0, R=r)
    Aa, Ba = d.augmented()
    x0 = np.array([0.1, -0.2, 0.05, 0.3, -0.4])

    def cost(K):
        x, J = x0.copy(), 0.0
        for _ in range(4000):  # slowest pole |z| < 0.95: the tail after 4000 steps is < 1e-80
            u = -K @ x
            J += x @ d.Q @ x + u @ d.R @ u
            x = Aa @ x + Ba @ u
        return J

    assert cost(d.K) == pytest.approx(d.cost(x0), rel=1e-9)
    rng = np.random.default_rng(0)
    for _ in range(5):  # any nearby stabilising gain costs more
        dK = 1e-3 * rng.standard_normal(d.K.shape) * np.abs(d.K).max()
        assert cost(d.K + dK) > d.cost(x0)


def test_filter_gain_differs_from_dlqe_predictor_gain(pitch_model):
    d = design_lqg(pitch_model, Q=1.0, R=75.0)
    A = np.asarray(pitch_model.A)
    assert d.Lp == pytest.approx(A @ d.Lc, abs=1e-12)
    assert np.max(np.abs(d.Lp - d.Lc)) > 0.1  # the two gains are genuinely different
    C = np.asarray(pitch_model.C)
    Pe = d.Pe
    assert d.Lc == pytest.approx(Pe @ C.T / (C @ Pe @ C.T + d.Re), abs=1e-12)


@pytest.mark.parametrize("injection", ["error", "integrator"])
def test_compensator_system_reproduces_update(pitch_model, injection):
    d = design_lqg(pitch_model, R=1.0, reference_injection=injection)
    ctl = LQGController(d)
    rng = np.random.default_rng(5)
    r, y = rng.standard_normal(50), rng.standard_normal(50)
    u = np.array([ctl.update(r[k], y[k])[0] for k in range(50)])
    comp = ctl.compensator()
    _, u_sys = control.forced_response(comp, T=np.arange(50) * 0.2, U=np.vstack([r, y]))
    assert u == pytest.approx(np.ravel(u_sys), abs=1e-9)
    assert comp.dt == pytest.approx(0.2)


@pytest.mark.parametrize("injection", ["error", "integrator"])
@pytest.mark.parametrize("gain_error", [1.0, 1.3])
def test_zero_steady_state_error_to_a_step(pitch_model, injection, gain_error):
    plant = LinearPlant(pitch_model * gain_error)  # integral action also absorbs a 30 % gain error
    ctl = LQGController(design_lqg(pitch_model, R=75.0, reference_injection=injection))
    rec = closed_loop(plant, ctl, np.full(400, 0.2))
    assert abs(rec.outputs[-1, 0] - 0.2) < 1e-9


def test_zero_steady_state_error_on_each_output_of_a_mimo_plant(mimo_model):
    ctl = LQGController(design_lqg(mimo_model, Q=1.0, R=1.0))
    ref = np.tile([0.3, -0.1], (600, 1))
    rec = closed_loop(LinearPlant(mimo_model), ctl, ref)
    assert rec.outputs[-1] == pytest.approx([0.3, -0.1], abs=1e-9)


def test_estimate_follows_the_saturated_plant_exactly(pitch_model):
    # The controller's estimator uses the clipped input, which is what the plant held, so with a
    # perfect model and the estimator fed y (integrator injection) the estimate IS the state.
    plant = LinearPlant(pitch_model, input_limits=(-0.05, 0.05))
    ctl = LQGController(design_lqg(pitch_model, R=1.0, reference_injection="integrator"), input_limits=(-0.05, 0.05))
    rec = closed_loop(plant, ctl, np.full(200, 0.3))
    assert rec.extras["saturated"].any()
    # row k: "state" is x(k) (the plant's channel at t_k), "estimate" is x_hat(k)
    assert rec.extras["estimate"] == pytest.approx(rec.extras["state"], abs=1e-12)


def test_anti_windup_holds_the_integrator_and_limits_overshoot(pitch_model):
    d = design_lqg(pitch_model, R=1.0, reference_injection="integrator")
    plant = LinearPlant(pitch_model, input_limits=(-0.21, 0.21))
    ref = np.full(600, 0.3)
    aware = closed_loop(plant, LQGController(d, input_limits=(-0.21, 0.21)), ref)
    naive = closed_loop(plant, LQGController(d), ref)  # does not know the limits: winds up
    assert aware.extras["saturated"].any() and naive.extras["saturated"].any()
    over_aware = aware.outputs[:, 0].max() - 0.3
    over_naive = naive.outputs[:, 0].max() - 0.3
    assert over_aware < 0.5 * over_naive
    assert abs(aware.outputs[-1, 0] - 0.3) < 1e-6


def test_integrator_is_held_while_pushing_into_saturation(pitch_model):
    ctl = LQGController(design_lqg(pitch_model, R=1.0), input_limits=(-0.01, 0.01))
    u = ctl.update(1.0, 0.0)
    assert u[0] > 0.01 and ctl.saturated[0]
    assert ctl.integral == pytest.approx([0.0])  # the error would have pushed u further up
    ctl2 = LQGController(design_lqg(pitch_model, R=1.0))
    ctl2.update(1.0, 0.0)
    assert ctl2.integral == pytest.approx([1.0])


def test_bad_update_leaves_the_controller_unchanged(pitch_model):
    ctl = LQGController(design_lqg(pitch_model, R=75.0))
    ctl.update(0.1, 0.0)
    before = (ctl.estimate, ctl.integral)
    with pytest.raises(InputError, match="measurement .* must be finite"):
        ctl.update(0.1, np.nan)
    with pytest.raises(InputError, match=r"reference .* must have shape \(1,\)"):
        ctl.update([0.1, 0.2], 0.0)
    assert ctl.estimate == pytest.approx(before[0]) and ctl.integral == pytest.approx(before[1])


def test_estimator_is_faster_than_the_regulator_for_the_thesis_weights(pitch_model):
    for r in LQG_WEIGHTS_R:
        assert design_lqg(pitch_model, R=r).estimator_faster


def _unstabilisable():
    # an unstable mode (z = 1.2) that u cannot reach
    return control.ss([[1.2, 0.0], [0.0, 0.5]], [[0.0], [1.0]], [[1.0, 1.0]], [[0.0]], 0.2)


def _zero_at_one():
    # y/u = (z - 1) / (z - 0.5)^2: the integral of the error is unreachable
    return control.ss(control.tf([1, -1], [1, -1, 0.25], 0.2))


@pytest.mark.parametrize(
    "kwargs, error, match",
    [
        (dict(system=_unstabilisable()), DesignError, r"not stabilisable: modes \[\(1.2\+0j\)\]"),
        (dict(system=_zero_at_one()), DesignError, "not stabilisable.*zero at z = 1"),
        (dict(R=0.0), DesignError, r"R must be positive definite; its smallest eigenvalue is 0 \(allowed: > 0\)"),
        (dict(R=-75.0), DesignError, "R must be positive definite; its smallest eigenvalue is -75"),
        (
            dict(Q=-1.0),
            DesignError,
            r"Q must be positive semi-definite; its smallest eigenvalue is -1 \(allowed: >= 0\)",
        ),
        (dict(Q=np.diag([1, 1, 1, 1, -0.5])), DesignError, "Q must be positive semi-definite"),
        (dict(Q=np.triu(np.ones((5, 5)))), DesignError, "Q must be symmetric"),
        (dict(Q=np.eye(4)), InputError, r"Q must have shape \(5, 5\)"),
        (dict(Re=0.0), DesignError, "Re must be positive definite"),
        (dict(Qe="big"), InputError, r"Qe must be real numbers \(float64\), got 'big': text values are not allowed"),
        (dict(system=eq_6_33()), DesignError, r"direct term D = \[\[0.0097\]\]"),
        (dict(system=eq_3_11()), InputError, "must be a python-control StateSpace, got TransferFunction"),
        (dict(system=control.ss([[-1.0]], [[1.0]], [[1.0]], [[0.0]])), ConfigurationError, "discrete-time"),
        (dict(tracked_outputs=[1]), InputError, r"distinct output indices in \[0, 0\]"),
        (dict(reference_injection="feedforward"), InputError, "unknown reference_injection 'feedforward'"),
    ],
)
def test_bad_designs_are_refused(pitch_model, kwargs, error, match):
    args = dict(system=pitch_model, Q=1.0, R=75.0)
    args.update(kwargs)
    with pytest.raises(error, match=match):
        design_lqg(**args)


def test_undetectable_pair_is_refused():
    sys = control.ss([[1.2, 0.0], [0.0, 0.5]], [[1.0], [1.0]], [[0.0, 1.0]], [[0.0]], 0.2)
    with pytest.raises(DesignError, match=r"\(A, C\) is not detectable"):
        design_lqg(sys, R=1.0)


@pytest.mark.parametrize("limits", [(0.5, 1.0), (-1.0, -0.5), (1.0, -1.0)])
def test_bad_limits_are_refused(pitch_model, limits):
    with pytest.raises(InputError, match="lower <= 0 <= upper"):
        LQGController(design_lqg(pitch_model, R=75.0), input_limits=limits)


def test_nan_limits_are_refused_and_infinite_ones_accepted(pitch_model):
    design = design_lqg(pitch_model, R=75.0)
    with pytest.raises(InputError, match=r"input_limits lower must be numbers or \+-inf, not NaN"):
        LQGController(design, input_limits=(np.nan, 1.0))
    assert LQGController(design, input_limits=(-np.inf, 1.0)).input_limits[0].tolist() == [-np.inf]
