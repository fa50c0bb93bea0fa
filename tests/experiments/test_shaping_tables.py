"""Table 4.2 (1-DOF) on eq. (3.11): thesis values beside computed ones; known-truth checks."""

import numpy as np
import pytest

from trms.errors import InputError
from trms.experiments import shaping_tables as st
from trms.reference import TABLE_4_2


@pytest.fixture(scope="module")
def table():
    return st.table_4_2()


def test_rows_carry_the_thesis_values(table):
    assert len(table.rows) == 4
    for row in table.rows:
        assert row[-1] == TABLE_4_2[(row[0], row[1])]
    assert "Noise-free cells more than 30 %" in table.notes[1]


def test_noise_free_attenuation_is_bounded_by_the_filter_gain(table):
    # Y = G F U: the PSD ratio at a mode is |F|^2 there, blurred by leakage which can only let
    # neighbouring (less attenuated) power in; 1 dB allows for the window's own bias.
    filters = st.shaping_filters()
    for row in table.rows:
        gain = -filters[row[0]].gain_db([row[1]])[0]
        assert 0.0 < row[2] <= gain + 1.0
    lpf = {row[1]: row[2] for row in table.rows if row[0] == "LPF 0.1 Hz"}
    assert lpf[0.34] == pytest.approx(-filters["LPF 0.1 Hz"].gain_db([0.34])[0], abs=1.0)


def test_an_ambient_floor_lowers_every_attenuation(table):
    for row in table.rows:
        assert row[2] > row[3] > row[4]


def test_disturbed_runs_are_reproducible():
    a = st.doublet_responses(disturbance_std=0.05, seed=4)
    b = st.doublet_responses(disturbance_std=0.05, seed=4)
    assert all(np.array_equal(a[k], b[k]) for k in a)
    c = st.doublet_responses(disturbance_std=0.05, seed=5)
    assert not np.array_equal(a["unshaped"], c["unshaped"])


def test_negative_disturbance_is_refused():
    with pytest.raises(InputError, match=r"disturbance_std = -0.1 V is outside"):
        st.doublet_responses(disturbance_std=-0.1)


# ------------------------------------------------------------------ on any plant (ch. 4 on the twin)
def test_shaped_runs_hold_the_other_input_and_are_reproducible():
    from trms.experiments.plants import make_plant

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


def test_chapter_4_section_is_complete(ch4_results, tmp_path):
    s1, s2 = ch4_results
    sec = st.section(s1, s2, tmp_path)
    assert [len(t.rows) for t in sec.tables][1] == len(st.TABLE_4_3)
    for t in sec.tables:
        assert t.missing() == []
    assert all(f.path.is_file() for f in sec.figures)
