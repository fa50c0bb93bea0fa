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
    pitch_weights,
)
from trms.control.loop import closed_loop
from trms.errors import ConfigurationError, InputError
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
