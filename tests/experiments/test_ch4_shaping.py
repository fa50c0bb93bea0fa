"""Chapter 4 on a plant: the doublets of Tables 4.2 and 4.3, the shapers, the ambient floor and its check."""

import numpy as np
import pytest

from trms.errors import InputError
from trms.experiments import ch4_shaping as st
from trms.reference import HOVER_PITCH_RMS, TABLE_4_2


@pytest.fixture(scope="module")
def floor():
    """The twin's doublets under the most ambient excitation its calibration allows (Table 4.2's only)."""
    from trms.reference import eq_3_11

    return st.ambient_floors(eq_3_11(), 0, two_dof=False)


def test_the_floor_is_the_most_ambient_excitation_the_calibrated_hover_rms_allows(floor):
    """The scale sets the hover pitch RMS, proportional to the turbulence with the noise and quantisation beside it,
    at the top of the calibrated range: measured there, it lies within it (the floor's own check) and close to the
    top (within 10 %); the calibrated level's own RMS lies in the range too."""
    lo, hi = HOVER_PITCH_RMS
    assert floor.scale == pytest.approx(hi / floor.hover_rms[1.0]) and floor.scale > 1.0
    assert lo <= floor.hover_rms[1.0] <= hi and floor.admissible
    assert floor.hover_rms[floor.scale] == pytest.approx(hi, rel=0.1)
    assert floor.shaping_2dof is None and set(floor.shaping_1dof.attenuation) == set(TABLE_4_2)


def test_more_ambient_excitation_raises_the_hover_rms():
    assert st.hover_pitch_rms(4.0) > 2.0 * st.hover_pitch_rms(1.0)


def test_disturbed_runs_are_reproducible():
    from trms.worlds import make_plant

    u = st.shaping_filters()
    a = st.shaped_runs(make_plant("linear", "1dof"), u, disturbance_std=0.05, seed=4)
    b = st.shaped_runs(make_plant("linear", "1dof"), u, disturbance_std=0.05, seed=4)
    assert all(a[k].equals(b[k]) for k in a)


def test_negative_disturbance_is_refused():
    from trms.worlds import make_plant

    with pytest.raises(InputError, match=r"disturbance_std = -0.1 V is outside"):
        st.shaped_runs(make_plant("linear", "1dof"), {}, disturbance_std=-0.1)


# ------------------------------------------------------------------ on any plant (ch. 4 on the twin)
def test_the_orderings_each_world_reproduces(ch4_results):
    # Table 4.2: the LPF attenuates more than the BSF at both modes (thesis 5.83 > 0.83, 7 > 1.83), on both worlds;
    # Table 4.3: u2 -> y2 Filter-3 beats the LPF at 0.1 Hz, u1 -> y1 the LPF beats Filter-1 at 0.34 Hz, on the
    # linear model (the filters' own ranking). Tolerance: 1 dB, the Welch estimate's leakage bias. On the twin the
    # Table 4.3 pairs are within one run's scatter under its ambient excitation (at seeds 0-4: the LPF ahead of
    # Filter-1 by -0.4 to +4.9 dB, Filter-3 ahead of the LPF by -0.9 to +4.6 dB): one run does not rank them.
    s1, s2 = ch4_results
    for world in ("linear", "twin"):
        a1 = s1[world].attenuation
        for mode in st.MODES:
            assert a1[("LPF 0.1 Hz", mode)] > a1[("BSF 0.2-0.4 Hz", mode)] + 1.0, (world, mode)
    a2 = s2["linear"].attenuation
    assert a2[("u2->y2", 0.1, "Filter-3")] > a2[("u2->y2", 0.1, "LPF 0.05 Hz")] + 1.0
    assert a2[("u1->y1", 0.34, "LPF 0.05 Hz")] > a2[("u1->y1", 0.34, "Filter-1")] + 1.0


def test_shaped_runs_hold_the_other_input_and_are_reproducible():
    from trms.worlds import make_plant

    plant = make_plant("linear", "2dof")
    filters = st.filters_2dof()
    a = st.shaped_runs(plant, {"Filter-3": filters["Filter-3"]}, input_index=1, duration=30.0, seed=2)
    b = st.shaped_runs(plant, {"Filter-3": filters["Filter-3"]}, input_index=1, duration=30.0, seed=2)
    assert list(a) == ["unshaped", "Filter-3"]
    assert all(a[k].equals(b[k]) for k in a)
    np.testing.assert_array_equal(a["Filter-3"].inputs[:, 0], plant.operating_point.inputs[0])
    du = a["unshaped"].deviations()[0][:, 1]
    assert du.max() == pytest.approx(st.DOUBLET_AMPLITUDE) and du.min() == pytest.approx(-st.DOUBLET_AMPLITUDE)


def test_linear_world_attenuation_stays_below_the_filter_gain(ch4_results):
    s1, s2 = ch4_results
    filters = st.shaping_filters()
    for (name, mode), value in s1["linear"].attenuation.items():
        if name in filters:
            # measurement noise can only add power to the shaped run: the attenuation cannot
            # exceed the filter's own gain by more than the Welch estimate's 1 dB leakage bias
            assert 0.0 < value <= -filters[name].gain_db([mode])[0] + 1.0, (name, mode)
    two = st.filters_2dof()
    for (ch, mode, fname), value in s2["linear"].attenuation.items():
        assert value <= -two[fname].gain_db([mode])[0] + 1.0, (ch, mode, fname)


def test_zvd_shaper_cuts_the_residual_vibration_of_the_mode_it_was_designed_for(ch4_results):
    s1, _ = ch4_results
    lin = s1["linear"]
    assert lin.shaper_modes[0][0] == pytest.approx(0.342, abs=0.005)
    assert lin.residual_db["ZVD"] > 10.0 and lin.residual_db["ZV"] > 10.0
