"""Designs that would silently be wrong are refused."""

import control
import numpy as np
import pytest

from trms.control.loop import DiagonalController
from trms.control.lq_design import augment_with_integrators, current_estimator_gain
from trms.control.lqg import LQGController, design_lqg
from trms.control.metrics import step_edges, step_metrics
from trms.control.plots import plot_closed_loop
from trms.control.realization import observer_canonical, residualise
from trms.control.shaping.continuous import shaper_for_modes, zv_shaper, zvd_shaper
from trms.control.shaping.filters import bands_around, butterworth_bandstop, butterworth_lowpass, multiband_bandstop
from trms.errors import ConfigurationError, DesignError, InputError
from trms.worlds import design_model


def test_q_zero_loses_integral_action_and_is_refused():
    with pytest.raises(DesignError, match=r"largest \|z\| = .*Q = 0 loses integral action"):
        design_lqg(design_model("1dof"), Q=0.0, R=125.0)
    design = design_lqg(design_model("1dof"), Q=1.0, R=125.0)
    assert np.abs(design.regulator_poles).max() < 1.0


@pytest.mark.parametrize(
    "make",
    [lambda f: zv_shaper(f, 0.05), lambda f: zvd_shaper(f, 0.05), lambda f: shaper_for_modes([(0.1, 0.1), (f, 0.05)])],
)
def test_a_shaper_for_a_mode_above_nyquist_is_refused(make):
    ts = 0.2
    with pytest.raises(InputError, match=r"at or above the Nyquist frequency 2.5 Hz"):
        make(10.0).at(ts)  # would collapse to the identity filter
    with pytest.raises(InputError, match="Nyquist"):
        make(2.5).at(ts)
    taps = make(1.0).at(ts).taps
    assert np.count_nonzero(taps) > 1


@pytest.mark.parametrize("time", [np.linspace(5.0, 0.0, 20), np.r_[0.0, 1.0, 1.0, np.arange(2.0, 19.0)]])
def test_step_metrics_need_increasing_time(time):
    with pytest.raises(InputError, match="time must increase strictly"):
        step_metrics(time, np.linspace(0, 1, 20), np.zeros(20), 0.0, 1.0)


# ------------------------------------------------ bad inputs: one InputError line, never a numpy/scipy leak


def _model():
    return design_model("1dof")


def _with(matrix, value=np.nan):
    """The design model with entry (0, 0) of A, B or C replaced."""
    m = _model()
    mats = {k: np.array(getattr(m, k), float) for k in "ABCD"}
    mats[matrix][0, 0] = value
    return control.ss(mats["A"], mats["B"], mats["C"], mats["D"], m.dt)


def _record():
    from trms.record import Record

    t = np.arange(4) * 0.2
    return Record(
        t,
        np.zeros((4, 1)),
        np.zeros((4, 1)),
        ("u",),
        ("pitch",),
        {"reference": np.ones((4, 1)), "control": np.zeros((4, 1))},
        {},
    )


LPF = (2, 0.2, 0.2)  # order, cutoff Hz, Ts s

