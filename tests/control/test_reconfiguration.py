"""The reconfiguring LQG on known truth: a lag whose input gain drops is detected, estimated and re-designed for."""

from __future__ import annotations

import control
import numpy as np
import pytest

from trms.control.detection import ChiSquareDetector
from trms.control.lqg import LQGController, design_lqg
from trms.control.reconfiguration import ReconfiguringLQG, embedded
from trms.errors import DesignError, InputError

LAG = control.ss([[0.9]], [[0.1]], [[1.0]], [[0.0]], 0.1)


def _fly(loop, gain_after, seed, n=400, at=150):
    y, rng = 0.0, np.random.default_rng(seed)
    errors = []
    for k in range(n):
        r = 0.2 if (k // 60) % 2 else -0.2
        u = float(loop.update(r, y)[0])
        errors.append(r - y)
        y = 0.9 * y + (0.1 if k < at else 0.1 * gain_after) * u + 0.01 * rng.standard_normal()
    return np.array(errors)


def _detector():
    return ChiSquareDetector([[2e-4]], window=5, false_alarm_rate=1e-3)


@pytest.mark.parametrize("gain", [0.7, 0.5, 0.35])
@pytest.mark.parametrize("seed", [1, 2, 3])
def test_a_lost_input_gain_is_detected_by_the_next_steps_and_estimated_within_a_tenth(gain, seed):
    loop = ReconfiguringLQG(LAG, design_lqg, _detector(), decide_after=20)
    _fly(loop, gain, seed)  # the fault at sample 150, mid-way through a hold; the next steps at 180 and 240
    assert loop.alarm_sample is not None and 150 <= loop.alarm_sample < 250  # within the next two steps
    assert loop.effectiveness[0] == pytest.approx(gain, abs=0.1)
    assert loop.controller.design.model.B[0, 0] == pytest.approx(0.1 * loop.effectiveness[0])


@pytest.mark.parametrize("seed", [4, 5, 6, 7])
def test_a_healthy_loop_is_never_re_designed(seed):
    loop = ReconfiguringLQG(LAG, design_lqg, _detector(), decide_after=20)
    _fly(loop, 1.0, seed)
    assert loop.switch_sample is None and loop.effectiveness[0] == 1.0


def test_the_re_designed_loop_tracks_better_than_the_nominal_one_after_the_fault():
    fixed = _fly(ReconfiguringLQG(LAG, design_lqg, _detector(), decide_after=20), 0.35, 8)
    nominal = _fly(LQGController(design_lqg(LAG)), 0.35, 8)
    after = slice(200, None)
    assert np.sqrt(np.mean(fixed[after] ** 2)) < 0.97 * np.sqrt(np.mean(nominal[after] ** 2))


def test_reset_returns_to_the_nominal_design():
    loop = ReconfiguringLQG(LAG, design_lqg, _detector(), decide_after=20)
    _fly(loop, 0.5, 1)
    loop.reset()
    assert loop.alarm_sample is None and loop.effectiveness[0] == 1.0
    assert loop.controller.design.model.B[0, 0] == pytest.approx(0.1)


def test_bumpless_transfer_keeps_the_command_continuous():
    a, b = LQGController(design_lqg(LAG)), LQGController(design_lqg(LAG, R=10.0))
    y, u = 0.0, []
    for k in range(60):
        if k == 30:
            b.continue_from(a)
        u.append(float((a if k < 30 else b).update(0.1, y)[0]))
        y = 0.9 * y + 0.1 * u[-1]
    steps = np.abs(np.diff(u[20:40]))
    assert steps[9] <= 1.5 * max(steps[8], steps[10])  # the switch (29 -> 30) is no bigger than its neighbours
    with pytest.raises(InputError, match="cannot continue from a controller of 2 states"):
        b.continue_from(
            LQGController(design_lqg(control.ss(np.diag([0.9, 0.5]), [[0.1], [0.1]], [[1.0, 1.0]], 0, 0.1)))
        )


def test_a_frozen_reading_is_taken_for_a_dead_sensor_and_the_loop_runs_on_its_model_meanwhile():
    loop = ReconfiguringLQG(LAG, design_lqg, _detector(), decide_after=20, frozen_after=5)
    y, rng, held = 0.0, np.random.default_rng(3), None
    truth = []
    for k in range(300):
        r = 0.2 if (k // 60) % 2 else -0.2
        reading = held if 100 <= k < 160 else y  # the sensor freezes at sample 100 for 60 samples
        held = y if k == 99 else held
        u = float(loop.update(r, reading)[0])
        truth.append(y)
        y = 0.9 * y + 0.1 * u + 0.01 * rng.standard_normal()
    assert loop.sensor_faults == [(103, 160)]  # five equal readings: the last true one (99) and four frozen
    assert loop.switch_sample is None and loop.effectiveness[0] == 1.0  # not an actuator fault
    # running on its model, the loop still followed the step at sample 120 with the sensor dead
    assert abs(np.mean(truth[150:160]) + 0.2) < 0.05  # the reference there: -0.2 rad since sample 120


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"design": 3}, "design must be a function model -> LQGDesign, got int"),
        ({"frozen_after": 1}, r"frozen_after = 1 is outside the allowed range \[2, inf\]"),
        ({"model": control.tf([1], [1, 1])}, "model must be a discrete control.StateSpace, got TransferFunction"),
        ({"detector": "chi2"}, "detector must be a ChiSquareDetector, got str"),
        ({"detector": ChiSquareDetector(np.eye(2))}, "the detector tests 2 outputs; the model has 1"),
        ({"decide_after": 0}, r"decide_after = 0 is outside the allowed range \[1, inf\]"),
        ({"tolerance": 1.5}, r"tolerance = 1.5 is outside the allowed range"),
        ({"drop_below": 0.0}, r"drop_below = 0.0 is outside the allowed range \(0.0, 1.0\]"),
    ],
)
def test_bad_settings_are_refused_in_one_line(kwargs, match):
    args = {"model": LAG, "design": design_lqg, "detector": _detector(), **kwargs}
    with pytest.raises(InputError, match=match):
        ReconfiguringLQG(**args)


