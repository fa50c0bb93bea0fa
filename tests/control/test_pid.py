"""Discrete PID: its transfer functions, back-calculation anti-windup, tuning, loops on both worlds, refusals."""

import control
import numpy as np
import pytest

from trms.control.loop import closed_loop, deviation_limits
from trms.control.metrics import square_wave_metrics
from trms.control.pid import PIDController, PIDGains
from trms.control.pid_tuning import channel_model, decentralised_pid, tune_pid
from trms.errors import DesignError, InputError
from trms.worlds import design_model, make_plant

TS = 0.2


@pytest.fixture(scope="module")
def gains():
    return tune_pid(design_model("1dof", TS))


def _tf_pid(kp, ki, kd, N, weight_p, weight_d, ts):
    """The same discrete PID built from python-control transfer functions (forward Euler integral,
    backward-difference filtered derivative)."""
    tf_ = kd / (kp * N)
    return (
        control.tf([weight_p * kp], [1.0], ts)
        + control.tf([ki * ts], [1.0, -1.0], ts)
        + control.tf([weight_d * kd, -weight_d * kd], [tf_ + ts, -tf_], ts)
    )


def test_transfer_functions_equal_the_python_control_construction():
    g = PIDGains(kp=1.3, ki=0.7, kd=0.4, N=8.0, b=0.6, c=0.3)
    pid = PIDController(g, TS)
    comp = pid.compensator()
    c_r, c_y = _tf_pid(1.3, 0.7, 0.4, 8.0, 0.6, 0.3, TS), _tf_pid(1.3, 0.7, 0.4, 8.0, 1.0, 1.0, TS)
    w = np.logspace(-3, np.log10(np.pi / TS) - 1e-6, 200)
    for mine, ref, sign in ((comp[0, 0], c_r, 1.0), (comp[0, 1], c_y, -1.0)):
        a = sign * mine(np.exp(1j * w * TS))
        b = ref(np.exp(1j * w * TS))
        assert np.max(np.abs(a - b) / np.abs(b)) < 1e-10
    # the sample-by-sample law (no limits) equals the transfer functions driven by the same signals
    rng = np.random.default_rng(3)
    r, y = rng.standard_normal(60), rng.standard_normal(60)
    u = np.array([pid.update(ri, yi)[0] for ri, yi in zip(r, y)])
    t = np.arange(60) * TS
    want = control.forced_response(c_r, t, r).outputs - control.forced_response(c_y, t, y).outputs
    assert np.max(np.abs(u - want)) < 1e-10


def _windup_run(gains, tracking_time):
    """0.6 rad asked for 20 s with +-0.2 V (only about 0.3 rad reachable), then 0.1 rad: the integrator winds up."""
    plant = make_plant("linear", "1dof", TS, noise_std=0.0)
    pid = PIDController(gains, TS, input_limits=(-0.2, 0.2), tracking_time=tracking_time)
    integral = []
    update = pid.update

    def logged(r, y):
        u = update(r, y)
        integral.append(pid.integral)
        return u

    pid.update = logged  # type: ignore[method-assign]
    rec = closed_loop(plant, pid, np.r_[np.full(100, 0.6), np.full(200, 0.1)], seed=0)
    return rec, np.array(integral)


def test_back_calculation_bounds_the_integrator_and_cuts_the_overshoot(gains):
    with_aw, i_aw = _windup_run(gains, None)
    without, i_free = _windup_run(gains, np.inf)
    assert np.sum(np.abs(with_aw.extras["control"]) >= 0.2 - 1e-12) > 20  # the limits are active
    second_aw, second_free = square_wave_metrics(with_aw)[1], square_wave_metrics(without)[1]
    assert second_aw.overshoot < second_free.overshoot - 0.5
    assert second_aw.settling_time < 0.5 * second_free.settling_time
    # with back-calculation the integrator stays near the actuator's range; without, it winds up tenfold
    assert np.max(np.abs(i_aw)) < 0.25 and np.max(np.abs(i_free)) > 1.0


