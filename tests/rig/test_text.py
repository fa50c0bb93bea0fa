"""Text exports as columns: the delimiter and decimal comma found from the data, the header among title and comment
lines, quoted fields, encodings; binary and MATLAB files refused in one line."""

from pathlib import Path

import numpy as np
import pytest

from trms.errors import InputError
from trms.rig.checks import ExportLayout
from trms.rig.text import decode_export, read_text_columns

LAYOUT = ExportLayout("t", ("V",), ("pitch",), "deg", "s", False, ("u1",), ("pitch",))


def _file(tmp_path, text, encoding="utf-8"):
    path = tmp_path / "rig.csv"
    path.write_bytes(text.encode(encoding))
    return path


@pytest.mark.parametrize(
    "text, delimiter",
    [
        ("t,V,pitch\n0,2.0,1\n0.05,2.5,3\n0.1,2.5,5\n", "comma"),
        ("t;V;pitch\n0;2,0;1\n0,05;2,5;3\n0,1;2,5;5\n", "semicolon"),
        ("t\tV\tpitch\n0\t2.0\t1\n0.05\t2.5\t3\n0.1\t2.5\t5\n", "tab"),
        ("t   V  pitch\n0   2.0  1\n0.05 2.5 3\n0.1  2.5  5\n", "whitespace"),
        ('"t","V","pitch"\n"0","2.0","1"\n"0.05","2.5","3"\n"0.1","2.5","5"\n', "comma"),
    ],
    ids=["comma", "semicolon and decimal comma", "tab", "whitespace", "quoted"],
)
def test_every_delimiter_gives_the_same_numbers(tmp_path, text, delimiter):
    data, lines, notes, read = read_text_columns(_file(tmp_path, text), LAYOUT)
    np.testing.assert_array_equal(data, [[0.0, 2.0, 1.0], [0.05, 2.5, 3.0], [0.1, 2.5, 5.0]])
    assert (
        lines == [2, 3, 4] and notes == [] and read == {"format": "text", "encoding": "utf-8", "delimiter": delimiter}
    )


def test_title_and_comment_lines_are_skipped_and_named(tmp_path):
    text = "# logger 3\nRig run 7;;\nt;V;pitch;extra\n0;2;1;9\n0,05;2;1;9\n"
    data, lines, notes, _ = read_text_columns(_file(tmp_path, text, "latin-1"), LAYOUT)
    assert data.shape == (2, 3) and lines == [4, 5]
    assert notes == [
        f"{str(tmp_path / 'rig.csv')!r}: skipped line 2 'Rig run 7;;', 1 comment line (#) from line 1 "
        "(its header is line 3)"
    ]


@pytest.mark.parametrize(
    "text, message",
    [
        ("t,V\n0,1\n0.1,1\n", "column 'pitch' is missing from"),
        ("t,V,pitch\n0,1,2\n0.1,1,2\n0.2,1,x\n", "row 4, column 'pitch': 'x' is not a number"),
        ("t,V,pitch\n0,1,nan\n0.1,1,2\n", "row 2, column 'pitch': 'nan' is not a finite number"),
        ("t,V,V,pitch\n0,1,1,2\n0.1,1,1,2\n", "column 'V' is ambiguous"),
        ("0,1,2\n0.1,1,2\n", "has no header row"),
    ],
)
def test_a_bad_table_is_one_line_naming_row_and_column(tmp_path, text, message):
    with pytest.raises(InputError, match=message) as exc:
        read_text_columns(_file(tmp_path, text), LAYOUT)
    assert "\n" not in str(exc.value)


def test_decode_export_reads_utf16_and_refuses_matlab_and_binary():
    assert decode_export("t,V\n".encode("utf-16"), Path("a.csv")) == ("t,V\n", "utf-16")
    assert decode_export(b"t,pitch \xb0\n", Path("a.csv")) == ("t,pitch \u00b0\n", "latin-1")
    with pytest.raises(InputError, match="is a MATLAB file, not a CSV export"):
        decode_export(b"MATLAB 5.0 MAT-file, Platform: x" + bytes(200), Path("a.csv"))
    with pytest.raises(InputError, match="byte 0x00 at offset 3 is binary data"):
        decode_export(b"t,V\x00", Path("a.csv"))
