"""The faked rig: its excitations' shapes and seeding, its truth, and its rig-style CSV read back in radians."""

import subprocess
import sys

import numpy as np
import pytest

from trms.errors import InputError
from trms.record import Record
from trms.rig.exports import record_from_csv
from trms.rig.faked import ENCODER_NOISE, FAKED_RIG, excitation, faked_rig_records, to_rig_csv
from trms.twin import load_spec
from trms.twin.parameters import read_parameters

TS = 0.05


def test_doublets_rest_a_second_then_alternate_halves_of_two_four_and_six_seconds():
    u = excitation("doublets", 20.0, TS, 0.25)
    expected = np.concatenate([np.r_[np.zeros(20), np.full(w, 0.25), np.full(w, -0.25)] for w in (40, 80, 120)])[:400]
    assert u.shape == (400,)
    np.testing.assert_array_equal(u, expected)
    assert np.array_equal(u, excitation("doublets", 20.0, TS, 0.25, seed=9))  # nothing random in them


def test_prbs_holds_plus_minus_the_amplitude_for_two_second_clock_periods_and_is_seeded():
    u = excitation("prbs", 40.0, TS, 0.12, seed=3)
    assert u.shape == (800,)
    assert set(np.unique(u)) == {-0.12, 0.12}
    assert np.all(u.reshape(20, 40) == u.reshape(20, 40)[:, :1])  # constant within each 2 s clock period
    assert np.array_equal(u, excitation("prbs", 40.0, TS, 0.12, seed=3))
    assert not np.array_equal(u, excitation("prbs", 40.0, TS, 0.12, seed=4))


def test_an_unknown_excitation_is_refused_naming_the_choices():
    with pytest.raises(InputError, match="excitation kind.*'prbs'.*'doublets'"):
        excitation("chirp", 10.0, TS, 0.25)


@pytest.fixture(scope="module")
def two_dof():
    return faked_rig_records("2dof", 0.25, 3.0, ("prbs", "doublets"), seed=5)


def test_the_truth_is_the_shipped_model_times_the_faked_rigs_factors_and_records_are_seeded(two_dof):
    truth, (a, b) = two_dof
    shipped = read_parameters(load_spec(), list(FAKED_RIG))
    assert truth == {n: pytest.approx(shipped[n] * f, rel=1e-12) for n, f in FAKED_RIG.items()}
    assert a.input_names == ("u1", "u2") and a.output_names == ("pitch", "yaw") and len(a) == 60
    du = a.inputs - a.inputs[0] + excitation("prbs", 3.0, TS, 0.25, 5)[0]  # the first sample is on a level
    np.testing.assert_allclose(a.inputs[:, 0] - a.inputs[0, 0] + du[0, 0], excitation("prbs", 3.0, TS, 0.25, 5))
    # the doublet record rests for its first second: its main voltage is the hover one there
    assert np.all(b.inputs[:20, 0] == b.inputs[0, 0]) and not np.all(b.inputs[:, 0] == b.inputs[0, 0])
    again = faked_rig_records("2dof", 0.25, 3.0, ("prbs",), seed=5)[1][0]
    assert again.equals(a)
    other = faked_rig_records("2dof", 0.25, 3.0, ("prbs",), seed=6)[1][0]
    assert not np.array_equal(other.outputs, a.outputs)
    assert ENCODER_NOISE == 0.002


def test_the_rig_csv_reads_back_as_the_record_in_radians(two_dof, tmp_path):
    _, (rec, _) = two_dof
    path = to_rig_csv(rec, tmp_path / "rig.csv")
    header = path.read_text().splitlines()[0]
    assert header == "Time [s],Main motor [V],Tail motor [V],Pitch [deg],Yaw [deg]"
    back = record_from_csv(
        path,
        time="Time [s]",
        inputs=["Main motor [V]", "Tail motor [V]"],
        outputs=["Pitch [deg]", "Yaw [deg]"],
        units="deg",
        hover_segment=(0.0, 0.1),
        input_names=["u1", "u2"],
        output_names=["pitch", "yaw"],
        config="2dof",
    )
    assert back.metadata["config"] == "2dof"
    np.testing.assert_allclose(back.time, rec.time, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(back.inputs, rec.inputs)
    np.testing.assert_allclose(back.outputs, rec.outputs, rtol=1e-14, atol=1e-15)
    assert np.abs(rec.outputs).max() > 0.01  # it moved: degrees read as radians would not pass


def test_trms_import_of_the_rig_csv_gives_the_record_back(tmp_path):
    _, (rec,) = faked_rig_records("1dof", 0.25, 2.0, ("prbs",), seed=2)
    to_rig_csv(rec, tmp_path / "rig.csv")
    res = subprocess.run(
        [
            sys.executable,
            "-m",
            "trms.cli",
            "import",
            "rig.csv",
            "--time",
            "Time [s]",
            "--inputs",
            "Main motor [V]",
            "--outputs",
            "Pitch [deg]",
            "--units",
            "deg",
            "--hover",
            "0:0.1",
            "--config",
            "1dof",
            "--out",
            "rig.npz",
        ],
        cwd=tmp_path,
        capture_output=True,
        text=True,
    )
    assert res.returncode == 0, res.stderr
    back = Record.load(tmp_path / "rig.npz")
    assert back.input_names == ("u1",) and back.output_names == ("pitch",)
    np.testing.assert_array_equal(back.inputs, rec.inputs)
    np.testing.assert_allclose(back.outputs, rec.outputs, rtol=1e-14, atol=1e-15)
