"""H-infinity mixed sensitivity: the textbook design of Skogestad and Postlethwaite, the pitch design, refusals."""

import sys
import warnings

import control
import numpy as np
import pytest

from trms.control.hinf import (
    FAST_MODE,
    HinfController,
    _one_blas_thread,
    continuous_model,
    design_mixsyn,
    diagonal_weights,
    pitch_weights,
)
from trms.control.loop import closed_loop
from trms.errors import ConfigurationError, InputError
from trms.plant import LinearPlant
from trms.worlds import design_model, make_plant

TS = 0.1


def _response(sys_, points):
    """``C (x I - A)^-1 B + D`` at each point, by direct solves (python-control's evaluation loses digits on the
    synthesis's badly scaled realisations)."""
    A, B, C, D = (np.asarray(getattr(sys_, m), float) for m in "ABCD")
    x = np.linalg.solve(points[:, None, None] * np.eye(A.shape[0]) - A, np.broadcast_to(B, (points.size, *B.shape)))
    return (C @ x + D)[:, 0, 0]


@pytest.fixture(scope="module")
def pitch():
    model = design_model("1dof", TS)
    return model, design_mixsyn(model, *pitch_weights())


def test_the_textbook_design_matches_mixsyn_and_the_published_gamma():
    """Skogestad and Postlethwaite, Multivariable Feedback Control (2005), example 2.11:
    G = 200 / ((10 s + 1)(0.05 s + 1)^2), W1 = (s / 1.5 + 10) / (s + 1e-3), W2 = 1; gamma = 1.37."""
    s = control.tf("s")
    G = 200 / ((10 * s + 1) * (0.05 * s + 1) ** 2)
    W1, W2 = (s / 1.5 + 10) / (s + 10 * 1e-4), control.tf([1.0], [1.0])
    mine = design_mixsyn(G, W1, W2)
    with warnings.catch_warnings(), _one_blas_thread():  # same BLAS threads as the design: only speed differs
        warnings.simplefilter("ignore", FutureWarning)  # python-control's own connect()
        K, CL, info = control.mixsyn(G, W1, W2, None)
    assert abs(mine.gamma - info[0]) <= 1e-12 * info[0]
    assert round(mine.gamma, 2) == 1.37
    w = np.logspace(-2, 3, 200)
    for a, b in ((mine.controller, K), (mine.closed_loop, CL)):
        fa, fb = _response(a, 1j * w), _response(b, 1j * w)
        assert np.max(np.abs(fa - fb)) <= 1e-9 * np.max(np.abs(fb))
    assert mine.discrete_controller is None


def test_the_pitch_loop_is_stable_with_the_promised_disk_margin(pitch):
    model, design = pitch
    assert design.sample_time == TS and design.gamma < 1.0
    assert design.stable_with(model)
    margin = design.margin(model)
    assert margin.stable and margin.alpha >= 1.0 / (design.gamma * 2.0 + 0.5)  # the bound of W1's M = 2


def test_tustin_of_the_controller_without_its_fast_mode(pitch):
    _, design = pitch
    kc, kd = design.controller, design.discrete_controller
    fast = np.abs(kc.poles()) > FAST_MODE * np.pi / TS
    assert fast.sum() == 1 and kd.nstates == kc.nstates - 1  # the synthesis's pole near -1e8 rad/s is residualised
    z = np.exp(1j * np.array([1e-9, 0.05, 0.7, 5.0]) * TS)  # s = 0 maps to z = 1
    s = 2.0 / TS * (z - 1.0) / (z + 1.0)
    # below the fast mode the residualised, discretised controller is K(s) at the Tustin frequency
    assert np.max(np.abs(_response(kd, z) - _response(kc, s)) / np.abs(_response(kc, s))) <= 1e-4
    assert np.all(np.abs(kd.poles()) < 1.0) and np.min(np.real(kd.poles())) > -0.5


def test_the_continuous_model_is_the_exact_inverse_of_the_zero_order_hold():
    model = design_model("1dof", TS)
    back = control.c2d(continuous_model(model), TS, method="zoh")
    assert np.allclose(back.A, model.A, atol=1e-10) and np.allclose(back.B, model.B, atol=1e-12)