def test_tuned_pid_meets_its_sensitivity_bound_and_is_stable(gains):
    model = design_model("1dof", TS)
    c_y = -PIDController(gains, TS).compensator()[0, 1]
    loop = control.series(model, c_y)
    assert np.all(np.abs(control.feedback(loop, 1).poles()) < 1.0)
    w = np.linspace(1e-4, np.pi / TS, 4000)
    peak = np.max(np.abs(1.0 / (1.0 + loop(np.exp(1j * w * TS)))))
    assert peak < 1.7 * 1.01


@pytest.mark.parametrize("world", ["linear", "twin"])
def test_the_tuned_pid_tracks_the_pitch_in_both_worlds(gains, world):
    plant = make_plant(world, "1dof", TS)
    ref = np.r_[np.full(150, 0.2), np.full(150, -0.2)]
    rec = closed_loop(plant, PIDController(gains, TS, deviation_limits(plant)), ref, seed=1)
    pitch = plant.operating_point.output_deviation(rec.outputs)[:, 0]
    assert abs(np.mean(pitch[120:150]) - 0.2) < 0.03 and abs(np.mean(pitch[270:]) + 0.2) < 0.03


@pytest.mark.parametrize(
    ("kwargs", "text"),
    [({"kp": 0.0, "ki": 1.0, "kd": 0.0}, "kp = 0.0"), ({"kp": 1.0, "ki": -1.0, "kd": 0.0}, "ki = -1.0")],
)
def test_bad_gains_are_refused_in_one_line(kwargs, text):
    with pytest.raises(InputError, match=text) as err:
        PIDGains(**kwargs)
    assert "\n" not in str(err.value)


@pytest.mark.parametrize("reference, measurement, text", [("a", 0.0, "reference"), (0.0, [1.0, 2.0], "measurement")])
def test_a_sample_that_is_not_one_number_is_refused_in_one_line(reference, measurement, text):
    pid = PIDController(PIDGains(1.0, 1.0, 0.0), TS)
    with pytest.raises(InputError, match=rf"{text} \(deviation rad\) must be") as err:
        pid.update(reference, measurement)
    assert "\n" not in str(err.value) and pid.integral == 0.0  # nothing changed


def test_bad_limits_are_refused():
    with pytest.raises(InputError, match="lower <= 0 <= upper"):
        PIDController(PIDGains(1.0, 1.0, 0.0), TS, input_limits=(1.0, 2.0))


# ---------------------------------------------------------------------------------------------- several outputs
_TWO = (PIDGains(kp=0.8, ki=0.3, kd=0.2), PIDGains(kp=0.5, ki=0.1, kd=0.4, b=0.7, c=0.5))


@pytest.mark.parametrize("limits", [None, ((-0.4, -0.3), (0.5, 0.2))])
def test_the_decentralised_pid_is_two_siso_pids_fed_the_same_signals(mimo_model, limits):
    """Known truth: loop k reads reference k and output k and drives input k alone, each with its own limits and
    back-calculation; with the limits active (the second case) the anti-windup acts and it still holds."""
    pid = decentralised_pid(mimo_model, limits, gains=_TWO)
    siso = [PIDController(g, 0.1, None if limits is None else (limits[0][i], limits[1][i])) for i, g in enumerate(_TWO)]
    rng = np.random.default_rng(3)
    r, y = rng.standard_normal((60, 2)), rng.standard_normal((60, 2))
    got = np.array([pid.update(r[k], y[k]) for k in range(60)])
    want = np.array([[float(siso[i].update(r[k, i], y[k, i])[0]) for i in (0, 1)] for k in range(60)])
    assert np.max(np.abs(got - want)) <= 1e-12
    if limits is not None:  # the limits were active, and the integrators were driven back by them
        assert np.any(got == limits[1][0]) and np.any(got == limits[0][1])
        assert pid.loops[0].integral != PIDController(_TWO[0], 0.1).integral


