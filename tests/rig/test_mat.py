"""MATLAB exports as columns: variables, struct fields, struct-array elements, matrix columns (1-based)."""

import numpy as np
import pytest
import scipy.io

from trms.errors import InputError
from trms.rig.checks import ExportLayout
from trms.rig.mat import is_mat_header, read_mat_columns


@pytest.fixture
def mat(tmp_path):
    t = np.arange(5) * 0.1
    path = tmp_path / "run.mat"
    scipy.io.savemat(
        path,
        {
            "data": {"time": t, "u1": 2.0 + t, "pitch": 10 * t},
            "log": np.column_stack([t, 2.0 + t, 10 * t]),
            "S": {"signals": [{"values": 10 * t}, {"values": -t}]},
        },
    )
    return path, t


@pytest.mark.parametrize(
    "time, u, y",
    [
        ("data.time", "data.u1", "data.pitch"),
        ("time", "u1", "pitch"),  # fields of the one struct that has them, named alone
        ("log(:,1)", "log(:,2)", "log(:,3)"),
        ("data.time", "log(:,2)", "S.signals(1).values"),
    ],
)
def test_every_way_of_naming_a_column_reads_the_same_numbers(mat, time, u, y):
    path, t = mat
    data, lines, notes, read = read_mat_columns(
        path, ExportLayout(time, (u,), (y,), "deg", "s", False, ("u1",), ("p",))
    )
    np.testing.assert_allclose(data, np.column_stack([t, 2.0 + t, 10 * t]), rtol=0, atol=1e-12)
    assert lines is None and notes == [] and read == {"format": "mat"}


@pytest.mark.parametrize(
    "column, message",
    [
        ("data", r"is a struct \(fields time, u1, pitch\); name one of its fields"),
        ("log", r"is 5x3, not one series; name one column, e.g. 'log\(:,1\)'"),
        ("log(:,4)", r"is not a column of 'log', a 5x3 matrix .*K in 1..3"),
        ("S.signals(3).values", "asks for element 3 of 2"),
        ("nope", "variable 'nope' is missing from"),
    ],
)
def test_a_wrong_name_is_one_line(mat, column, message):
    layout = ExportLayout("data.time", ("data.u1",), (column,), "deg", "s", False, ("u1",), ("p",))
    with pytest.raises(InputError, match=message):
        read_mat_columns(mat[0], layout)


def test_the_header_tells_a_mat_file():
    assert is_mat_header(b"MATLAB 7.3 MAT-file") and is_mat_header(bytes(512) + b"\x89HDF\r\n\x1a\n")
    assert not is_mat_header(b"time,u1,pitch\n")
