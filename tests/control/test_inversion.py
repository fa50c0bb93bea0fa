"""The thrust-curve inversion: the rotor's static thrust linear in the command at every amplitude, limits mapped."""

import numpy as np
import pytest

from trms.control.inversion import InvertedInputs, linearised_limits
from trms.errors import InputError
from trms.twin.rotors import ThrustCurve

CURVE = ThrustCurve(3.15029, 0.05625, 0.385, 0.03236, 0.2215, 11.0, 57.12)  # the shipped main rotor's
TRIM = 0.56664705


class Hold:
    """A controller that commands a set value."""

    sample_time = 0.2
    value = np.zeros(1)

    def reset(self) -> None:
        pass

    def update(self, reference, measurement):
        return self.value


class WithEstimate(Hold):
    estimate = np.array([1.0, 2.0])


@pytest.mark.parametrize("v", [-2.0, -0.4, -0.05, 0.0, 0.1, 0.7, 2.5])
def test_the_thrust_is_the_trims_plus_the_trim_slope_times_the_command(v):
    inv = InvertedInputs(Hold(), [CURVE], [TRIM], (-10.0, 10.0))
    u = float(inv.voltages([v])[0])
    expected = CURVE.thrust(TRIM) + float(CURVE.slope(TRIM)) * v
    assert float(CURVE.thrust(TRIM + u)) == pytest.approx(expected, rel=1e-12, abs=1e-12)


def test_without_inversion_the_static_gain_changes_with_the_amplitude_and_with_it_does_not():
    slope = float(CURVE.slope(TRIM))
    raw = [(float(CURVE.thrust(TRIM + v)) - float(CURVE.thrust(TRIM))) / (slope * v) for v in (-0.4, 0.4)]
    assert raw[1] / raw[0] > 1.25  # secant gains 0.88 and 1.12 of the slope: the curve bends about 30 % per volt
    inv = InvertedInputs(Hold(), [CURVE], [TRIM], (-10.0, 10.0))
    lin = [
        (float(CURVE.thrust(TRIM + inv.voltages([v])[0])) - float(CURVE.thrust(TRIM))) / (slope * v)
        for v in (-0.4, 0.4)
    ]
    assert lin == pytest.approx([1.0, 1.0], rel=1e-12)


def test_the_limits_are_the_rotors_reach_in_trim_slope_volts_and_map_back_to_the_voltage_limits():
    lo, hi = linearised_limits([CURVE, None], [TRIM, 0.5], (-10.0, 10.0))
    inv = InvertedInputs(Hold(), [CURVE, None], [TRIM, 0.5], (-10.0, 10.0))
    assert inv.limits()[0].tolist() == lo.tolist() and lo[1] == -10.5 and hi[1] == 9.5  # the pass-through input
    volts = inv.voltages([lo[0], 0.0])
    assert float(CURVE.thrust(TRIM + volts[0])) == pytest.approx(float(CURVE.thrust(-10.0)), rel=1e-12)
    full = CURVE.tau_max / CURVE.k  # beyond full speed the curve is flat: the upper limit is full thrust
    assert float(CURVE.thrust(TRIM + inv.voltages([hi[0], 0.0])[0])) == pytest.approx(CURVE.thrust(full), rel=1e-12)


def test_the_wrapped_controller_is_updated_and_its_estimate_seen_only_where_it_has_one():
    c = WithEstimate()
    c.value = np.array([0.3])
    inv = InvertedInputs(c, [CURVE], [TRIM], (-10.0, 10.0))
    assert inv.update(0.0, 0.0)[0] == inv.voltages([0.3])[0] and inv.sample_time == 0.2 and inv.n_references == 1
    assert inv.estimate.tolist() == [1.0, 2.0]
    assert not hasattr(InvertedInputs(Hold(), [CURVE], [TRIM], (-10.0, 10.0)), "estimate")


@pytest.mark.parametrize(
    "maps, trim, limits, match",
    [
        ([CURVE], [TRIM, 0.0], (-10.0, 10.0), "need one input map"),
        ([object()], [TRIM], (-10.0, 10.0), "input map 0 must have thrust, voltage and slope"),
        ([CURVE], [11.0], (-10.0, 10.0), "must lie strictly inside the input limits"),
        ([CURVE], [5.0], (-10.0, 10.0), "slope 0 N/V at its trim 5 V"),
    ],
)
def test_bad_setups_are_refused_in_one_line(maps, trim, limits, match):
    with pytest.raises(InputError, match=match):
        InvertedInputs(Hold(), maps, trim, limits)
