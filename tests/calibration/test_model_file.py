"""The calibrated values go into a new MJCF, never onto the shipped model or the start model."""

import shutil

import pytest

from trms.calibration.model_file import check_destination, write_new_model
from trms.errors import InputError
from trms.twin.model import DEFAULT_MODEL_PATH, load_spec
from trms.twin.parameters import read_parameters


def test_the_values_go_into_a_copy_and_the_start_is_untouched(tmp_path):
    start = tmp_path / "rig.xml"
    shutil.copy(DEFAULT_MODEL_PATH, start)
    before = start.read_bytes()
    name = next(iter(read_parameters(load_spec(start))))
    value = read_parameters(load_spec(start))[name] * 1.25
    out = write_new_model({name: value}, start, tmp_path / "new" / "cal.xml")
    assert out == (tmp_path / "new" / "cal.xml").resolve() and start.read_bytes() == before
    assert read_parameters(load_spec(out))[name] == pytest.approx(value, rel=1e-5)  # written with 6 digits
    assert sorted(p.name for p in out.parent.iterdir()) == ["cal.xml"]  # no temporary copy left


def test_the_shipped_model_and_the_start_are_refused(tmp_path):
    shipped = DEFAULT_MODEL_PATH.read_bytes()
    with pytest.raises(InputError, match="is the shipped model; use --replace-shipped"):
        write_new_model({}, tmp_path / "a.xml", DEFAULT_MODEL_PATH)
    with pytest.raises(InputError, match="is the model calibration starts from"):
        check_destination(tmp_path / "a.xml", tmp_path / "a.xml")
    assert DEFAULT_MODEL_PATH.read_bytes() == shipped