def test_a_design_function_that_returns_no_design_is_named():
    with pytest.raises(
        DesignError, match=r"design function <lambda> returned None \(NoneType\); allowed: an LQGDesign"
    ):
        ReconfiguringLQG(LAG, lambda model: None, _detector())


# ------------------------------------------------------------------ two inputs, one of them lost
A2 = np.diag([0.9, 0.8])
B2 = np.array([[0.1, 0.03], [0.04, 0.1]])
TWO = control.ss(A2, B2, np.eye(2), np.zeros((2, 2)), 0.1)


def _design_two(model):
    """Both outputs integrated with both inputs; the first alone with one input left."""
    kept = int(np.count_nonzero(np.any(np.asarray(model.B) != 0.0, axis=0)))
    return design_lqg(model, tracked_outputs=[0, 1] if kept == 2 else [0])


def _fly_two(loop, seed, n=400, at=150):
    """Square waves on both outputs; the second input's gain drops to 0 at ``at`` (a stuck actuator, at trim)."""
    x, rng, errors = np.zeros(2), np.random.default_rng(seed), []
    for k in range(n):
        r = np.array([0.2 if (k // 60) % 2 else -0.2, 0.2 if ((k + 30) // 80) % 2 else -0.2])
        y = x + 0.01 * rng.standard_normal(2)
        u = np.clip(loop.update(r, y), -2.0, 2.0)
        errors.append(r - y)
        x = A2 @ x + B2 @ (u if k < at else u * [1.0, 0.0])
    return np.array(errors)


@pytest.mark.parametrize("seed", [1, 2])
def test_a_stuck_input_of_two_is_estimated_dropped_and_the_other_output_tracked_at_least_as_well(seed):
    detector = ChiSquareDetector(np.eye(2) * 1e-4, window=10, false_alarm_rate=1e-4)
    loop = ReconfiguringLQG(TWO, _design_two, detector, (-2.0, 2.0), decide_after=20, drop_below=0.3)
    fixed = _fly_two(loop, seed)
    sample, first = next((k, e) for k, e in loop.estimates if k >= 150)
    assert sample < 180  # decided within 30 samples of the fault
    assert first == pytest.approx([1.0, 0.0], abs=0.1)
    assert loop.effectiveness[1] == 0.0 and loop.effectiveness[0] == pytest.approx(1.0, abs=0.1)
    assert loop.controller.design.tracked == (0, 1) and np.all(loop.controller.design.K[1] == 0.0)
    nominal = _fly_two(LQGController(_design_two(TWO), (-2.0, 2.0)), seed)
    after = slice(200, None)
    rms = [float(np.sqrt(np.mean(e[after, 0] ** 2))) for e in (fixed, nominal)]
    assert rms[0] <= rms[1]


def test_an_embedded_design_acts_as_the_smaller_one_and_refuses_an_output_it_cannot_hold():
    small = design_lqg(TWO, tracked_outputs=[1])
    big = embedded(small, (0, 1))
    assert big.tracked == (0, 1) and np.array_equal(big.K[:, [0, 1, 3]], small.K)
    assert np.all(big.Ki[:, 0] == 0.0) and big.cost([0.0, 0.0, 5.0, 1.0]) == pytest.approx(small.cost([0, 0, 1.0]))
    assert np.sum(np.isclose(big.regulator_poles, 1.0)) == 1  # the added integrator counts, never acts
    assert embedded(small, (1,)) is small
    with pytest.raises(DesignError, match=r"tracks outputs \[1\] that the loop does not"):
        embedded(small, (0,))
