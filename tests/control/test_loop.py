"""Closed loop on any Plant: deviation conventions, Record contents, agreement with python-control, refusals."""

import control
import numpy as np
import pytest

from trms.control.loop import closed_loop, deviation_limits
from trms.control.lqg import LQGController, design_lqg
from trms.control.shaping import butterworth_lowpass
from trms.errors import ConfigurationError, InputError
from trms.plant import LinearPlant, simulate
from trms.record import OperatingPoint
from trms.signals import square_wave

TRIM = OperatingPoint(np.array([4.5]), np.array([-0.3]), ("u1",), ("y1",))


@pytest.fixture
def design(pitch_model):
    return design_lqg(pitch_model, Q=1.0, R=75.0)


def test_sas_matches_the_python_control_closed_loop(pitch_model, design):
    ctl = LQGController(design)
    ref = square_wave(80.0, 0.2, 40.0, 0.2)
    rec = closed_loop(LinearPlant(pitch_model), ctl, ref)
    comp = ctl.compensator()
    # u = comp_r r + comp_y y and y = P u: the same loop built by python-control
    loop = control.feedback(pitch_model, comp[:, 1:], sign=1) * control.ss([], [], [], [[1.0]], 0.2)
    pre = comp[:, :1]
    sys = control.series(pre, loop)
    _, y = control.forced_response(sys, T=rec.time, U=ref)
    assert rec.outputs[:, 0] == pytest.approx(np.ravel(y), abs=1e-9)


def test_trim_is_handled_in_one_place(pitch_model, design):
    ref = square_wave(40.0, 0.2, 20.0, 0.1)
    base = closed_loop(LinearPlant(pitch_model), LQGController(design), ref)
    trimmed = closed_loop(LinearPlant(pitch_model, operating_point=TRIM), LQGController(design), ref)
    assert trimmed.inputs[:, 0] == pytest.approx(base.inputs[:, 0] + 4.5, abs=1e-12)
    assert trimmed.outputs[:, 0] == pytest.approx(base.outputs[:, 0] - 0.3, abs=1e-12)
    du, dy = trimmed.deviations()
    assert du[:, 0] == pytest.approx(trimmed.extras["control"][:, 0], abs=1e-12)
    assert trimmed.metadata["operating_point"]["inputs"] == [4.5]


def test_record_extras_and_csas(pitch_model, design):
    ref = square_wave(40.0, 0.2, 20.0, 0.2)
    lpf = butterworth_lowpass(2, 0.2, 0.2)
    rec = closed_loop(LinearPlant(pitch_model), LQGController(design), ref, prefilter=lpf, seed=3)
    for key, shape in [
        ("reference", (200, 1)),
        ("prefiltered_reference", (200, 1)),
        ("control", (200, 1)),
        ("estimate", (200, 4)),
        ("applied_inputs", (200, 1)),
        ("saturated", (200, 1)),
        ("state", (200, 4)),
    ]:
        assert rec.extras[key].shape == shape
    assert rec.extras["prefiltered_reference"][:, 0] == pytest.approx(lpf.apply(ref), abs=1e-15)
    assert rec.metadata["loop"] == "CSAS" and rec.metadata["prefilter"] == lpf.name and rec.metadata["seed"] == 3
    # CSAS is the SAS driven by the prefiltered command
    sas = closed_loop(LinearPlant(pitch_model), LQGController(design), lpf.apply(ref))
    assert rec.outputs == pytest.approx(sas.outputs, abs=1e-15)
    # the record is the same as an open-loop simulate of the same inputs
    again = simulate(LinearPlant(pitch_model), rec.inputs, seed=3)
    assert again.outputs == pytest.approx(rec.outputs, abs=1e-15)


def test_saturation_is_recorded_with_deviation_limits(pitch_model):
    plant = LinearPlant(pitch_model, operating_point=TRIM, input_limits=(-10.0, 10.0))
    lower, upper = deviation_limits(plant)
    assert lower.tolist() == [-14.5] and upper.tolist() == [5.5]
    ctl = LQGController(design_lqg(pitch_model, R=1.0), input_limits=(lower, upper))
    rec = closed_loop(plant, ctl, square_wave(40.0, 0.2, 20.0, 0.5))
    sat = rec.extras["saturated"][:, 0]
    assert sat.any()
    assert np.all(np.isin(rec.extras["applied_inputs"][sat, 0], [-10.0, 10.0]))
    assert np.all(np.abs(rec.inputs[sat, 0]) > 10.0)


