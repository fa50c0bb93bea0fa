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