def test_the_controller_tracks_the_linear_model(pitch):
    model, design = pitch
    plant = make_plant("linear", "1dof", TS, noise_std=0.0)
    rec = closed_loop(plant, HinfController(design, (-10.0, 10.0)), np.full(300, 0.2), seed=0)
    assert abs(rec.outputs[-1, 0] - plant.operating_point.outputs[0] - 0.2) < 2e-3


def test_a_missing_slycot_names_the_extra(monkeypatch):
    plant = control.ss([[-1.0]], [[1.0]], [[1.0]], [[0.0]])
    monkeypatch.setitem(sys.modules, "slycot", None)
    with pytest.raises(ConfigurationError, match=r"pip install 'trms\[control\]'") as err:
        design_mixsyn(plant, control.tf([1.0], [1.0, 1e-3]))
    assert "\n" not in str(err.value)


def test_a_discrete_weight_is_refused():
    with pytest.raises(InputError, match="W1 must be a continuous"):
        design_mixsyn(design_model("1dof", TS), control.tf([1.0], [1.0, 0.5], TS))


# ---------------------------------------------------------------------------------------------- 2 x 2
def _two_by_two():
    """A coupled, stable 2 x 2 textbook plant (first-order entries, 20 % and 10 % off-diagonal) and its weights."""
    G = control.ss(control.tf([[[1.0], [0.2]], [[0.1], [1.0]]], [[[1.0, 1.0], [1.0, 2.0]], [[1.0, 1.0], [1.0, 3.0]]]))
    return G, diagonal_weights(pitch_weights(bandwidth=0.5), pitch_weights(bandwidth=0.3, effort=0.1))


def _mimo_response(sys_, points):
    A, B, C, D = (np.asarray(getattr(sys_, m), float) for m in "ABCD")
    x = np.linalg.solve(points[:, None, None] * np.eye(A.shape[0]) - A, np.broadcast_to(B, (points.size, *B.shape)))
    return C @ x + D


def test_the_two_by_two_design_is_python_controls_own_mixsyn():
    G, (W1, W2) = _two_by_two()
    mine = design_mixsyn(G, W1, W2, sample_time=TS)
    with warnings.catch_warnings(), _one_blas_thread():
        warnings.simplefilter("ignore", FutureWarning)
        K, CL, info = control.mixsyn(control.ss(G), W1, W2, None)
    assert abs(mine.gamma - info[0]) <= 1e-12 * info[0] and mine.gamma < 1.0
    w = 1j * np.logspace(-2, 3, 100)
    for a, b in ((mine.controller, K), (mine.closed_loop, CL)):
        fa, fb = _mimo_response(a, w), _mimo_response(b, w)
        assert fa.shape == fb.shape and np.max(np.abs(fa - fb)) <= 1e-9 * np.max(np.abs(fb))
    assert np.allclose(np.diag(np.abs(W1(0))), [1e3, 1e3]) and abs(W1(0)[0, 1]) == 0.0  # diagonal weights


def test_the_two_by_two_controller_runs_through_closed_loop_and_holds_both_outputs():
    G, weights = _two_by_two()
    design = design_mixsyn(G, *weights, sample_time=TS)
    plant = LinearPlant(control.c2d(G, TS), noise_std=0.0, input_limits=(-10.0, 10.0))
    ctrl = HinfController(design, ([-10.0, -10.0], [10.0, 10.0]))
    assert ctrl.n_references == 2 and design.stable_with(control.c2d(G, TS))
    rec = closed_loop(plant, ctrl, np.tile([0.2, -0.1], (300, 1)), seed=0)
    assert np.max(np.abs(rec.outputs[-1] - [0.2, -0.1])) < 2e-3 * 0.2  # |S(0)| <= 1e-3 on both channels
    # the loop's inputs are the discrete controller's response to the recorded errors
    Kd = design.discrete_controller
    err = rec.extras["reference"] - rec.outputs
    x, u = np.zeros(Kd.nstates), []
    for e in err:
        u.append(Kd.C @ x + Kd.D @ e)
        x = Kd.A @ x + Kd.B @ e
    assert np.max(np.abs(np.array(u) - rec.extras["control"])) <= 1e-9