def test_each_loop_is_tuned_on_its_own_channel(mimo_model):
    pid = decentralised_pid(mimo_model, horizon=1.0, Ms=2.0)
    for i in (0, 1):
        channel = channel_model(mimo_model, i, i)
        assert np.array_equal(channel.B[:, 0], mimo_model.B[:, i]) and np.array_equal(channel.C[0], mimo_model.C[i])
        assert pid.loops[i].gains == tune_pid(channel, horizon=1.0, Ms=2.0)
    assert pid.outputs == pid.inputs == (0, 1) and pid.n_inputs == 2


@pytest.mark.parametrize(
    ("kwargs", "text"),
    [
        ({"pairs": [(0, 0), (1, 0)]}, "distinct input indices"),
        ({"pairs": [(0, 0), (2, 1)]}, "output indices"),
        ({"gains": _TWO[:1]}, "one PIDGains per pair"),
        ({"input_limits": (-1.0, [1.0, 2.0, 3.0])}, r"shape \(2,\)"),
    ],
)
def test_bad_decentralised_settings_are_refused_in_one_line(mimo_model, kwargs, text):
    kwargs.setdefault("gains", _TWO)
    with pytest.raises(InputError, match=text) as err:
        decentralised_pid(mimo_model, **kwargs)
    assert "\n" not in str(err.value)


def test_a_filtered_pid_damps_the_pitch_mode_that_a_plain_one_cannot():
    """On eq. (3.11) the plain PID leaves the 0.34 Hz mode near the plant's damping; the measurement filter's lag lets
    the damping constraint hold."""
    from trms.control.damping import mode_damping

    model = design_model("1dof", 0.2)
    plain = tune_pid(model)
    filtered = tune_pid(model, min_damping=0.1)
    k = lambda g: -PIDController(g, 0.2).compensator()[0, 1]  # noqa: E731
    assert plain.tm == 0.0 and mode_damping(model, k(plain)).closed.damping < 0.08
    assert filtered.tm > 0.0 and mode_damping(model, k(filtered)).closed.damping >= 0.1
    with pytest.raises(DesignError, match="no PID with a measurement filter .* damping ratio of 0.6"):
        tune_pid(model, min_damping=0.6)


def test_the_measurement_filter_is_the_second_order_filter_it_says():
    """tm > 0: the controller is the PID of a filtered measurement, F(s) = 1 / (1 + s tm + (s tm)^2 / 2), bilinear."""
    g = PIDGains(kp=0.8, ki=0.2, kd=0.3, tm=1.2)
    pid = PIDController(g, TS).compensator()
    plain = PIDController(PIDGains(kp=0.8, ki=0.2, kd=0.3), TS).compensator()
    tm = 1.2
    F = control.c2d(control.tf([1.0], [tm * tm / 2, tm, 1.0]), TS, method="bilinear")
    z = np.exp(1j * np.linspace(0.01, 3.0, 40) * TS)
    np.testing.assert_allclose(pid[0, 1](z), plain[0, 1](z) * F(z), rtol=1e-9)
    np.testing.assert_allclose(pid[0, 0](z), plain[0, 0](z), rtol=1e-9)  # the reference is not filtered


@pytest.mark.parametrize(
    "kwargs, text",
    [
        ({"min_damping": 0.9}, "min_damping = 0.9 is outside"),
        ({"min_damping": 0.1, "damping_band": (0.5, 0.2)}, "damping_band must be"),
    ],
)
def test_bad_damping_requests_are_refused_in_one_line(kwargs, text):
    with pytest.raises(InputError, match=text):
        tune_pid(design_model("1dof", 0.2), **kwargs)


def test_a_negative_filter_time_is_refused():
    with pytest.raises(InputError, match="tm = -1.0 s is outside"):
        PIDGains(kp=1.0, ki=0.0, kd=0.0, tm=-1.0)
