"""Step metrics on responses with known closed-form answers; spectral attenuation through attenuation_db."""

import numpy as np
import pytest

import trms.control.metrics as metrics
from trms.control.metrics import mode_attenuation, square_wave_metrics, step_edges, step_metrics, total_variation
from trms.errors import InputError
from trms.record import Record

# Responses sampled at 1 ms: linear interpolation of a crossing errs by < (dt^2 / 8) max|y''| / |y'|,
# below 1e-4 s here; 1e-3 s is the stated tolerance.
T_TOL = 1e-3


def test_first_order_step_has_textbook_rise_and_settling_times():
    tau = 1.2
    t = np.arange(0, 20, 1e-3)
    y = 0.5 + 2.0 * (1 - np.exp(-t / tau))  # from 0.5 to 2.5
    m = step_metrics(t, y, np.ones_like(t), initial=0.5, target=2.5)
    assert m.rise_time == pytest.approx(tau * np.log(9), abs=T_TOL)
    assert m.settling_time == pytest.approx(tau * np.log(50), abs=T_TOL)
    assert m.overshoot == 0.0


@pytest.mark.parametrize("zeta", [0.1, 0.3, 0.6])
def test_second_order_overshoot_and_downward_steps(zeta):
    wn = 2.0
    wd = wn * np.sqrt(1 - zeta**2)
    t = np.arange(0, 40, 1e-3)
    s = 1 - np.exp(-zeta * wn * t) * (np.cos(wd * t) + zeta / np.sqrt(1 - zeta**2) * np.sin(wd * t))
    expected = 100 * np.exp(-zeta * np.pi / np.sqrt(1 - zeta**2))
    up = step_metrics(t, s, np.zeros_like(t), 0.0, 1.0)
    down = step_metrics(t, 1 - 2 * s, np.zeros_like(t), 1.0, -1.0)  # same shape, downward, twice the size
    assert up.overshoot == pytest.approx(expected, rel=1e-4)
    assert down.overshoot == pytest.approx(expected, rel=1e-4)
    assert down.rise_time == pytest.approx(up.rise_time, abs=T_TOL)
    assert down.settling_time == pytest.approx(up.settling_time, abs=T_TOL)
    # the envelope bounds the 2 % settling time
    assert up.settling_time <= np.log(50 / np.sqrt(1 - zeta**2)) / (zeta * wn) + T_TOL


def test_unsettled_and_unreached_give_nan_and_control_measures():
    t = np.arange(10) * 0.2
    y = np.linspace(0, 0.5, 10)  # never reaches 90 %, never settles
    u = np.array([0, 1, -1, 1, 0, 0, 0, 0, 0, 2.0])
    m = step_metrics(t, y, u, 0.0, 1.0, saturated=u > 1.5)
    assert np.isnan(m.rise_time) and np.isnan(m.settling_time)
    assert m.peak_control == 2.0
    assert m.rms_control == pytest.approx(np.sqrt(7 / 10))
    assert m.saturated_time == pytest.approx(0.2)
    assert m.total_variation == pytest.approx(1 + 2 + 2 + 1 + 2)
    assert total_variation(np.column_stack([u, u])) == pytest.approx(16.0)


def test_step_edges_and_square_wave_metrics_on_a_record():
    ref = np.r_[np.full(50, 1.0), np.full(50, -1.0)]
    assert step_edges(ref).tolist() == [0, 50]
    assert step_edges(ref, rest=1.0).tolist() == [50]
    t = np.arange(100) * 0.2
    y = np.r_[1 - np.exp(-t[:50] / 0.5), 1 - 2 * (1 - np.exp(-t[:50] / 0.5))]
    rec = Record(
        t,
        np.zeros(100),
        y + 0.1,
        ("u1",),
        ("y1",),
        {"reference": ref[:, None], "control": np.zeros((100, 1)), "saturated": np.zeros((100, 1), bool)},
        {
            "sample_time": 0.2,
            "operating_point": {"inputs": [0.0], "outputs": [0.1], "input_names": ["u1"], "output_names": ["y1"]},
        },
    )
    first, second = square_wave_metrics(rec)
    assert (first.initial, first.target, first.start_time) == (0.0, 1.0, 0.0)
    assert (second.initial, second.target, second.start_time) == (1.0, -1.0, 10.0)
    # sampled at 0.2 s the interpolated rise time of an exponential is within 0.01 s of 0.5 ln 9
    assert first.rise_time == pytest.approx(0.5 * np.log(9), abs=0.01)
    assert second.rise_time == pytest.approx(first.rise_time, abs=1e-9)
    assert square_wave_metrics(rec, output="y1") == [first, second]