class _Proportional:
    """A minimal controller satisfying the protocol: u = k (r - y)."""

    sample_time = 0.2

    def __init__(self, k):
        self.k = k

    def reset(self):
        pass

    def update(self, reference, measurement):
        return self.k * (np.asarray(reference) - np.asarray(measurement))


def test_any_controller_with_the_protocol_runs(pitch_model):
    rec = closed_loop(LinearPlant(pitch_model), _Proportional(0.1), np.full(50, 0.1))
    assert "estimate" not in rec.extras
    assert rec.extras["control"][0, 0] == pytest.approx(0.01)


@pytest.mark.parametrize(
    "make, error, match",
    [
        (
            lambda m, d: closed_loop(
                LinearPlant(m), LQGController(design_lqg(control.ss(m.A, m.B, m.C, m.D, 0.1), R=1.0)), np.zeros(5)
            ),
            ConfigurationError,
            r"controller sample time 0.1 s differs from the plant's 0.2 s",
        ),
        (
            lambda m, d: closed_loop(
                LinearPlant(m), LQGController(d), np.zeros(5), prefilter=butterworth_lowpass(2, 0.1, 0.1)
            ),
            ConfigurationError,
            "prefilter sample time 0.1 s differs",
        ),
        (
            lambda m, d: closed_loop(LinearPlant(m), LQGController(d), np.zeros((5, 2))),
            InputError,
            r"reference .* must have shape \(any, 1\)",
        ),
        (
            lambda m, d: closed_loop(LinearPlant(m), LQGController(d), [0.0, np.inf]),
            InputError,
            "reference .* must be finite",
        ),
        (lambda m, d: closed_loop(LinearPlant(m), LQGController(d), np.zeros(0)), InputError, "at least one sample"),
    ],
)
def test_bad_loops_are_refused(pitch_model, design, make, error, match):
    with pytest.raises(error, match=match):
        make(pitch_model, design)


def test_an_input_shaper_is_a_prefilter_and_tames_the_mode(pitch_model):
    from trms.control.metrics import square_wave_metrics
    from trms.control.shaping import model_modes, shaper_for_modes

    shaper = shaper_for_modes(model_modes(pitch_model)).at(0.2)
    ctl = LQGController(design_lqg(pitch_model, R=1.0))
    ref = square_wave(80.0, 0.2, 40.0, 0.2)
    sas = square_wave_metrics(closed_loop(LinearPlant(pitch_model), ctl, ref))
    csas = square_wave_metrics(closed_loop(LinearPlant(pitch_model), ctl, ref, prefilter=shaper))
    assert max(m.overshoot for m in csas) < 0.5 * max(m.overshoot for m in sas)
    assert max(m.peak_control for m in csas) < max(m.peak_control for m in sas)


@pytest.mark.parametrize("columns", [1, 2])
def test_a_prefiltered_controller_is_the_csas_loop_sample_by_sample(columns):
    """The same bits as closed_loop with the prefilter, one reference column or two."""
    from trms.control.loop import DiagonalController, Prefiltered
    from trms.control.pid import PIDController, PIDGains

    m = control.ss(np.diag([0.9, 0.8][:columns]), np.eye(columns) * 0.1, np.eye(columns), 0.0, 0.1)
    plant = LinearPlant(m)
    lp = butterworth_lowpass(2, 0.3, 0.1)
    ref = np.column_stack([square_wave(20.0, 0.1, 10.0, 0.2 * (k + 1)) for k in range(columns)])

    def make():
        loops = [PIDController(PIDGains(kp=1.0, ki=0.5, kd=0.0), 0.1) for _ in range(columns)]
        return DiagonalController(loops, tuple(range(columns)), tuple(range(columns)), columns)

    a = closed_loop(plant, make(), ref, lp)
    b = closed_loop(plant, Prefiltered(make(), lp), ref)
    assert np.array_equal(a.extras["control"], b.extras["control"])
    assert np.array_equal(a.outputs, b.outputs)


def test_a_prefiltered_controller_needs_second_order_sections_at_its_sample_time():
    from trms.control.loop import Prefiltered
    from trms.control.pid import PIDController, PIDGains
    from trms.control.shaping.sampled import discrete_shaper

    pid = PIDController(PIDGains(kp=1.0, ki=0.0, kd=0.0), 0.1)
    with pytest.raises(InputError, match="prefilter must be a CommandFilter"):
        Prefiltered(pid, discrete_shaper([(0.3, 0.1)], 0.1))
    with pytest.raises(ConfigurationError, match="prefilter sample time 0.2 s differs"):
        Prefiltered(pid, butterworth_lowpass(2, 0.3, 0.2))