@pytest.mark.parametrize(
    ("weights", "text"),
    [
        ((control.tf([1.0], [1.0, -0.5]), None), "W1 has a pole at s = 0.5 rad/s; allowed: poles with real part < 0"),
        ((control.tf([1.0], [1.0, 0.0]), None), "W1 has a pole at s = 0 rad/s"),
        ((control.tf([1.0], [1.0, 1e-3]), control.tf([0.1], [1.0])), "W1 must be 2x2"),
        ((None, None), "W1 must be a continuous python-control LTI"),
    ],
)
def test_bad_weights_are_refused_in_one_line(weights, text):
    G, (W1, W2) = _two_by_two()
    W1_, W2_ = weights
    if W2_ is None and W1_ is not None:  # a SISO weight checked on a SISO plant
        G, W2_ = G[0, 0], W2[0, 0]
    with pytest.raises(InputError, match=text) as err:
        design_mixsyn(G, W1_, W2_)
    assert "\n" not in str(err.value)


def test_a_plant_that_is_not_square_is_refused():
    G, (W1, _) = _two_by_two()
    with pytest.raises(InputError, match="model must be square .* got 2 outputs x 1 inputs"):
        design_mixsyn(G[:, 0], W1)
    discrete = control.ss([[0.0]], [[1.0, 0.5]], [[1.0]], [[0.0, 0.0]], TS)  # a pole at z = 0: no matrix logarithm
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # refused before any conversion warns
        with pytest.raises(InputError, match="model must be square .* got 1 outputs x 2 inputs"):
            design_mixsyn(discrete, *pitch_weights())


@pytest.mark.parametrize("pole", [0.0, -0.5])
def test_a_discrete_plant_without_a_continuous_equivalent_is_refused(pole):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(InputError, match=rf"pole at z = {pole:g}: .* no continuous zero-order-hold equivalent"):
            design_mixsyn(control.ss([[pole]], [[1.0]], [[1.0]], [[0.0]], TS), *pitch_weights())


def test_the_controller_refuses_text_in_one_line(pitch):
    controller = HinfController(pitch[1])
    with pytest.raises(InputError, match=r"measurement \(deviation rad\) must be real numbers .* got 'x'"):
        controller.update(0.0, "x")
    with pytest.raises(InputError, match=r"reference \(deviation rad\) must be 1 number, got 2"):
        controller.update([0.1, 0.2], 0.0)


def test_the_disturbance_channel_tends_to_mixsyn_and_damps_the_mode_it_would_cancel():
    from trms.control.damping import mode_damping
    from trms.worlds import design_model

    model = design_model("1dof")
    W1, W2 = pitch_weights()
    plain = design_mixsyn(model, W1, W2)
    tiny = design_mixsyn(model, W1, W2, Wd=control.tf([1e-6], [1.0]))
    assert tiny.gamma == pytest.approx(plain.gamma, rel=1e-6) and tiny.disturbance_weight is not None
    heavy = design_mixsyn(model, W1, W2, Wd=control.tf([0.5], [1.0]))
    assert heavy.gamma > plain.gamma  # the disturbance blocks cost performance
    assert mode_damping(model, heavy.discrete_controller).closed.damping >= 0.15
    assert heavy.stable_with(model)


def test_the_disturbance_plant_is_the_interconnection_it_says():
    """With K = 0: r reaches z1 as W1, d reaches z1 as -W1 G Wd, u reaches z2 as W2, e = r - G (u + Wd d)."""
    from trms.control.generalised_plant import disturbance_plant

    s = control.tf("s")
    G = control.ss(2.0 / (s + 1))
    W1, W2, Wd = control.tf([3.0], [1.0]), control.tf([0.1], [1.0]), control.tf([0.5], [1.0])
    dc = np.asarray(control.dcgain(disturbance_plant(G, W1, W2, None, Wd)))
    # rows z1, z2, e; columns r, d, u
    np.testing.assert_allclose(dc, [[3.0, -3.0, -6.0], [0.0, 0.0, 0.1], [1.0, -1.0, -2.0]], atol=1e-12)
    with_t = disturbance_plant(G, W1, W2, control.tf([0.2], [1.0]), Wd)
    np.testing.assert_allclose(np.asarray(control.dcgain(with_t))[2], [0.0, 0.2, 0.4], atol=1e-12)


def test_a_disturbance_weight_needs_a_control_weight():
    s = control.tf("s")
    with pytest.raises(InputError, match="Wd needs a control weight W2"):
        design_mixsyn(1 / (s + 1), control.tf([0.5, 1], [1, 1e-3]), None, Wd=control.tf([0.5], [1.0]))