BAD_INPUTS = {
    # integral LQG: the model
    "A nan": (lambda: design_lqg(_with("A")), r"system.A must be finite; found nan at index \(0, 0\)"),
    "B inf": (lambda: design_lqg(_with("B", np.inf)), r"system.B must be finite; found inf at index \(0, 0\)"),
    "C nan": (lambda: design_lqg(_with("C")), r"system.C must be finite; found nan"),
    # integral LQG: the weights (LQR) and covariances (Kalman)
    "Q nan": (lambda: design_lqg(_model(), Q=np.nan), r"Q must be finite; found nan"),
    "R inf": (lambda: design_lqg(_model(), R=np.inf), r"R must be finite; found inf"),
    "Qe nan matrix": (lambda: design_lqg(_model(), Qe=np.full((4, 4), np.nan)), r"Qe must be finite"),
    "R text": (lambda: design_lqg(_model(), R="75"), r"R must be real numbers \(float64\), got '75': text values"),
    "Q text": (lambda: design_lqg(_model(), Q="1"), r"Q must be real numbers \(float64\), got '1': text values"),
    "Re text": (lambda: design_lqg(_model(), Re="1"), r"Re must be real numbers \(float64\), got '1'"),
    "R bool": (lambda: design_lqg(_model(), R=True), r"R must be real numbers \(float64\), got True: booleans"),
    "Qe bool": (lambda: design_lqg(_model(), Qe=False), r"Qe must be real numbers \(float64\), got False: booleans"),
    "R None": (lambda: design_lqg(_model(), R=None), r"R must be real numbers \(float64\), got None"),
    "noise_input text": (lambda: design_lqg(_model(), noise_input="x"), r"noise_input must be real numbers"),
    "tracked text": (lambda: design_lqg(_model(), tracked_outputs="0"), r"tracked_outputs must be a non-empty seq"),
    "tracked float": (
        lambda: design_lqg(_model(), tracked_outputs=[0.5]),
        r"integers, distinct output indices in \[0, 0\], got \[0.5\]",
    ),
    "tracked int": (lambda: design_lqg(_model(), tracked_outputs=0), r"tracked_outputs must be a non-empty seq"),
    "kalman nan": (
        lambda: current_estimator_gain(np.full((2, 2), np.nan), np.eye(1, 2), np.eye(2), np.eye(2), np.eye(1)),
        r"A must be finite",
    ),
    "kalman Re text": (
        lambda: current_estimator_gain(0.5 * np.eye(2), np.eye(1, 2), np.eye(2), np.eye(2), "1"),
        r"Re must be real numbers \(float64\), got '1'",
    ),
    "augment not square": (
        lambda: augment_with_integrators(np.ones((2, 3)), np.ones((2, 1)), np.ones((1, 2))),
        "square",
    ),
    # the controller
    "limits text": (
        lambda: LQGController(design_lqg(_model(), R=75.0), ("-1", "1")),
        r"input_limits lower must be real numbers \(float64\), got '-1'",
    ),
    "limits bool": (lambda: LQGController(design_lqg(_model(), R=75.0), (False, True)), r"booleans are not numbers"),
    "limits shape": (
        lambda: LQGController(design_lqg(_model(), R=75.0), ([-1.0, -1.0], [1.0, 1.0])),
        r"input_limits lower must be a scalar or have shape \(1,\), got shape \(2,\)",
    ),
    "limits not a pair": (
        lambda: LQGController(design_lqg(_model(), R=75.0), 10.0),
        r"must be a pair \(lower, upper\)",
    ),
    "update bool": (lambda: LQGController(design_lqg(_model(), R=75.0)).update(True, 0.0), r"reference .* booleans"),
    "n_inputs text": (lambda: DiagonalController([], (), (), "1"), r"n_inputs must be an integer >= 1, got '1'"),
    # realisations
    "observer nan": (
        lambda: observer_canonical(control.tf([1.0, np.nan], [1.0, -0.5, 0.2], 0.1)),
        r"system numerator must be finite; found nan at index \(1,\)",
    ),
    "observer inf": (
        lambda: observer_canonical(control.tf([1.0, 1.0], [1.0, np.inf, 0.2], 0.1)),
        r"system denominator must be finite; found inf",
    ),
    "residualise nan": (
        lambda: residualise(control.ss([[np.nan, 0.0], [0.0, -1.0]], [[1.0], [1.0]], [[1.0, 1.0]], 0), [0]),
        r"system.A must be finite",
    ),
    "residualise keep text": (
        lambda: residualise(control.ss(-np.eye(2), np.ones((2, 1)), np.ones((1, 2)), 0), "0"),
        r"keep must be a non-empty sequence of integers, distinct state indices in \[0, 1\], got '0'",
    ),
    "residualise keep bool": (
        lambda: residualise(control.ss(-np.eye(2), np.ones((2, 1)), np.ones((1, 2)), 0), [True]),
        r"keep must be a non-empty sequence .* got \[True\]",
    ),
    # command filters
    "cutoff text": (
        lambda: butterworth_lowpass(2, "0.2", 0.2),
        r"cutoff must be a number in \(0 Hz, 2.5 Hz\), got '0.2'",
    ),
    "cutoff bool": (
        lambda: butterworth_lowpass(2, True, 0.2),
        r"cutoff must be a number in \(0 Hz, 2.5 Hz\), got True",
    ),
    "band text": (lambda: butterworth_bandstop(2, ("0.2", "0.4"), 0.2), r"band low edge must be a number"),
    "bands None": (lambda: multiband_bandstop(2, None, 0.2), r"bands must be a sequence of \(low, high\) pairs"),
    "kind list": (
        lambda: multiband_bandstop(2, [(0.2, 0.4)], 0.2, kind=["butterworth"]),
        r"unknown band-stop kind \['butterworth'\]; allowed: 'butterworth', 'elliptic'",
    ),
    "centres None": (lambda: bands_around(None, 0.2), r"centres must be a sequence of frequencies"),
    "command text": (lambda: butterworth_lowpass(*LPF).apply(["1", "2"]), r"command must be real numbers .* text"),
    "command bool": (lambda: butterworth_lowpass(*LPF).apply(np.array([True, False])), r"command .* booleans"),
    "initial text": (lambda: butterworth_lowpass(*LPF).apply(np.ones(5), initial="1"), r"initial must be real numbers"),
    "initial shape": (
        lambda: butterworth_lowpass(*LPF).apply(np.ones((5, 2)), initial=[1.0, 2.0, 3.0]),
        r"initial must be a scalar or hold one value per command column, shape \(2,\); got shape \(3,\)",
    ),
    "frequencies text": (lambda: butterworth_lowpass(*LPF).gain_db("0.1"), r"frequencies must be real numbers"),
    "cascade non-filter": (lambda: butterworth_lowpass(*LPF).then("x"), r"other must be a CommandFilter, got str"),
    "shaped command text": (lambda: zv_shaper(0.3, 0.1).at(0.2).apply(["1", "2"]), r"command must be real numbers"),
    "shaper too long": (
        lambda: zvd_shaper(1e-3, 0.0).at(0.001),
        r"lasts 1000 s, 1e\+06 taps of sample_time = 0.001 s; allowed: at most 100000 taps",
    ),
    "shaper frequency tiny": (
        lambda: zv_shaper(1e-320, 0.1),
        r"frequency = 1e-320 Hz is too low.*allowed: frequency >",
    ),
    # metrics and plots
    "step initial text": (
        lambda: step_metrics([0, 1, 2], [0, 1, 1], [0, 0, 0], "0", 1.0),
        r"initial must be a real number in \[-inf rad, inf rad\], got '0'",
    ),
    "step target nan": (lambda: step_metrics([0, 1, 2], [0, 1, 1], [0, 0, 0], 0.0, np.nan), r"target = nan rad"),
    "step saturated shape": (
        lambda: step_metrics([0, 1, 2], [0, 1, 1], [0, 0, 0], 0.0, 1.0, saturated=[True]),
        r"saturated must be flags \(booleans or 0/1\) of shape \(3,\) or \(3, m\)",
    ),
    "step saturated text": (
        lambda: step_metrics([0, 1, 2], [0, 1, 1], [0, 0, 0], 0.0, 1.0, saturated=["no", "no", "no"]),
        r"saturated must be flags",
    ),
    "edges rest text": (lambda: step_edges([0.0, 1.0], rest="0"), r"rest must be a real number"),
    "plot output out of range": (lambda: plot_closed_loop(_record(), output=3), r"output must be an integer index"),
    "plot limits text": (lambda: plot_closed_loop(_record(), limits=("-1", "1")), r"limits lower must be real numbers"),
}


