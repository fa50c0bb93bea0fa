"""The twin's static pitch curve beside the published model's: equilibria that long runs reach, gains that are the
curves' slopes, stops where the beam sits on them."""

import numpy as np
import pytest

from trms.calibration.static_pitch import StaticPitch, plot_static_pitch, static_pitch_curves
from trms.twin import Twin, load_spec
from trms.twin.published import static_pitch


@pytest.fixture(scope="module")
def shipped():
    return static_pitch_curves(load_spec())


def test_the_twins_static_pitch_is_where_a_long_still_air_run_settles():
    offsets = [-1.0, -0.3, 0.0, 0.2, 0.3, 0.35]
    curves = static_pitch_curves(load_spec(), offsets)
    twin = Twin("1dof", 1.0, still_air=True, counts_per_rev=0)
    assert curves.twin.trim == pytest.approx(twin.operating_point.inputs[0], abs=1e-9)
    for dv, pitch, on_stop in zip(offsets, curves.twin.pitch, curves.twin.on_stop):
        rec = twin.run(np.full((150, 1), twin.operating_point.inputs[0] + dv))  # 150 s: the mode long decayed
        assert rec.extras["true_angles"][-1, 0] == pytest.approx(pitch, abs=1e-5), dv
        assert bool(rec.extras["at_stop"][-1, 0]) == on_stop, dv
    assert curves.twin.on_stop.tolist() == [False] * 5 + [True]  # +0.35 V drives the twin onto its stop


def test_each_local_gain_is_the_slope_of_its_curve():
    at, h = np.array([-0.8, -0.3, 0.1, 0.25]), 1e-3
    offsets = np.sort(np.r_[at - h, at, at + h, 0.0])
    curves = static_pitch_curves(load_spec(), offsets)
    for curve in curves.curves:
        pitch = dict(zip(offsets.round(9), curve.pitch))
        gain = dict(zip(offsets.round(9), curve.gain))
        for x in at:
            slope = (pitch[round(x + h, 9)] - pitch[round(x - h, 9)]) / (2 * h)
            assert gain[round(x, 9)] == pytest.approx(slope, rel=2e-3), (curve.label, x)


def test_both_scalings_meet_the_twins_gain_at_trim_and_part_in_the_large_signal(shipped):
    trim = int(np.flatnonzero(shipped.offsets == 0.0)[0])
    for curve in (shipped.input_scaled, shipped.output_scaled):
        assert curve.gain[trim] == pytest.approx(shipped.twin.gain[trim], rel=1e-9)
    free = ~shipped.input_scaled.on_stop
    np.testing.assert_allclose(
        shipped.input_scaled.pitch[free], static_pitch(shipped.scale * shipped.offsets[free]), rtol=1e-12
    )
    free = ~shipped.output_scaled.on_stop
    np.testing.assert_allclose(
        shipped.output_scaled.pitch[free], shipped.scale * static_pitch(shipped.offsets[free]), rtol=1e-12
    )
    # the twin's gain grows with the voltage: steeper above trim than below
    assert shipped.twin.gain[trim + 2] > 1.1 * shipped.twin.gain[trim] > 1.2 * shipped.twin.gain[trim - 2]


def test_the_reach_is_where_the_beam_leaves_for_the_stop():
    spec = load_spec()
    reach = static_pitch_curves(spec, [0.0, 0.5]).curves
    for k, curve in enumerate(reach):
        below, above = static_pitch_curves(spec, [0.0, curve.reach - 1e-3, curve.reach + 1e-3]).curves[k].on_stop[1:]
        assert (below, above) == (False, True), curve.label
        assert 0.0 < curve.reach < 1.0, curve.label


def test_the_curves_round_trip_and_draw(shipped):
    again = StaticPitch.from_dict(shipped.to_dict())
    assert again.to_dict() == shipped.to_dict()
    table = shipped.table()
    assert [row[0] for row in table.rows] == [f"{v:+.2f}" for v in np.round(np.arange(-1.0, 1.01, 0.1), 2) + 0.0]
    assert table.missing() == []
    for curve in shipped.curves:
        assert np.all(curve.gain[curve.on_stop] == 0.0) and np.all(curve.gain[~curve.on_stop] > 0.0)
    fig = plot_static_pitch(shipped)
    assert len(fig.axes) == 2 and len(fig.axes[0].lines) >= 6


@pytest.mark.parametrize("offsets", [[0.1, 0.2], [0.0, -0.1], [[0.0]]])
def test_offsets_that_do_not_increase_through_zero_are_refused(offsets):
    with pytest.raises(ValueError, match="offsets must increase and hold 0 V"):
        static_pitch_curves(load_spec(), offsets)


def test_the_hover_voltage_is_where_the_pendulum_puts_it(shipped):
    """The note's explanation holds on the twin: n tan(-rest) / g is its trim within 1 %."""
    trim = int(np.flatnonzero(shipped.offsets == 0.0)[0])
    predicted = shipped.log_slope * np.tan(-shipped.rest_pitch) / shipped.twin.gain[trim]
    assert predicted == pytest.approx(shipped.twin.trim, rel=0.01)
    assert 1.0 < shipped.log_slope < 2.0 and f"{predicted:.3f} V" in shipped.hover_note()[0]


def test_the_report_reads_the_same_bits_as_a_fresh_measurement(shipped):
    from trms.calibration.evidence import measured_static_pitch

    assert measured_static_pitch(load_spec()).to_dict() == shipped.to_dict()