def test_mode_attenuation_is_the_power_ratio_and_uses_attenuation_db(monkeypatch):
    rng = np.random.default_rng(2)
    y = rng.standard_normal(600)
    calls = []
    real = metrics.attenuation_db

    def spy(*args, **kwargs):
        calls.append(args)
        return real(*args, **kwargs)

    monkeypatch.setattr(metrics, "attenuation_db", spy)
    att = mode_attenuation(y, y / 10.0, 0.2, [0.25, 0.34], nperseg=128)
    assert att == pytest.approx([20.0, 20.0], abs=1e-9)  # a tenth of the amplitude: 20 dB at every frequency
    assert len(calls) == 1


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda: step_metrics(np.arange(5.0), np.zeros(5), np.zeros(5), 1.0, 1.0), "initial and target must differ"),
        (lambda: step_metrics(np.arange(5.0), np.zeros(4), np.zeros(5), 0.0, 1.0), r"output must have shape \(5,\)"),
        (lambda: step_metrics(np.arange(5.0), np.zeros(5), np.zeros(3), 0.0, 1.0), "control must have 5 rows"),
        (lambda: step_metrics(np.arange(5.0), np.zeros(5), np.zeros(5), 0.0, 1.0, band=0.0), "band = 0.0 is outside"),
        (lambda: step_metrics(np.arange(1.0), np.zeros(1), np.zeros(1), 0.0, 1.0), "at least 2 samples"),
        (
            lambda: square_wave_metrics(Record(np.arange(3.0), np.zeros(3), np.zeros(3), ("u",), ("y",))),
            "no 'reference'/'control' extras",
        ),
    ],
)
def test_bad_metric_input_is_refused(call, match):
    with pytest.raises(InputError, match=match):
        call()


def test_the_noise_band_is_the_larger_of_two_percent_and_three_standard_deviations():
    from trms.control.metrics import noise_band

    assert noise_band(0.4, 0.0) == 0.02 and noise_band(-0.4, 0.001) == 0.02
    assert noise_band(0.2, 0.004) == pytest.approx(0.06) and noise_band(0.2, 0.004, sigmas=1.0) == 0.02
    with pytest.raises(InputError, match="step = 0.0 rad is outside"):
        noise_band(0.0, 0.001)
    with pytest.raises(InputError, match="rest_std = -1.0 rad is outside"):
        noise_band(0.4, -1.0)


def test_each_step_is_judged_in_the_band_of_its_own_targets_rest_and_the_jump_is_measured():
    """A +-1 square wave wobbling 0.06 around +1 and still at -1: the 2 % band cannot hold the upper steps (the wobble
    is outside it at their last sample), a band of 3 standard deviations at rest there can; the jump at each step is
    the command's change from the sample before."""
    t = np.arange(0.0, 40.0, 0.1)
    ref = np.where((t // 10) % 2 == 0, 1.0, -1.0)
    wobble = np.where(ref > 0, 0.06 * np.cos(2 * np.pi * t), 0.0)
    u = ref.copy()
    rec = Record(
        t,
        np.zeros((t.size, 1)),
        (ref + wobble)[:, None],
        ("u1",),
        ("pitch",),
        {"reference": ref[:, None], "control": u[:, None]},
    )
    narrow = square_wave_metrics(rec)
    noisy = square_wave_metrics(rec, rest_std={1.0: 0.06, -1.0: 0.0})
    assert [np.isnan(m.settling_time) for m in narrow] == [True, False, True, False]
    assert [np.isnan(m.settling_time) for m in noisy] == [False, False, False, False]
    assert [m.largest_move for m in noisy] == [1.0, 2.0, 2.0, 2.0]


def test_a_loop_that_wobbles_at_rest_by_more_than_its_step_never_settles():
    t = np.arange(0.0, 10.0, 0.1)
    ref = np.full(t.size, 0.1)
    rec = Record(
        t,
        np.zeros((t.size, 1)),
        ref[:, None],
        ("u1",),
        ("pitch",),
        {"reference": ref[:, None], "control": np.zeros((t.size, 1))},
    )
    (calm,) = square_wave_metrics(rec, rest_std=0.01)
    (wild,) = square_wave_metrics(rec, rest_std=0.05)  # 3 sigma = 150 % of the step
    assert calm.settling_time == 0.0 and np.isnan(wild.settling_time)