@pytest.mark.parametrize("case", BAD_INPUTS, ids=list(BAD_INPUTS))
def test_bad_input_is_one_clear_input_error(case):
    call, match = BAD_INPUTS[case]
    with pytest.raises(InputError, match=match) as info:
        call()
    assert "\n" not in str(info.value)


@pytest.mark.parametrize("value", [75, 75.0, np.float64(75.0), [[75.0]], np.array([75.0])])
def test_numeric_weights_in_every_form_are_still_accepted(value):
    assert design_lqg(_model(), R=value).R.tolist() == [[75.0]]


def test_a_nan_sample_time_is_a_configuration_error():
    m = _model()
    with pytest.raises(ConfigurationError, match=r"finite numeric dt > 0 \(s\), got dt = nan"):
        design_lqg(control.ss(m.A, m.B, m.C, 0, float("nan")))
    with pytest.raises(InputError, match=r"finite numeric dt > 0 \(s\), got dt = nan"):
        observer_canonical(control.tf([1.0], [1.0, -0.5], float("nan")))


@pytest.mark.parametrize(
    "weights, match",
    [
        ({"Q": 1e308}, r"Q has an entry of magnitude 1e\+308; allowed: 0 or 1e-12 \.\. 1e\+12"),
        ({"R": 1e13}, r"R has an entry of magnitude 1e\+13"),
        ({"R": 1e-300}, r"R has an entry of magnitude 1e-300"),
        ({"Qe": 1e20}, r"Qe has an entry of magnitude 1e\+20"),
        ({"Re": 1e-13}, r"Re has an entry of magnitude 1e-13"),
    ],
)
def test_weights_beyond_the_solvers_precision_are_refused_naming_the_weight(weights, match):
    with pytest.raises(DesignError, match=match) as info:
        design_lqg(_model(), **weights)
    assert "\n" not in str(info.value)


@pytest.mark.parametrize("q, r", [(1.0, 1e12), (1e12, 1.0), (1e-6, 1.0)])
def test_weights_far_from_one_within_the_range_still_design(q, r):
    assert np.abs(design_lqg(_model(), Q=q, R=r).regulator_poles).max() < 1.0
