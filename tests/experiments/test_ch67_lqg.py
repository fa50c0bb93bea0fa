"""Chapters 6/7 run on a plant: cases, measures, judge, push, loop margins (known truth on eq. 3.11)."""

import numpy as np
import pytest

from trms.errors import InputError
from trms.experiments import ch67_lqg as lc


def test_times_do_not_depend_on_amplitude_while_nothing_saturates():
    plant = lc.pitch_plant()
    rec_a, m_a = lc.run_case(plant, 75.0, "SAS", amplitude=0.1)
    rec_b, m_b = lc.run_case(plant, 75.0, "SAS", amplitude=0.2)
    assert [m.rise_time for m in m_a] == pytest.approx([m.rise_time for m in m_b], abs=1e-9)
    assert [m.settling_time for m in m_a] == pytest.approx([m.settling_time for m in m_b], abs=1e-9)
    assert rec_b.extras["control"] == pytest.approx(2 * rec_a.extras["control"], abs=1e-12)


def test_summary_measures_its_alternatives_on_the_same_run():
    plant = lc.pitch_plant()
    rec, steps = lc.run_case(plant, 75.0, "CSAS LPF 0.2 Hz")
    s = lc.summarise(rec, lc.deviation_limits(plant))
    # noise-free: no wander, the narrow band is used; the rise from the command edge includes the prefilter's lag
    assert s["wander"] < 1e-3 and s["band"] == lc.NARROW_BAND and s["TS"] == s["TS narrow"]
    assert s["TR edge"] > s["TR"]
    assert s["TS wide"] <= s["TS narrow"]
    assert s["step"] == pytest.approx(2 * lc.DEFAULT_AMPLITUDE)


def test_the_band_follows_the_measured_wander():
    assert lc.settling_band(0.001, 0.4) == lc.NARROW_BAND
    assert lc.settling_band(0.02, 0.4) == lc.WIDE_BAND


def test_margins_on_eq_3_11_explain_the_rigs_r1_failure():
    # eq. (3.11) is the design model here, so these are known-truth checks of the margins code
    p = lc.pitch_plant().system
    m1, m75 = lc.loop_margins(p, p, 1.0), lc.loop_margins(p, p, 75.0)
    assert m1.stable and not m1.stable_with_delay
    assert m1.delay_margin_s < 0.2 < m75.delay_margin_s  # one sample of 0.2 s breaks R = 1 only
    assert m75.stable_with_delay and m75.phase_margin_deg > m1.phase_margin_deg + 30


def test_delay_margin_agrees_with_a_delayed_loop():
    # a loop with delay margin d stays stable with a pure delay just below d (in samples) and not just above
    import control

    p = lc.pitch_plant().system
    m = lc.loop_margins(p, p, 1.0)
    assert 0.0 < m.delay_margin_s < 0.2
    plant_delayed = control.series(control.ss([[0.0]], [[1.0]], [[1.0]], [[0.0]], 0.2), p)
    assert not lc.loop_margins(plant_delayed, p, 1.0).stable


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda: lc.run_case(lc.pitch_plant(), 75.0, "SAS+"), "unknown case 'SAS\\+'"),
        (lambda: lc.pitch_plant(trim=10.0), r"trim = 10.0 V must lie strictly inside the limits"),
        (lambda: lc.pitch_plant(limit=0.0), "limit = 0.0 V is outside"),
    ],
)
def test_bad_settings_are_refused(call, match):
    with pytest.raises(InputError, match=match):
        call()


def test_design_model_is_required_for_a_twin():
    from trms.worlds import make_plant

    with pytest.raises(InputError, match="a design model is needed"):
        lc.run_case(make_plant("twin", "1dof"), 75.0, "SAS")


def test_every_case_runs_on_both_worlds(ch67_results):
    lin, twin, _, weights, _ = ch67_results
    keys = {(r, c) for r in weights for c in lc.ALL_CASES}
    assert set(lin) == keys and set(twin) == keys
    assert all(res.status in lc.STATUSES for res in (*lin.values(), *twin.values()))
    assert all(lin[(75.0, c)].status == "settled" for c in lc.ALL_CASES)


def test_the_twin_runs_carry_gusts_and_its_channels(ch67_results):
    twin = ch67_results[1]
    rec = twin[(75.0, "SAS")].record
    assert np.std(rec.extras["disturbance"][:, 0]) > 0 and "true_angles" in rec.extras


def test_judge_flags_a_run_at_the_stops(ch67_results):
    lin = ch67_results[0]
    rec = lin[(75.0, "SAS")].record
    steps = lc.square_wave_metrics(rec, band=lc.WIDE_BAND)
    assert lc.judge(rec, steps) == "settled"
    extras = dict(rec.extras)
    extras["true_angles"] = np.full((len(rec), 2), lc.STOP_ANGLE)
    at_stop = lc.Record(rec.time, rec.inputs, rec.outputs, rec.input_names, rec.output_names, extras, rec.metadata)
    assert lc.judge(at_stop, steps) == "hit the stops"


def test_push_disturbs_the_twin_and_is_measured(ch67_results):
    push = ch67_results[2]
    res = push[75.0]
    y = res.record.deviations()[1][:, 0]
    before = np.abs(y[res.record.time < lc.PUSH[0]]).max()
    assert res.peak > 2 * before  # the push, not the gusts, sets the peak
    assert res.status in {"recovered", "not recovered"}
