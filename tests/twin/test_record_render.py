"""Rendering a saved twin Record: its configuration checked before anything is drawn."""

import numpy as np
import pytest

from trms.errors import ConfigurationError, InputError
from trms.record import Record
from trms.twin import Twin
from trms.twin.record_render import render_saved_record


@pytest.fixture(scope="module")
def record():
    twin = Twin("1dof", 0.1)
    rec = twin.run(np.tile(twin.operating_point.inputs, (5, 1)))
    rec.metadata["config"] = "1dof"
    return rec


def test_a_record_renders_in_its_own_configuration(tmp_path, record):
    path, config = render_saved_record(record, tmp_path / "last.png", label="r.npz")
    assert config == "1dof" and path.stat().st_size > 1000


def test_another_configuration_or_no_samples_is_refused_before_drawing(tmp_path, record):
    with pytest.raises(ConfigurationError, match="--config 2dof does not match record 'r.npz'"):
        render_saved_record(record, tmp_path / "x.png", "2dof", label="r.npz")
    bare = Record(record.time, record.inputs, record.outputs, record.input_names, record.output_names)
    with pytest.raises(InputError, match="record 'r.npz' does not say its configuration; pass --config"):
        render_saved_record(bare, tmp_path / "x.png", label="r.npz")
    assert list(tmp_path.iterdir()) == []
